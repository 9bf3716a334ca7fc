// Every tensor of a network's graph at its static size: initializers as declared, graph inputs
// at the shapes the runtime feeds, and each node's output by its operator's rule
// (onnx_operators.h), in dependency order. Whatever ONNX Runtime makes of the graph, constant
// folding included, holds tensors of these sizes, so their sum bounds what the network asks
// for (docs/security.md, "Memory budget").
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bundle/onnx_graph.h"

namespace softdeca::bundle::onnx {

struct StaticSizes {
  std::uint64_t bytes = 0;  // all tensors (saturating)
  std::string largest;      // the largest tensor's name
  std::uint64_t largest_bytes = 0;
  std::size_t tensors = 0;
};

// `fed`: the dimensions of each graph input as the runtime feeds it. Throws
// softdeca::Error(FORMAT) for a graph input the runtime does not feed, a tensor defined twice
// or nowhere, a cycle, or a node whose output has no static shape (onnx_operators.h).
StaticSizes static_sizes(const Graph& graph, const std::map<std::string, std::vector<std::uint64_t>>& fed);

}  // namespace softdeca::bundle::onnx
