// CRC-32 (IEEE 802.3, the polynomial of zlib and PNG): checksums of recording records and
// headers, and the ids of landmark profiles and neutral meshes.
#pragma once

#include <cstddef>
#include <cstdint>

namespace softdeca::stream {

// CRC of `size` bytes, continuing from `crc` (0 to start).
uint32_t crc32(const void* data, std::size_t size, uint32_t crc = 0);

// The CRC of A followed by B from crc32(A), crc32(B) and B's length, in O(log size_b)
// (zlib's crc32_combine): checksums of ranges from prefix checksums without rereading bytes.
uint32_t crc32_combine(uint32_t crc_a, uint32_t crc_b, std::size_t size_b);

// The operator behind it, for callers that combine with the same lengths many times:
// crc32_combine(a, b, n) == crc32_apply(crc32_shift(n), a) ^ b, and
// crc32_shift(n + 1) == crc32_apply(crc32_shift(n), crc32_shift(1)).
uint32_t crc32_shift(std::size_t size_b);
uint32_t crc32_apply(uint32_t shift, uint32_t crc);

}  // namespace softdeca::stream
