// Sizes that an ONNX graph computes from constants, for the memory budget (onnx_model_scan.h):
// ONNX Runtime folds constant subgraphs while it creates a session, so a few bytes of graph
// can ask for gigabytes before any input exists (a Range to 2^28, a Tile by 2^20, a
// ConstantOfShape of a Shape). The producers whose output size follows from constant inputs
// are evaluated here, in graph order, from the constants and static shapes the scan collects;
// what depends on run-time inputs stays unknown (docs/security.md, "Limits of the budget").
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace softdeca::runtime {

struct FoldNode {
  std::string op;
  std::vector<std::string> inputs, outputs;
  std::map<std::string, std::int64_t> ints;  // integer attributes (axis, start, end)
  std::vector<double> value;                 // a Constant's values, when short and numeric
  bool has_value = false;
  std::vector<std::uint64_t> value_dims;     // a Constant's dims
  std::uint64_t value_element_bytes = 4;     // a Constant's (or ConstantOfShape's) element size
};

class ConstantSizes {
 public:
  // A constant's values (short numeric tensors only) and any tensor's static shape.
  void values(const std::string& name, std::vector<double> v) { values_[name] = std::move(v); }
  void shape(const std::string& name, std::vector<std::uint64_t> dims, std::uint64_t element_bytes);
  void node(FoldNode n) { nodes_.push_back(std::move(n)); }

  // Evaluates the nodes in order; produced(output, bytes) for each output whose size follows
  // from constants (sizes saturate at UINT64_MAX).
  void evaluate(const std::function<void(const std::string&, std::uint64_t)>& produced);

 private:
  struct Shape {
    std::vector<std::uint64_t> dims;
    std::uint64_t element_bytes = 4;
  };
  const std::vector<double>* values_of(const std::string& name) const;
  const Shape* shape_of(const std::string& name) const;
  void output(const std::string& name, std::vector<std::uint64_t> dims, std::uint64_t element_bytes,
              const std::function<void(const std::string&, std::uint64_t)>& produced);
  void step(const FoldNode& n, const std::function<void(const std::string&, std::uint64_t)>& produced);

  std::map<std::string, std::vector<double>> values_;
  std::map<std::string, Shape> shapes_;
  std::vector<FoldNode> nodes_;
};

}  // namespace softdeca::runtime
