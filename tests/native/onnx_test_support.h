// A few protobuf fields, enough for tests to write (hostile) ONNX graphs byte by byte.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

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

// ONNX messages (onnx.proto's field numbers).
constexpr std::uint64_t kFloat = 1, kInt64 = 7;

// Little-endian int64 values, a TensorProto's raw_data.
inline std::string int64s(const std::vector<std::int64_t>& values) {
  std::string raw;
  for (const std::int64_t v : values)
    for (int i = 0; i < 8; ++i) raw += static_cast<char>(static_cast<std::uint64_t>(v) >> (8 * i));
  return raw;
}
// TensorProto: dims, element type, name and raw data (none: declared, not stored).
inline std::string tensor(const std::string& name, std::uint64_t dtype, const std::vector<std::uint64_t>& dims,
                          const std::string& raw = "") {
  std::string t;
  for (const std::uint64_t d : dims) t += field(1, d);
  t += field(2, dtype) + field(8, name);
  if (!raw.empty()) t += field(9, raw);
  return t;
}
// An int64 vector tensor (a shape, axes, indices) of the given values.
inline std::string int64_vector(const std::string& name, const std::vector<std::int64_t>& values) {
  return tensor(name, kInt64, {values.size()}, int64s(values));
}
// AttributeProto fields of a node: an integer, integers, a string, a tensor.
inline std::string int_attribute(const std::string& name, std::int64_t v) {
  return field(5, field(1, name) + field(3, static_cast<std::uint64_t>(v)) + field(20, 2));
}
inline std::string ints_attribute(const std::string& name, const std::vector<std::int64_t>& values) {
  std::string a = field(1, name);
  for (const std::int64_t v : values) a += field(8, static_cast<std::uint64_t>(v));
  return field(5, a + field(20, 7));
}
inline std::string string_attribute(const std::string& name, const std::string& value) {
  return field(5, field(1, name) + field(4, value) + field(20, 3));
}
inline std::string tensor_attribute(const std::string& name, const std::string& value_tensor) {
  return field(5, field(1, name) + field(5, value_tensor) + field(20, 4));
}
// A GraphProto `node` field: inputs ("" leaves an optional one out), one output, the
// operator, attributes.
inline std::string node(const std::string& op, const std::vector<std::string>& inputs, const std::string& output,
                        const std::string& attributes = "") {
  std::string n;
  for (const std::string& i : inputs) n += field(1, i);
  return field(1, n + field(2, output) + field(4, op) + attributes);
}
// A Constant node whose value is the tensor; an initializer.
inline std::string constant(const std::string& output, const std::string& value_tensor) {
  return node("Constant", {}, output, tensor_attribute("value", value_tensor));
}
inline std::string initializer(const std::string& t) { return field(5, t); }
// A graph input of a tensor type (its dims are the contract's).
inline std::string graph_input(const std::string& name, std::uint64_t dtype = kFloat) {
  return field(11, field(1, name) + field(2, field(1, field(1, dtype))));
}
// ModelProto: IR version 8, the default operator set at `opset`, one graph of these fields.
inline std::string model(const std::string& graph_fields, std::uint64_t opset = 17) {
  return field(1, 8) + field(8, field(2, opset)) + field(7, field(2, std::string("g")) + graph_fields);
}

// Constants of int64 values inside the graph, and a float tensor filled to constant dims.
inline std::string vector_constant(const std::string& name, const std::vector<std::int64_t>& values) {
  return constant(name, int64_vector("", values));
}
inline std::string scalar_constant(const std::string& name, std::int64_t value) {
  return constant(name, tensor("", kInt64, {}, int64s({value})));
}
inline std::string filled(const std::string& name, const std::vector<std::int64_t>& dims) {
  return vector_constant(name + "_dims", dims) + node("ConstantOfShape", {name + "_dims"}, name);
}

// Graphs of a few hundred bytes that ONNX Runtime's constant folding would turn into 2 to 4 GiB
// (docs/security.md): each is refused for an operator off the list, or counted at its size
// (its largest tensor is 'red_big'). Names start with "red_", so they can join a real graph.
struct RedTeamGraph {
  const char* what;
  std::string fields;
  const char* refused_operator;  // null: refused by the memory budget
};
inline std::vector<RedTeamGraph> red_team_graphs() {
  constexpr std::int64_t n = 3 << 13;  // n x n floats: 2.25 GiB
  std::string concat = filled("red_x0", {1 << 20});
  for (int i = 1; i <= 9; ++i)
    concat += node("Concat", {"red_x" + std::to_string(i - 1), "red_x" + std::to_string(i - 1)},
                   i == 9 ? "red_big" : "red_x" + std::to_string(i), int_attribute("axis", 0));
  return {
      {"Range to Add(c, c)",
       scalar_constant("red_0", 0) + scalar_constant("red_c", n * n / 2) + scalar_constant("red_1", 1) +
           node("Add", {"red_c", "red_c"}, "red_limit") + node("Range", {"red_0", "red_limit", "red_1"}, "red_big"),
       "Range"},
      {"ConstantOfShape of a Mul", vector_constant("red_s", {n}) + node("Mul", {"red_s", "red_s"}, "red_dims") +
                                        node("ConstantOfShape", {"red_dims"}, "red_big"),
       nullptr},
      {"ConstantOfShape of a Reshape",
       vector_constant("red_s", {n, n}) + vector_constant("red_to", {2}) + node("Reshape", {"red_s", "red_to"}, "red_dims") +
           node("ConstantOfShape", {"red_dims"}, "red_big"),
       nullptr},
      {"ConstantOfShape of a Squeeze",
       constant("red_s", tensor("", kInt64, {1, 2}, int64s({n, n}))) + node("Squeeze", {"red_s"}, "red_dims") +
           node("ConstantOfShape", {"red_dims"}, "red_big"),
       "Squeeze"},
      {"ConstantOfShape of a Gather",
       vector_constant("red_s", {n, 7, n}) + vector_constant("red_at", {0, 2}) +
           node("Gather", {"red_s", "red_at"}, "red_dims") + node("ConstantOfShape", {"red_dims"}, "red_big"),
       nullptr},
      {"a Concat of itself, nine times", concat, nullptr},
      {"a MatMul outer product", filled("red_a", {n, 1}) + filled("red_b", {1, n}) + node("MatMul", {"red_a", "red_b"}, "red_big"),
       nullptr},
  };
}

}  // namespace softdeca::test
