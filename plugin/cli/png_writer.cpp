#include "png_writer.h"

#include <algorithm>
#include <stdexcept>

#include "json.h"
#include "stream/crc32.h"

namespace softdeca::cli {

namespace {
constexpr std::size_t kStoredBlock = 65535;  // the most a stored deflate block holds

void put32(std::string& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((v >> shift) & 0xff);
}

void chunk(std::string& out, const char type[4], const std::string& data) {
  put32(out, static_cast<std::uint32_t>(data.size()));
  const std::string body = std::string(type, 4) + data;
  out += body;
  put32(out, stream::crc32(body.data(), body.size()));
}

// zlib stream of stored blocks: header 78 01, blocks of [final bit, LEN, ~LEN, bytes], Adler-32.
std::string zlib_stored(const std::string& raw) {
  std::string z = "\x78\x01";
  std::size_t at = 0;
  do {
    const std::size_t n = std::min(kStoredBlock, raw.size() - at);
    const bool last = at + n == raw.size();
    z += static_cast<char>(last ? 1 : 0);
    const auto len = static_cast<std::uint16_t>(n), nlen = static_cast<std::uint16_t>(~len);
    z += static_cast<char>(len & 0xff);
    z += static_cast<char>(len >> 8);
    z += static_cast<char>(nlen & 0xff);
    z += static_cast<char>(nlen >> 8);
    z.append(raw, at, n);
    at += n;
  } while (at < raw.size());
  put32(z, adler32(raw.data(), raw.size()));
  return z;
}
}  // namespace

std::uint32_t adler32(const void* data, std::size_t size, std::uint32_t adler) {
  constexpr std::uint32_t kMod = 65521;
  constexpr std::size_t kRun = 5552;  // the most bytes before the sums can overflow 32 bits
  const auto* p = static_cast<const std::uint8_t*>(data);
  std::uint32_t a = adler & 0xffff, b = adler >> 16;
  while (size > 0) {
    const std::size_t n = std::min(size, kRun);
    for (std::size_t i = 0; i < n; ++i) {
      a += p[i];
      b += a;
    }
    a %= kMod;
    b %= kMod;
    p += n;
    size -= n;
  }
  return (b << 16) | a;
}

std::string encode_png(const std::uint8_t* rgb, std::size_t width, std::size_t height) {
  if (width == 0 || height == 0 || width > 16384 || height > 16384)
    throw std::invalid_argument("a PNG picture of " + std::to_string(width) + " x " + std::to_string(height) + " pixels");
  std::string raw;  // each row behind filter type 0 (none)
  raw.reserve(height * (3 * width + 1));
  for (std::size_t y = 0; y < height; ++y) {
    raw += '\0';
    raw.append(reinterpret_cast<const char*>(rgb + 3 * width * y), 3 * width);
  }
  std::string header;
  put32(header, static_cast<std::uint32_t>(width));
  put32(header, static_cast<std::uint32_t>(height));
  header += std::string("\x08\x02\x00\x00\x00", 5);  // 8 bits, RGB, deflate, filter 0, no interlace
  std::string png = "\x89PNG\r\n\x1a\n";
  chunk(png, "IHDR", header);
  chunk(png, "IDAT", zlib_stored(raw));
  chunk(png, "IEND", "");
  return png;
}

void write_png(const std::string& path, const std::uint8_t* rgb, std::size_t width, std::size_t height) {
  write_text_file(path, encode_png(rgb, width, height));
}

}  // namespace softdeca::cli
