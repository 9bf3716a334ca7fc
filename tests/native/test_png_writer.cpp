// The PNG writer of the command line's pictures (plugin/cli/png_writer.h): known checksums, the
// file's structure read back byte by byte, and Python's zlib decoding it where Python exists.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "avatar_test_files.h"
#include "bundle/sha256.h"
#include "png_writer.h"
#include "stream/crc32.h"

using namespace softdeca::cli;

namespace {
std::uint32_t be32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(s[at + static_cast<std::size_t>(k)]);
  return v;
}

std::vector<std::uint8_t> test_image(std::size_t w, std::size_t h) {
  std::vector<std::uint8_t> rgb(3 * w * h);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>((i * 7 + i / 3) & 0xff);
  return rgb;
}

// The rows as PNG filters them (type 0 before each), what the IDAT stream must decompress to.
std::string filtered(const std::vector<std::uint8_t>& rgb, std::size_t w, std::size_t h) {
  std::string raw;
  for (std::size_t y = 0; y < h; ++y) {
    raw += '\0';
    raw.append(reinterpret_cast<const char*>(rgb.data() + 3 * w * y), 3 * w);
  }
  return raw;
}

struct Chunk {
  std::string type, data;
};

// The chunks of a PNG file, each CRC checked.
std::vector<Chunk> chunks(const std::string& png) {
  std::vector<Chunk> out;
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  for (std::size_t at = 8; at + 12 <= png.size();) {
    const std::uint32_t length = be32(png, at);
    const std::string body = png.substr(at + 4, 4 + length);
    EXPECT_EQ(be32(png, at + 8 + length), softdeca::stream::crc32(body.data(), body.size())) << body.substr(0, 4);
    out.push_back({body.substr(0, 4), body.substr(4)});
    at += 12 + length;
  }
  return out;
}

// The deflate stream of stored blocks read back; the Adler-32 recomputed by its definition.
std::string inflate_stored(const std::string& z) {
  EXPECT_EQ((static_cast<unsigned char>(z[0]) * 256 + static_cast<unsigned char>(z[1])) % 31, 0);
  std::string raw;
  std::size_t at = 2;
  for (bool last = false; !last;) {
    last = z[at] & 1;
    EXPECT_EQ((z[at] >> 1) & 3, 0) << "not a stored block";
    const unsigned len = static_cast<unsigned char>(z[at + 1]) | static_cast<unsigned char>(z[at + 2]) << 8;
    const unsigned nlen = static_cast<unsigned char>(z[at + 3]) | static_cast<unsigned char>(z[at + 4]) << 8;
    EXPECT_EQ(len ^ nlen, 0xffffu);
    raw += z.substr(at + 5, len);
    at += 5 + len;
  }
  std::uint32_t a = 1, b = 0;
  for (const char c : raw) {
    a = (a + static_cast<unsigned char>(c)) % 65521;
    b = (b + a) % 65521;
  }
  EXPECT_EQ(be32(z, at), (b << 16) | a);
  EXPECT_EQ(at + 4, z.size());
  return raw;
}
}  // namespace

TEST(PngWriter, ChecksumsGiveTheirKnownValues) {
  EXPECT_EQ(adler32("Wikipedia", 9), 0x11E60398u);
  EXPECT_EQ(adler32("", 0), 1u);
  const std::string zeros(100000, '\xff');  // past the run after which the sums are reduced
  std::uint32_t a = 1, b = 0;
  for (std::size_t i = 0; i < zeros.size(); ++i) {
    a = (a + 255) % 65521;
    b = (b + a) % 65521;
  }
  EXPECT_EQ(adler32(zeros.data(), zeros.size()), (b << 16) | a);
  EXPECT_EQ(adler32(zeros.data() + 10, zeros.size() - 10, adler32(zeros.data(), 10)), adler32(zeros.data(), zeros.size()));
  const std::vector<std::uint8_t> pixel = {1, 2, 3};
  const std::string png = encode_png(pixel.data(), 1, 1);
  EXPECT_EQ(png.substr(png.size() - 12), std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12));
}

TEST(PngWriter, TheFileReadsBackToThePixels) {
  for (const auto& [w, h] : std::vector<std::pair<std::size_t, std::size_t>>{{3, 2}, {300, 100}}) {  // one block, several
    const std::vector<std::uint8_t> rgb = test_image(w, h);
    const std::vector<Chunk> c = chunks(encode_png(rgb.data(), w, h));
    ASSERT_EQ(c.size(), 3u);
    EXPECT_EQ(c[0].type, "IHDR");
    EXPECT_EQ(be32(c[0].data, 0), w);
    EXPECT_EQ(be32(c[0].data, 4), h);
    EXPECT_EQ(c[0].data.substr(8), std::string("\x08\x02\x00\x00\x00", 5));
    EXPECT_EQ(c[1].type, "IDAT");
    EXPECT_EQ(inflate_stored(c[1].data), filtered(rgb, w, h));
    EXPECT_EQ(c[2].type, "IEND");
  }
  EXPECT_THROW(encode_png(nullptr, 0, 10), std::invalid_argument);
}

TEST(PngWriter, PythonsZlibDecodesIt) {
  if (std::system("python3 -c 'import zlib' > /dev/null 2>&1") != 0) GTEST_SKIP() << "no python3 with zlib";
  const softdeca::test::TempDir dir("png");
  const std::size_t w = 257, h = 301;  // several stored blocks
  const std::vector<std::uint8_t> rgb = test_image(w, h);
  write_png(dir.file("picture.png"), rgb.data(), w, h);
  const std::string script =
      "import hashlib, struct, sys, zlib\n"
      "d = open(sys.argv[1], 'rb').read(); at = 8; idat = b''\n"
      "while at < len(d):\n"
      "    n, = struct.unpack('>I', d[at:at + 4]); body = d[at + 4:at + 8 + n]\n"
      "    assert struct.unpack('>I', d[at + 8 + n:at + 12 + n])[0] == zlib.crc32(body), body[:4]\n"
      "    idat += body[4:] if body[:4] == b'IDAT' else b''; at += 12 + n\n"
      "print(hashlib.sha256(zlib.decompress(idat)).hexdigest())\n";
  const std::string script_path = dir.write("decode.py", script);
  FILE* p = popen(("python3 " + script_path + " " + dir.file("picture.png")).c_str(), "r");
  ASSERT_NE(p, nullptr);
  char line[128] = {};
  const bool read = std::fgets(line, sizeof line, p) != nullptr;
  EXPECT_EQ(pclose(p), 0);
  ASSERT_TRUE(read);
  const std::string raw = filtered(rgb, w, h);
  EXPECT_EQ(std::string(line).substr(0, 64),
            softdeca::bundle::sha256_hex(reinterpret_cast<const std::uint8_t*>(raw.data()), raw.size()));
}
