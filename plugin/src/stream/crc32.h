// CRC-32 (IEEE 802.3, the polynomial of zlib and PNG): checksums of recording records and
// headers, and the ids of landmark profiles and neutral meshes.
#pragma once

#include <cstddef>
#include <cstdint>

namespace softdeca::stream {

// CRC of `size` bytes, continuing from `crc` (0 to start).
uint32_t crc32(const void* data, std::size_t size, uint32_t crc = 0);

}  // namespace softdeca::stream
