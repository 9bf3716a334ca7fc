// The ONNX scan's size estimate on graphs rather than bytes: the fuzzer's bytes are a small
// program that builds a graph of the constant-foldable producers the memory budget counts
// (Range, Tile, ConstantOfShape, Expand, Resize), fed by constants of chosen sizes and
// values, Shape chains, Concat, Cast and subgraphs. Each graph is scanned after every step:
// a step only adds tensors of new names, so the estimate never shrinks, and a
// ConstantOfShape of a known vector is counted at least at its size, saturating at
// UINT64_MAX rather than wrapping (docs/security.md, "Memory budget").
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "api/error_boundary.h"
#include "bundle/onnx_model_scan.h"
#include "fuzz_check.h"
#include "onnx_test_support.h"

using namespace softdeca::runtime;
using softdeca::test::field;

namespace {

constexpr std::uint64_t kMax = UINT64_MAX;
constexpr std::size_t kMaxSteps = 24;

std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) { return a != 0 && b > kMax / a ? kMax : a * b; }

class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  std::uint8_t next() { return pos_ < size_ ? data_[pos_++] : 0; }
  // A value spanning small and huge magnitudes, either sign.
  std::int64_t value() {
    const std::uint8_t mantissa = next(), shift = next();
    const std::int64_t v = static_cast<std::int64_t>(mantissa) << (shift % 48);
    return shift & 0x80 ? -v : v;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_, pos_ = 0;
};

std::string int64s(const std::vector<std::int64_t>& values) {
  std::string raw;
  for (std::int64_t v : values)
    for (int i = 0; i < 8; ++i) raw += static_cast<char>(static_cast<std::uint64_t>(v) >> (8 * i));
  return raw;
}
std::string floats_of(const std::vector<std::int64_t>& values) {
  std::string raw;
  for (std::int64_t v : values) {
    const float f = static_cast<float>(v);
    raw.append(reinterpret_cast<const char*>(&f), 4);
  }
  return raw;
}
// TensorProto: dims, data type (1 float, 7 int64), name, raw data.
std::string tensor(const std::string& name, std::uint64_t dtype, const std::vector<std::uint64_t>& dims,
                   const std::string& raw) {
  std::string t;
  for (std::uint64_t d : dims) t += field(1, d);
  t += field(2, dtype) + field(8, name);
  if (!raw.empty()) t += field(9, raw);
  return t;
}
std::string int_attribute(const std::string& name, std::int64_t v) {
  return field(5, field(1, name) + field(3, static_cast<std::uint64_t>(v)));
}
std::string node(const std::string& op, const std::vector<std::string>& inputs, const std::string& output,
                 const std::string& attributes = "") {
  std::string n;
  for (const std::string& i : inputs) n += field(1, i);
  return field(1, n + field(2, output) + field(4, op) + attributes);
}

// Builds the graph step by step; every step defines only names no earlier step used.
class GraphProgram {
 public:
  explicit GraphProgram(Bytes& in) : in_(in) {}

  // One step: a graph field (or several) appended; false when the program has ended.
  bool step() {
    if (in_.empty() || fields_.size() >= kMaxSteps) return false;
    const std::string out = "t" + std::to_string(fields_.size());
    switch (in_.next() % 13) {
      case 0: {  // an int64 vector initializer: a shape, repeats, sizes or a Range bound
        const std::vector<std::int64_t> v = values();
        fields_.push_back(field(5, tensor(out, 7, {v.size()}, int64s(v))));
        vectors_.push_back({out, v});
        break;
      }
      case 1: {  // a float scalar initializer (Range bounds in float)
        const std::vector<std::int64_t> v{in_.value()};
        fields_.push_back(field(5, tensor(out, 1, {}, floats_of(v))));
        break;
      }
      case 2: {  // a float tensor of declared dims and no data: a static shape
        std::vector<std::uint64_t> dims;
        for (std::size_t i = 0, n = in_.next() % 5; i < n; ++i) dims.push_back(in_.next() % 64);
        fields_.push_back(field(5, tensor(out, 1, dims, "")));
        break;
      }
      case 3: {  // a Constant node holding an int64 vector
        const std::vector<std::int64_t> v = values();
        fields_.push_back(node("Constant", {}, out,
                               field(5, field(1, std::string("value")) + field(5, tensor("", 7, {v.size()}, int64s(v))))));
        vectors_.push_back({out, v});
        break;
      }
      case 4: {  // Shape, sliced or not
        std::string attributes;
        if (in_.next() & 1) attributes = int_attribute("start", in_.value() % 8) + int_attribute("end", in_.value() % 8);
        fields_.push_back(node("Shape", {any()}, out, attributes));
        break;
      }
      case 5: fields_.push_back(node("Concat", {any(), any()}, out, int_attribute("axis", 0))); break;
      case 6: fields_.push_back(node(in_.next() & 1 ? "Cast" : "Identity", {any()}, out, int_attribute("to", 7))); break;
      case 7: fields_.push_back(node("Range", {any(), any(), any()}, out)); break;
      case 8: fields_.push_back(node("Tile", {any(), any()}, out)); break;
      case 9: constant_of_shape(out); break;
      case 10: fields_.push_back(node("Expand", {any(), any()}, out)); break;
      case 11: fields_.push_back(node("Resize", {any(), "", in_.next() & 1 ? any() : "", any()}, out)); break;
      case 12: {  // a subgraph: an If whose branch fills a constant shape
        const std::vector<std::int64_t> v = values();
        const std::string branch = node("Constant", {}, out + "s",
                                        field(5, field(1, std::string("value")) + field(5, tensor("", 7, {v.size()}, int64s(v))))) +
                                   node("ConstantOfShape", {out + "s"}, out + "f");
        fields_.push_back(node("If", {any()}, out, field(5, field(1, std::string("then_branch")) + field(6, branch))));
        expected_ = std::max(expected_, filled_bytes(v));
        break;
      }
    }
    names_.push_back(out);
    return true;
  }

  std::string model() const {
    std::string graph = field(2, std::string("g"));
    for (const std::string& f : fields_) graph += f;
    return field(1, 8) + field(7, graph);
  }
  // The least a correct scan counts: the largest ConstantOfShape of a known vector.
  std::uint64_t expected() const { return expected_; }

 private:
  struct Vector {
    std::string name;
    std::vector<std::int64_t> values;
  };

  std::vector<std::int64_t> values() {
    std::vector<std::int64_t> v;
    for (std::size_t i = 0, n = in_.next() % 6; i < n; ++i) v.push_back(in_.value());
    return v;
  }
  // A name an earlier step defined, or one nothing defines (a run-time input).
  std::string any() {
    const std::uint8_t b = in_.next();
    return names_.empty() || b == 0xFF ? std::string("input") : names_[b % names_.size()];
  }
  // The scan's rule for a dimension: below 1 counts as 1 (nonsense or "infer").
  // An empty vector (a scalar's shape, 4 bytes) is left out: too small to matter.
  static std::uint64_t filled_bytes(const std::vector<std::int64_t>& dims) {
    if (dims.empty()) return 0;
    std::uint64_t n = 4;  // float elements, ConstantOfShape's default
    for (std::int64_t d : dims) n = mul_sat(n, d < 1 ? 1 : static_cast<std::uint64_t>(d));
    return n;
  }
  void constant_of_shape(const std::string& out) {
    const std::uint8_t b = in_.next();
    if (!vectors_.empty() && b & 1) {
      const Vector& v = vectors_[b / 2 % vectors_.size()];
      fields_.push_back(node("ConstantOfShape", {v.name}, out));
      expected_ = std::max(expected_, filled_bytes(v.values));
    } else {
      fields_.push_back(node("ConstantOfShape", {any()}, out));
    }
  }

  Bytes& in_;
  std::vector<std::string> fields_, names_;
  std::vector<Vector> vectors_;
  std::uint64_t expected_ = 0;
};

OnnxModelScan scan(const std::string& model) {
  return scan_onnx_model(reinterpret_cast<const std::uint8_t*>(model.data()), model.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Bytes in(data, size);
  GraphProgram program(in);
  std::uint64_t previous = 0;
  while (program.step()) {
    OnnxModelScan s;
    try {
      s = scan(program.model());
    } catch (const softdeca::Error&) {
      FUZZ_CHECK(!"a well-formed graph was refused");
    }
    const std::uint64_t total = s.total_bytes();
    FUZZ_CHECK(total >= previous);  // one more producer never lowers the estimate
    FUZZ_CHECK(total >= s.initializer_bytes && total >= s.declared_bytes && total >= s.shaped_bytes);
    FUZZ_CHECK(s.shaped_bytes >= program.expected());  // saturated, never wrapped
    FUZZ_CHECK(s.largest_bytes <= total);
    previous = total;
  }
  return 0;
}
