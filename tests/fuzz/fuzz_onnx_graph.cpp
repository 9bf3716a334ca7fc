// The ONNX scan's static shapes on graphs rather than bytes: the fuzzer's bytes are a small
// program that builds a graph from a graph input and initializers and Constant nodes of chosen
// sizes and values, through the listed operators that carry shapes and sizes (Shape, Gather,
// Slice, Concat, Unsqueeze, Reshape, Mul, Add, Sub, Cast, Identity, ConstantOfShape, Expand,
// MatMul), and sometimes an operator off the list or a subgraph. Each graph is scanned after
// every step (a step only adds tensors of new names): a graph with an operator off the list or
// a subgraph is refused, and a refused graph stays refused; an accepted graph's total never
// shrinks, counts every ConstantOfShape of a known vector at least at its size, and saturates
// at 2^64 - 1 rather than wrapping (docs/security.md, "Memory budget").
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "api/error_boundary.h"
#include "bundle/onnx_model_scan.h"
#include "fuzz_check.h"
#include "onnx_test_support.h"

using namespace softdeca::bundle;
using namespace softdeca::test;

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

// Builds the graph step by step; every step defines only names no earlier step used.
class GraphProgram {
 public:
  explicit GraphProgram(Bytes& in) : in_(in) {}

  // One step: a graph field (or several) appended; false when the program has ended.
  bool step() {
    if (in_.empty() || fields_.size() >= kMaxSteps) return false;
    const std::string out = "t" + std::to_string(fields_.size());
    const std::uint8_t op = in_.next();
    switch (op % 16) {
      case 0: {  // an int64 vector initializer: a shape, axes, indices
        const std::vector<std::int64_t> v = values();
        fields_.push_back(initializer(int64_vector(out, v)));
        vectors_.push_back({out, v});
        break;
      }
      case 1: {  // a float tensor of declared dims and no data
        std::vector<std::uint64_t> dims;
        for (std::size_t i = 0, n = in_.next() % 5; i < n; ++i) dims.push_back(in_.next() % 64);
        fields_.push_back(initializer(tensor(out, kFloat, dims)));
        break;
      }
      case 2: {  // a Constant node holding an int64 vector
        const std::vector<std::int64_t> v = values();
        fields_.push_back(vector_constant(out, v));
        vectors_.push_back({out, v});
        break;
      }
      case 3: {  // Shape, sliced or not
        const std::string x = any();
        std::string attributes;
        if (in_.next() & 1) {
          attributes = int_attribute("start", in_.value() % 8);
          attributes += int_attribute("end", in_.value() % 8);
        }
        fields_.push_back(node("Shape", {x}, out, attributes));
        break;
      }
      case 4: {
        const std::vector<std::string> inputs = operands(2);
        fields_.push_back(node("Concat", inputs, out, int_attribute("axis", in_.value() % 3)));
        break;
      }
      case 5: {
        const std::string x = any();
        const std::uint8_t kind = in_.next();
        fields_.push_back(kind & 1 ? node("Cast", {x}, out, int_attribute("to", kind & 2 ? 7 : 1)) : node("Identity", {x}, out));
        break;
      }
      case 6: {
        const char* ops[] = {"Mul", "Add", "Sub"};
        const char* which = ops[in_.next() % 3];
        fields_.push_back(node(which, operands(2), out));
        break;
      }
      case 7: constant_of_shape(out); break;
      case 8: fields_.push_back(node("Expand", operands(2), out)); break;
      case 9: fields_.push_back(node("Reshape", operands(2), out)); break;
      case 10: {
        const std::vector<std::string> inputs = operands(2);
        fields_.push_back(node("Gather", inputs, out, int_attribute("axis", in_.value() % 3)));
        break;
      }
      case 11: fields_.push_back(node("Slice", operands(3), out)); break;
      case 12: fields_.push_back(node("MatMul", operands(2), out)); break;
      case 13: fields_.push_back(node("Unsqueeze", operands(2), out)); break;
      case 14: {  // an operator off the list
        const char* ops[] = {"Range", "Tile", "Squeeze", "Resize"};
        const char* which = ops[in_.next() % 4];
        fields_.push_back(node(which, operands(2), out));
        unlisted_ = true;
        break;
      }
      case 15: {  // a listed operator holding a subgraph
        const std::string x = any();
        const std::string body = vector_constant(out + "s", values());
        fields_.push_back(node("Identity", {x}, out, field(5, field(1, std::string("body")) + field(6, body))));
        unlisted_ = true;
        break;
      }
    }
    names_.push_back(out);
    return true;
  }

  std::string bytes() const {
    std::string graph = graph_input("input");
    for (const std::string& f : fields_) graph += f;
    return model(graph);
  }
  // Whether the graph holds an operator off the list or a subgraph: it must be refused.
  bool unlisted() const { return unlisted_; }
  // The least an accepting scan counts: the largest ConstantOfShape of a known vector.
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
  // A name an earlier step defined, or the graph input.
  std::string any() {
    const std::uint8_t b = in_.next();
    return names_.empty() || b == 0xFF ? std::string("input") : names_[b % names_.size()];
  }
  std::vector<std::string> operands(std::size_t n) {
    std::vector<std::string> names;
    for (std::size_t i = 0; i < n; ++i) names.push_back(any());  // in order: the program's bytes decide
    return names;
  }
  // Floats of those dims (a negative one makes the graph refused, so it never counts).
  static std::uint64_t filled_bytes(const std::vector<std::int64_t>& dims) {
    std::uint64_t n = 4;
    for (const std::int64_t d : dims) n = mul_sat(n, d < 0 ? 0 : static_cast<std::uint64_t>(d));
    return n;
  }
  void constant_of_shape(const std::string& out) {
    const std::uint8_t b = in_.next();
    if (!vectors_.empty() && b & 1) {
      const Vector& v = vectors_[b / 2 % vectors_.size()];
      fields_.push_back(node("ConstantOfShape", {v.name}, out));
      expected_ = std::max(expected_, filled_bytes(v.values));
    } else {
      const std::string x = any();
      fields_.push_back(node("ConstantOfShape", {x}, out));
    }
  }

  Bytes& in_;
  std::vector<std::string> fields_, names_;
  std::vector<Vector> vectors_;
  std::uint64_t expected_ = 0;
  bool unlisted_ = false;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Bytes in(data, size);
  GraphProgram program(in);
  bool refused = false;
  std::uint64_t previous = 0;
  while (program.step()) {
    const std::string m = program.bytes();
    try {
      const OnnxModelScan s = scan_onnx_model(reinterpret_cast<const std::uint8_t*>(m.data()), m.size(), {{"input", {-1, 3}}});
      FUZZ_CHECK(!refused);              // a refused graph stays refused
      FUZZ_CHECK(!program.unlisted());   // an operator off the list is never accepted
      FUZZ_CHECK(s.bytes >= previous);   // one more node never lowers the total
      FUZZ_CHECK(s.bytes >= program.expected());  // saturated, never wrapped
      FUZZ_CHECK(s.largest_bytes <= s.bytes);
      previous = s.bytes;
    } catch (const softdeca::Error&) {
      refused = true;
    }
  }
  return 0;
}
