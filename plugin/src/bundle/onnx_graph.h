// An ONNX graph as the bundle checks see it (read from the protobuf by onnx_model_scan.cpp):
// nodes with their operator and attributes, initializers, graph inputs, and for every tensor
// a static type. Short integer tensors (shapes, axes, indices) also carry their values, so
// that shapes computed inside the graph are known before ONNX Runtime sees it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace softdeca::bundle::onnx {

// Integer tensors of at most this many elements carry their values.
constexpr std::size_t kMaxValues = 64;
// Tensors of more dimensions are refused (the exporter writes at most 4).
constexpr std::size_t kMaxRank = 64;

// TensorProto.DataType values the networks' tensors may have.
enum DataType : int {
  kFloat = 1, kUint8 = 2, kInt8 = 3, kUint16 = 4, kInt16 = 5, kInt32 = 6, kInt64 = 7,
  kBool = 9, kFloat16 = 10, kDouble = 11, kUint32 = 12, kUint64 = 13, kBfloat16 = 16,
};
// Bytes per element of an accepted type, 0 for any other (strings, complex, 4- and 8-bit floats).
std::uint64_t element_size(std::int64_t dtype);
bool is_integer(std::int64_t dtype);  // integer or bool: the types whose values are carried
// Whether an integer value is one `dtype` holds (ONNX Runtime would wrap it otherwise).
bool holds(std::int64_t dtype, std::int64_t value);

struct Tensor {
  Tensor() = default;
  Tensor(std::int64_t type, std::vector<std::uint64_t> shape) : dtype(type), dims(std::move(shape)) {}

  std::int64_t dtype = kFloat;
  std::vector<std::uint64_t> dims;  // static, every one
  bool known = false;               // `values` holds every element (row-major)
  std::vector<std::int64_t> values;

  std::uint64_t elements() const;  // saturating
  std::uint64_t bytes() const;     // saturating
};

struct Attribute {
  enum Kind { kInt, kInts, kFloat, kFloats, kString, kTensor } kind = kInt;
  std::int64_t i = 0;
  std::vector<std::int64_t> ints;
  std::size_t floats = 0;  // how many (values do not matter here)
  std::string s;
  Tensor t;
};

struct Node {
  std::string name, op, domain;
  std::vector<std::string> inputs, outputs;  // "" for an optional input left out
  std::map<std::string, Attribute> attributes;

  std::string label() const;  // "<op> node '<name or first output>'" for messages
};

struct GraphInput {
  std::string name;
  std::int64_t dtype = 0;  // of a tensor type; 0 when the type is no tensor or not given
};

struct Initializer {
  std::string name;
  Tensor tensor;
};

struct Graph {
  std::vector<Node> nodes;
  std::vector<Initializer> initializers;
  std::vector<GraphInput> inputs;
};

// A name from the file, made safe to print: printable ASCII, at most 64 characters.
std::string printable(const std::string& name);

// Saturating arithmetic for sizes.
std::uint64_t add_sat(std::uint64_t a, std::uint64_t b);
std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b);

}  // namespace softdeca::bundle::onnx
