// The memory budget counts what constant-foldable producers would allocate (docs/security.md,
// "Bundles"): a few hundred bytes of graph whose Range, Tile, Shape-derived ConstantOfShape,
// Expand or Resize asks for a gibibyte or more are estimated at that size, one test per family.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include "bundle/onnx_model_scan.h"
#include "onnx_test_support.h"

using namespace softdeca::runtime;
using softdeca::test::field;

namespace {

constexpr std::uint64_t kGiB = std::uint64_t{1} << 30;

// TensorProto with dims, a data type (1 float, 7 int64) and raw little-endian data.
std::string tensor(const std::string& name, std::uint64_t dtype, std::initializer_list<std::uint64_t> dims,
                   const std::string& raw = "") {
  std::string t;
  for (std::uint64_t d : dims) t += field(1, d);
  t += field(2, dtype) + field(8, name);
  if (!raw.empty()) t += field(9, raw);
  return t;
}
std::string int64s(std::initializer_list<std::int64_t> values) {
  std::string raw;
  for (std::int64_t v : values)
    for (int i = 0; i < 8; ++i) raw += static_cast<char>(static_cast<std::uint64_t>(v) >> (8 * i));
  return raw;
}
std::string floats(std::initializer_list<float> values) {
  std::string raw;
  for (float v : values) {
    char b[4];
    std::memcpy(b, &v, 4);
    raw.append(b, 4);
  }
  return raw;
}
// NodeProto: inputs, one output, the operator, attributes.
std::string node(const std::string& op, std::initializer_list<std::string> inputs, const std::string& output,
                 const std::string& attributes = "") {
  std::string n;
  for (const std::string& i : inputs) n += field(1, i);
  return field(1, n + field(2, output) + field(4, op) + attributes);
}
// A Constant node whose value is the tensor.
std::string constant(const std::string& output, const std::string& value_tensor) {
  return node("Constant", {}, output, field(5, field(1, std::string("value")) + field(5, value_tensor)));
}
std::string initializer(const std::string& t) { return field(5, t); }

OnnxModelScan scan(const std::string& graph_fields) {
  const std::string model = field(1, 8) + field(7, field(2, std::string("g")) + graph_fields);
  return scan_onnx_model(reinterpret_cast<const std::uint8_t*>(model.data()), model.size());
}

TEST(OnnxConstantSizes, RangeOfConstantsIsCounted) {
  const std::string ints = constant("start", tensor("", 7, {}, int64s({0}))) +
                           constant("limit", tensor("", 7, {}, int64s({std::int64_t{1} << 28}))) +
                           constant("delta", tensor("", 7, {}, int64s({1}))) +
                           node("Range", {"start", "limit", "delta"}, "r");
  const OnnxModelScan s = scan(ints);
  EXPECT_EQ(s.shaped_bytes, 2 * kGiB);  // 2^28 elements of up to 8 bytes
  EXPECT_EQ(s.largest_tensor, "r");
  // The same with float initializers (no Constant nodes).
  const std::string f = initializer(tensor("a", 1, {}, floats({0}))) + initializer(tensor("b", 1, {}, floats({268435456.0f}))) +
                        initializer(tensor("c", 1, {}, floats({1}))) + node("Range", {"a", "b", "c"}, "r");
  EXPECT_EQ(scan(f).shaped_bytes, 2 * kGiB);
}

TEST(OnnxConstantSizes, TileByConstantRepeatsIsCounted) {
  const std::string g = initializer(tensor("x", 1, {4}, floats({1, 2, 3, 4}))) +
                        initializer(tensor("repeats", 7, {1}, int64s({std::int64_t{1} << 26}))) +
                        node("Tile", {"x", "repeats"}, "tiled");
  EXPECT_EQ(scan(g).shaped_bytes, kGiB);  // 4 x 2^26 floats
}

TEST(OnnxConstantSizes, ShapeDerivedSizesAreCounted) {
  // Shape of a declared 1024 x 1024 initializer, with 256 appended: a 1 GiB ConstantOfShape.
  const std::string g = initializer(tensor("x", 1, {1024, 1024})) + node("Shape", {"x"}, "s") +
                        constant("extra", tensor("", 7, {1}, int64s({256}))) + node("Concat", {"s", "extra"}, "dims",
                                                                                       field(5, field(1, std::string("axis")) + field(3, 0))) +
                        node("ConstantOfShape", {"dims"}, "filled");
  const OnnxModelScan s = scan(g);
  EXPECT_EQ(s.shaped_bytes, kGiB);
  EXPECT_EQ(s.largest_tensor, "filled");
}

TEST(OnnxConstantSizes, ExpandBroadcastsWithTheInputsShape) {
  // [1, 4096] expanded by [65536, 1]: [65536, 4096] floats, 1 GiB (the shape alone says 256 KiB).
  const std::string g = initializer(tensor("x", 1, {1, 4096})) +
                        initializer(tensor("shape", 7, {2}, int64s({65536, 1}))) + node("Expand", {"x", "shape"}, "big");
  EXPECT_EQ(scan(g).shaped_bytes, kGiB);
}

TEST(OnnxConstantSizes, ResizeToConstantSizesIsCounted) {
  const std::string g = initializer(tensor("x", 1, {1, 1, 2, 2})) +
                        initializer(tensor("sizes", 7, {4}, int64s({1, 1, 16384, 16384}))) +
                        node("Resize", {"x", "", "", "sizes"}, "up");
  EXPECT_EQ(scan(g).shaped_bytes, kGiB);
  // Scales on a tensor of static shape: 2 x 2 by 8192 in each spatial dimension.
  const std::string by_scales = initializer(tensor("x", 1, {1, 1, 2, 2})) +
                                initializer(tensor("scales", 1, {4}, floats({1, 1, 8192, 8192}))) +
                                node("Resize", {"x", "", "scales"}, "up");
  EXPECT_EQ(scan(by_scales).shaped_bytes, kGiB);
}

// Sizes that depend on run-time inputs stay unknown: nothing is made up for them.
TEST(OnnxConstantSizes, RunTimeSizesAreNotGuessed) {
  const std::string g = node("Range", {"input_a", "input_b", "input_c"}, "r") + node("Tile", {"input_x", "input_r"}, "t");
  EXPECT_EQ(scan(g).shaped_bytes, 0u);
}

}  // namespace
