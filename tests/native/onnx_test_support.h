// A few protobuf fields, enough for tests to write (hostile) ONNX graphs byte by byte.
#pragma once

#include <cstdint>
#include <string>

namespace softdeca::test {

inline std::string varint(std::uint64_t v) {
  std::string out;
  do {
    std::uint8_t b = v & 0x7F;
    v >>= 7;
    out += static_cast<char>(v ? b | 0x80 : b);
  } while (v);
  return out;
}
inline std::string field(int number, std::uint64_t value) { return varint(std::uint64_t(number) << 3) + varint(value); }
inline std::string field(int number, const std::string& bytes) {
  return varint(std::uint64_t(number) << 3 | 2) + varint(bytes.size()) + bytes;
}

}  // namespace softdeca::test
