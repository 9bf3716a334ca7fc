#include "stream/crc32.h"

#include <array>

namespace softdeca::stream {
namespace {
constexpr std::array<uint32_t, 256> make_table() {
  std::array<uint32_t, 256> t{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}
constexpr std::array<uint32_t, 256> kTable = make_table();

// a * b modulo the CRC polynomial, bit-reflected (bit 31 is x^0).
constexpr uint32_t multiply(uint32_t a, uint32_t b) {
  uint32_t product = 0;
  for (uint32_t m = 1u << 31; m != 0; m >>= 1) {
    if (a & m) product ^= b;
    b = (b & 1) ? (b >> 1) ^ 0xEDB88320u : b >> 1;
  }
  return product;
}

// kPowers[k] = x^(2^k) modulo the polynomial.
constexpr std::array<uint32_t, 32> make_powers() {
  std::array<uint32_t, 32> t{};
  uint32_t p = 1u << 30;  // x^1
  for (auto& v : t) {
    v = p;
    p = multiply(p, p);
  }
  return t;
}
constexpr std::array<uint32_t, 32> kPowers = make_powers();
}  // namespace

uint32_t crc32(const void* data, std::size_t size, uint32_t crc) {
  const auto* p = static_cast<const uint8_t*>(data);
  crc = ~crc;
  for (std::size_t i = 0; i < size; ++i) crc = kTable[(crc ^ p[i]) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

uint32_t crc32_shift(std::size_t size_b) {
  uint32_t shift = 1u << 31;  // x^0
  unsigned k = 3;             // x^(8 size_b) = product of x^(2^k) over the bits of size_b, shifted by 3
  for (std::size_t n = size_b; n != 0; n >>= 1, ++k)
    if (n & 1) shift = multiply(kPowers[k & 31], shift);
  return shift;
}

uint32_t crc32_apply(uint32_t shift, uint32_t crc) { return multiply(shift, crc); }

uint32_t crc32_combine(uint32_t crc_a, uint32_t crc_b, std::size_t size_b) {
  return multiply(crc32_shift(size_b), crc_a) ^ crc_b;
}

}  // namespace softdeca::stream
