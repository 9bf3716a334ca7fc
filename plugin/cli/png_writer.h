// PNG pictures without a compression library: 8-bit RGB, the image data in zlib's "stored"
// (uncompressed) deflate blocks, so a picture costs its raw size, fine for the tools' small
// figures. Chunk CRCs are the library's CRC-32 (stream/crc32.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace softdeca::cli {

// Adler-32 (RFC 1950), continuing from `adler` (1 to start).
std::uint32_t adler32(const void* data, std::size_t size, std::uint32_t adler = 1);

// The PNG file of `rgb` (width * height * 3 bytes, rows top to bottom). Throws
// std::invalid_argument for an empty or oversized picture.
std::string encode_png(const std::uint8_t* rgb, std::size_t width, std::size_t height);
void write_png(const std::string& path, const std::uint8_t* rgb, std::size_t width, std::size_t height);

}  // namespace softdeca::cli
