// What an ONNX model file asks of the host, read from its protobuf bytes before ONNX Runtime
// sees them: tensors whose data would be read from other files (external data), and an
// estimate of the memory its tensors need. A bundle comes from anywhere; ONNX Runtime would
// resolve an external-data location against the working directory and allocate whatever the
// graph declares, so both are decided here first (docs/security.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace softdeca::runtime {

struct OnnxModelScan {
  std::vector<std::string> external_tensors;  // names of tensors with external data
  std::uint64_t initializer_bytes = 0;        // initializers and Constant nodes, by their dims
  std::uint64_t declared_bytes = 0;           // graph inputs, outputs, value_info (free dims: 1)
  std::uint64_t shaped_bytes = 0;             // ConstantOfShape/Expand outputs of constant shape
  std::string largest_tensor;                 // the largest of all the above, for messages
  std::uint64_t largest_bytes = 0;
  std::size_t tensors = 0;                    // tensors and value infos seen

  std::uint64_t total_bytes() const;  // saturating sum
};

// Walks ModelProto (graph, nested subgraphs, functions, training graphs). Throws
// softdeca::Error(SOFTDECA_ERROR_FORMAT) for bytes that are not a well-formed protobuf message
// of that shape (nesting deeper than 32 included). Sizes saturate at UINT64_MAX.
OnnxModelScan scan_onnx_model(const std::uint8_t* data, std::size_t size);

}  // namespace softdeca::runtime
