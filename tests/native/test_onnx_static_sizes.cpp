// The ONNX check a bundle's networks pass before ONNX Runtime sees them (docs/security.md,
// "Bundles"): only the exporter's operators, every tensor's shape static, and their sizes
// summed. Graphs of a few hundred bytes that would fold to gigabytes are counted at that size
// whichever way their shapes are computed; operators off the list are refused by name; the
// committed bundle passes.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bundle/manifest.h"
#include "bundle/onnx_model_scan.h"
#include "bundle/onnx_operators.h"
#include "core/error.h"
#include "onnx_test_support.h"

using namespace softdeca::bundle;
using namespace softdeca::test;

namespace {

constexpr std::uint64_t kGiB = std::uint64_t{1} << 30;

OnnxModelScan scan(const std::string& graph_fields, const std::vector<TensorSpec>& inputs = {},
                   std::uint64_t opset = 17) {
  const std::string m = model(graph_fields, opset);
  return scan_onnx_model(reinterpret_cast<const std::uint8_t*>(m.data()), m.size(), inputs);
}
// The error a graph is refused with ("" when it is not).
std::string refusal(const std::string& graph_fields, const std::vector<TensorSpec>& inputs = {}, std::uint64_t opset = 17) {
  try {
    scan(graph_fields, inputs, opset);
  } catch (const softdeca::Error& e) {
    EXPECT_EQ(e.status(), SOFTDECA_ERROR_FORMAT);
    return e.what();
  }
  return "";
}
}  // namespace

// ---- graphs that fold to gigabytes ------------------------------------------------------------

TEST(OnnxStaticSizes, RedTeamGraphsAreRefusedOrCountedAtTheirSize) {
  for (const RedTeamGraph& g : red_team_graphs()) {
    SCOPED_TRACE(g.what);
    if (g.refused_operator) {
      const std::string error = refusal(g.fields);
      EXPECT_NE(error.find(std::string("operator '") + g.refused_operator + "'"), std::string::npos) << error;
      EXPECT_NE(error.find("is not one a bundle's networks may use"), std::string::npos) << error;
      continue;
    }
    const OnnxModelScan s = scan(g.fields);
    EXPECT_EQ(s.largest_tensor, "red_big");
    EXPECT_GE(s.largest_bytes, 2 * kGiB);
    EXPECT_GE(s.bytes, s.largest_bytes);
  }
}

TEST(OnnxStaticSizes, ShapesComputedByMulReshapeAndGatherAreExact) {
  // [2^14] * [2^14]: a 2^28-element float tensor, 1 GiB.
  const OnnxModelScan mul = scan(vector_constant("s", {1 << 14}) + node("Mul", {"s", "s"}, "dims") +
                                 node("ConstantOfShape", {"dims"}, "big"));
  EXPECT_EQ(mul.largest_tensor, "big");
  EXPECT_EQ(mul.largest_bytes, kGiB);
  EXPECT_EQ(mul.bytes, kGiB + 8 + 8);
  // [2^15, 2^15] floats, 4 GiB, reshaped or gathered on the way.
  const OnnxModelScan reshaped = scan(vector_constant("s", {1 << 15, 1 << 15}) + vector_constant("to", {2}) +
                                      node("Reshape", {"s", "to"}, "dims") + node("ConstantOfShape", {"dims"}, "big"));
  EXPECT_EQ(reshaped.largest_bytes, 4 * kGiB);
  const OnnxModelScan gathered = scan(vector_constant("s", {1 << 15, 7, 1 << 15}) + vector_constant("at", {0, 2}) +
                                      node("Gather", {"s", "at"}, "dims") + node("ConstantOfShape", {"dims"}, "big"));
  EXPECT_EQ(gathered.largest_bytes, 4 * kGiB);
}

TEST(OnnxStaticSizes, SelfConcatIsCountedAtEverySize) {
  // 4 MiB doubled ten times: the last is 4 GiB, and all of them together twice that.
  std::string g = filled("x0", {1 << 20});
  for (int i = 1; i <= 10; ++i) {
    const std::string in = "x" + std::to_string(i - 1);
    g += node("Concat", {in, in}, "x" + std::to_string(i), int_attribute("axis", 0));
  }
  const OnnxModelScan s = scan(g);
  EXPECT_EQ(s.largest_tensor, "x10");
  EXPECT_EQ(s.largest_bytes, 4 * kGiB);
  EXPECT_EQ(s.bytes, 8 * kGiB - 4 * (std::uint64_t{1} << 20) + 8);
}

TEST(OnnxStaticSizes, ExpandAndSliceOfComputedShapesAreCounted) {
  // [1, 4096] expanded by a shape sliced out of a longer vector: [65536, 4096] floats, 1 GiB.
  const std::string g = filled("x", {1, 4096}) + vector_constant("v", {9, 65536, 1, 9}) + vector_constant("from", {1}) +
                        vector_constant("to", {3}) + node("Slice", {"v", "from", "to"}, "dims") +
                        node("Expand", {"x", "dims"}, "big");
  EXPECT_EQ(scan(g).largest_bytes, kGiB);
}

// ---- static shapes -----------------------------------------------------------------------

TEST(OnnxStaticSizes, InputsAreFedAtTheContractsShapesWithBatchOne) {
  const std::vector<TensorSpec> contract{{"weights", {-1, 52}}, {"parameters", {100, 18}}};
  const std::string g = graph_input("weights") + graph_input("parameters") + initializer(tensor("w", kFloat, {52, 1000})) +
                        node("MatMul", {"weights", "w"}, "h") + node("Shape", {"parameters"}, "p_shape") +
                        node("ConstantOfShape", {"p_shape"}, "p_zeros");
  const OnnxModelScan s = scan(g, contract);
  // inputs 52 + 1800 floats, w 52000, h 1000, the shape 2 int64, the zeros 1800 floats
  EXPECT_EQ(s.bytes, 4 * (52 + 1800 + 52000 + 1000 + 1800) + 16u);
  EXPECT_EQ(s.tensors, 6u);
  // An input the runtime does not feed has no shape.
  EXPECT_NE(refusal(g + graph_input("extra"), contract).find("graph input 'extra' is not one the runtime feeds"),
            std::string::npos);
}

TEST(OnnxStaticSizes, WeightsAreTheStoredConstants) {
  // Initializers (float, float16) and Constant nodes' values count; a tensor computed from a
  // constant (ConstantOfShape's zeros) and the inputs do not.
  const std::vector<TensorSpec> contract{{"weights", {-1, 52}}};
  const std::string g = graph_input("weights") + initializer(tensor("w", kFloat, {52, 1000})) +
                        initializer(tensor("table", 10, {8, 3})) + node("MatMul", {"weights", "w"}, "h") +
                        vector_constant("dims", {4, 5}) + node("ConstantOfShape", {"dims"}, "zeros");
  EXPECT_EQ(scan(g, contract).weight_bytes, 4 * 52000 + 2 * 24 + 8 * 2u);
}

TEST(OnnxStaticSizes, ShapesFromRunTimeValuesAreRefused) {
  // A Reshape to a shape read from an input's values: unknown until it runs.
  const std::vector<TensorSpec> contract{{"x", {4}}};
  const std::string g = graph_input("x") + node("Cast", {"x"}, "xi", int_attribute("to", 7)) +
                        node("Reshape", {"x", "xi"}, "y");
  const std::string error = refusal(g, contract);
  EXPECT_NE(error.find("Reshape node 'y': its shape is computed from values not known at load"), std::string::npos)
      << error;
  // ConstantOfShape of a float constant cast to integers: floats carry no values.
  const std::string cast = initializer(tensor("f", kFloat, {1}, std::string("\0\0\x80\x3f", 4))) +
                           node("Cast", {"f"}, "n", int_attribute("to", 7)) + node("ConstantOfShape", {"n"}, "z");
  EXPECT_NE(refusal(cast).find("not known at load"), std::string::npos);
}

TEST(OnnxStaticSizes, RulesFollowOnnxSemantics) {
  // Reshape with 0 (copy) and -1 (infer); Unsqueeze; negative Slice steps; Gather along an
  // axis; Einsum; Gemm with transposes; ReduceSum over an axis, kept.
  const std::string g =
      filled("x", {2, 3, 4}) + vector_constant("shape", {0, -1}) + node("Reshape", {"x", "shape"}, "r") +  // [2, 12]
      vector_constant("axes", {0, -1}) + node("Unsqueeze", {"r", "axes"}, "u") +                         // [1, 2, 12, 1]
      vector_constant("s", {-1}) + vector_constant("e", {-100}) + vector_constant("a", {2}) +
      vector_constant("st", {-5}) + node("Slice", {"u", "s", "e", "a", "st"}, "sl") +  // [1, 2, 3, 1]: 11, 6, 1
      vector_constant("idx", {1, 0, 1, 1}) + node("Gather", {"x", "idx"}, "ga", int_attribute("axis", 1)) +  // [2, 4, 4]
      node("Einsum", {"x", "ga"}, "es", string_attribute("equation", "nij,nkj->nik")) +  // [2, 3, 4]
      filled("m", {5, 7}) + filled("n", {9, 7}) +
      node("Gemm", {"m", "n"}, "gm", int_attribute("transB", 1)) +  // [5, 9]
      vector_constant("one", {1}) + node("ReduceSum", {"x", "one"}, "rs");  // [2, 1, 4]
  const OnnxModelScan s = scan(g);
  const std::uint64_t floats = 24 + 24 + 24 + 6 + 32 + 24 + 35 + 63 + 45 + 8;
  const std::uint64_t int64_vectors = 3 + 2 + 2 + 1 + 1 + 1 + 1 + 4 + 2 + 2 + 1;
  EXPECT_EQ(s.bytes, 4 * floats + 8 * int64_vectors);
  // Shapes that do not go together are refused, by node.
  EXPECT_NE(refusal(filled("a", {2, 3}) + filled("b", {4, 5}) + node("MatMul", {"a", "b"}, "p")).find("MatMul node 'p'"),
            std::string::npos);
  EXPECT_NE(refusal(filled("a", {2, 3}) + filled("b", {3, 2}) + node("Add", {"a", "b"}, "p")).find("do not broadcast"),
            std::string::npos);
  EXPECT_NE(refusal(filled("a", {6}) + vector_constant("to", {4, -1}) + node("Reshape", {"a", "to"}, "p"))
                .find("no dimension in place of -1"),
            std::string::npos);
  EXPECT_NE(refusal(vector_constant("v", {1, 2}) + vector_constant("i", {2}) + node("Gather", {"v", "i"}, "p"))
                .find("index 2 is outside"),
            std::string::npos);
}

TEST(OnnxStaticSizes, ValuesCarriedThroughShapeArithmetic) {
  // torch's Expand export: Where(Equal(shape, -1), ones, shape) of a shape built by Concat of
  // a Shape and constants, the batch fed as 1.
  const std::vector<TensorSpec> contract{{"w", {-1, 52}}};
  const std::string g = graph_input("w") + node("Shape", {"w"}, "ws") + vector_constant("zero", {0}) +
                        node("Gather", {"ws", "zero"}, "batch") + vector_constant("rest", {-1, 3}) +
                        node("Concat", {"batch", "rest"}, "shape", int_attribute("axis", 0)) +
                        vector_constant("minus", {-1}) + node("Equal", {"shape", "minus"}, "is_free") +
                        node("ConstantOfShape", {"three"}, "ones",
                             tensor_attribute("value", tensor("", kInt64, {1}, int64s({1})))) +
                        vector_constant("three", {3}) + node("Where", {"is_free", "ones", "shape"}, "target") +
                        filled("x", {1, 1, 3}) + node("Expand", {"x", "target"}, "y");
  const OnnxModelScan s = scan(g, contract);
  // y is [1, 1, 3]: the -1 became 1 through Where.
  EXPECT_EQ(s.largest_tensor, "w");
  EXPECT_EQ(s.largest_bytes, 4 * 52u);
}

// ---- what the exporter never writes ----------------------------------------------------------

TEST(OnnxStaticSizes, OtherDomainsOpsetsFunctionsAndSubgraphsAreRefused) {
  const std::string foreign = field(1, field(1, std::string("x")) + field(2, std::string("y")) +
                                           field(4, std::string("Gelu")) + field(7, std::string("com.microsoft")));
  EXPECT_NE(refusal(filled("x", {1}) + foreign).find("operator 'Gelu' of domain 'com.microsoft'"), std::string::npos);
  EXPECT_NE(refusal(filled("x", {1}), {}, 11).find("imports ONNX opset 11"), std::string::npos);
  // An Identity with a graph attribute, an If (not listed either).
  const std::string sub = field(5, field(1, std::string("body")) + field(6, field(2, std::string("g2"))));
  EXPECT_NE(refusal(filled("x", {1}) + node("Identity", {"x"}, "y", sub)).find("holds a subgraph"), std::string::npos);
  EXPECT_NE(refusal(filled("x", {1}) + node("If", {"x"}, "y", sub)).find("operator 'If'"), std::string::npos);
  // Functions, training information, sparse initializers.
  const std::string m = model(filled("x", {1})) + field(25, field(1, std::string("f")));
  try {
    scan_onnx_model(reinterpret_cast<const std::uint8_t*>(m.data()), m.size(), {});
    ADD_FAILURE() << "a model with functions was accepted";
  } catch (const softdeca::Error& e) {
    EXPECT_NE(std::string(e.what()).find("defines functions"), std::string::npos) << e.what();
  }
  EXPECT_NE(refusal(field(15, field(1, tensor("v", kFloat, {4})))).find("sparse initializer"), std::string::npos);
  // A tensor split over two fields (protobuf would merge them) is refused.
  const std::string twice = field(5, field(1, std::string("value")) + field(5, tensor("", kInt64, {1})) +
                                         field(5, field(1, std::uint64_t{1} << 20)));
  EXPECT_NE(refusal(node("Constant", {}, "c", twice)).find("given twice"), std::string::npos);
}

TEST(OnnxStaticSizes, TheListIsTheExportersOperators) {
  // What torch.onnx writes for every configuration of the networks (docs/bundle.md).
  const std::vector<std::string> expected{
      "Add", "Cast", "Clip", "Concat", "Constant", "ConstantOfShape", "Cos", "Div", "Einsum", "Elu",
      "Equal", "Expand", "Gather", "Gemm", "Identity", "Log", "MatMul", "Mul", "Neg", "ReduceMean",
      "ReduceSum", "Reshape", "Shape", "Sigmoid", "Sin", "Slice", "Sub", "Unsqueeze", "Where"};
  EXPECT_EQ(onnx::allowed_operators(), expected);
}

// ---- the committed bundle --------------------------------------------------------------------

TEST(OnnxStaticSizes, CommittedBundlePasses) {
  const std::filesystem::path dir = std::filesystem::path(SOFTDECA_REPO_ROOT) / "models" / "softdeca-default";
  const auto read = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  const Manifest mf = parse_manifest(read(dir / "manifest.json"));
  ASSERT_EQ(mf.networks.size(), 10u);
  std::uint64_t total = 0;
  for (const auto& [key, spec] : mf.networks) {
    SCOPED_TRACE(spec.file);
    const std::string bytes = read(dir / spec.file);
    ASSERT_FALSE(bytes.empty());
    const OnnxModelScan s = scan_onnx_model(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), spec.inputs);
    EXPECT_TRUE(s.external_tensors.empty());
    EXPECT_GT(s.bytes, bytes.size() / 2);  // at least its (float16) tables
    total += s.bytes;
    std::printf("%s: %.1f MiB, largest '%s' %.1f MiB\n", spec.file.c_str(), double(s.bytes) / (1 << 20),
                s.largest_tensor.c_str(), double(s.largest_bytes) / (1 << 20));
  }
  EXPECT_LT(total, std::uint64_t{1} << 30);  // docs/security.md gives the figure
  std::printf("committed bundle: %.1f MiB in all its networks' tensors\n", double(total) / (1 << 20));
}
