// The operators a bundle's networks may use (docs/bundle.md, "Operators"): the ones the
// product's exporter writes (torch.onnx at opset 17, training/softdeca_train/models/bundle.py),
// each with the rule that gives its output's static type from its inputs' types. The list and
// the rules are one table (onnx_operators.cpp): an operator is allowed exactly when it has a
// rule, so every tensor of an accepted graph has a shape known at load.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bundle/onnx_graph.h"

namespace softdeca::bundle::onnx {

// The version of the default domain the rules follow (the exporter's; docs/bundle.md).
constexpr std::int64_t kOpsetVersion = 17;

bool is_allowed_operator(const std::string& op);
std::vector<std::string> allowed_operators();  // in the table's (alphabetical) order

// The output of `node`, whose operator is allowed, from its inputs (null: an optional input
// left out). Throws softdeca::Error(FORMAT) saying what does not fit: a required input left
// out, an attribute of the wrong kind, shapes that do not go together, or an input that
// decides a shape (Reshape's shape, Slice's bounds, ...) whose values are not known at load.
Tensor infer_output(const Node& node, const std::vector<const Tensor*>& inputs);

}  // namespace softdeca::bundle::onnx
