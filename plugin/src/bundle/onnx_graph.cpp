#include "bundle/onnx_graph.h"

#include <limits>

namespace softdeca::bundle::onnx {

namespace {
constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
}

std::uint64_t add_sat(std::uint64_t a, std::uint64_t b) { return a > kMax - b ? kMax : a + b; }
std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) { return a != 0 && b > kMax / a ? kMax : a * b; }

std::uint64_t element_size(std::int64_t dtype) {
  switch (dtype) {
    case kUint8: case kInt8: case kBool: return 1;
    case kUint16: case kInt16: case kFloat16: case kBfloat16: return 2;
    case kFloat: case kInt32: case kUint32: return 4;
    case kInt64: case kDouble: case kUint64: return 8;
    default: return 0;
  }
}

bool is_integer(std::int64_t dtype) {
  switch (dtype) {
    case kUint8: case kInt8: case kUint16: case kInt16: case kInt32: case kInt64: case kBool: case kUint32:
    case kUint64: return true;
    default: return false;
  }
}

bool holds(std::int64_t dtype, std::int64_t v) {
  switch (dtype) {
    case kBool: return v == 0 || v == 1;
    case kUint8: return v >= 0 && v <= 0xFF;
    case kInt8: return v >= -0x80 && v <= 0x7F;
    case kUint16: return v >= 0 && v <= 0xFFFF;
    case kInt16: return v >= -0x8000 && v <= 0x7FFF;
    case kInt32: return v >= std::numeric_limits<std::int32_t>::min() && v <= std::numeric_limits<std::int32_t>::max();
    case kUint32: return v >= 0 && v <= std::int64_t{0xFFFFFFFF};
    case kInt64: return true;
    case kUint64: return v >= 0;  // larger ones are not carried
    default: return false;
  }
}

std::uint64_t Tensor::elements() const {
  std::uint64_t n = 1;
  for (const std::uint64_t d : dims) n = mul_sat(n, d);
  return n;
}

std::uint64_t Tensor::bytes() const { return mul_sat(elements(), element_size(dtype)); }

std::string printable(const std::string& name) {
  std::string out;
  for (const char c : name.substr(0, 64)) out += (c >= 32 && c < 127) ? c : '?';
  return name.size() > 64 ? out + "..." : out;
}

std::string Node::label() const {
  const std::string& id = !name.empty() ? name : !outputs.empty() ? outputs.front() : name;
  return printable(op) + " node '" + printable(id) + "'";
}

}  // namespace softdeca::bundle::onnx
