// What an ONNX model file asks of the host, read from its protobuf bytes before ONNX Runtime
// sees them. A bundle comes from anywhere: ONNX Runtime would resolve an external-data
// location against the working directory, and fold constant subgraphs of any size while it
// creates a session, so both are decided here first (docs/security.md, "Bundles"):
// - tensors whose data would be read from other files (external data) are listed;
// - the graph may hold only what the product's exporter writes: operators of the allow-list
//   (onnx_operators.h) at opset 17, no functions, subgraphs, sparse or training data;
// - every tensor's shape is inferred statically from the shapes the runtime feeds, and their
//   sizes summed (onnx_static_sizes.h): the bound the memory budget is checked against.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "bundle/manifest.h"

namespace softdeca::bundle {

// The batch the runtime feeds every network with (a contract's free dimension).
constexpr std::int64_t kFedBatch = 1;

struct OnnxModelScan {
  std::vector<std::string> external_tensors;  // names of tensors with external data; when any,
                                              // nothing else is checked or counted
  std::uint64_t bytes = 0;                    // every tensor at its static size (saturating)
  std::uint64_t weight_bytes = 0;             // the stored constants (initializers and Constant
                                              // nodes' values): what one run reads of its weights
  std::string largest_tensor;                 // the largest of them, for messages
  std::uint64_t largest_bytes = 0;
  std::size_t tensors = 0;
};

// Reads ModelProto; `inputs` are the network's contract inputs (shapes with free dimensions
// fed as kFedBatch). Throws softdeca::Error(SOFTDECA_ERROR_FORMAT) for bytes that are not a
// well-formed protobuf message of that shape, for anything outside what the exporter writes
// (naming it), and for a tensor without a static shape.
OnnxModelScan scan_onnx_model(const std::uint8_t* data, std::size_t size, const std::vector<TensorSpec>& inputs);

}  // namespace softdeca::bundle
