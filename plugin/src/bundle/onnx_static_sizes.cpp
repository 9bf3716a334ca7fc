#include "bundle/onnx_static_sizes.h"

#include <deque>

#include "bundle/onnx_operators.h"
#include "core/error.h"

namespace softdeca::bundle::onnx {
namespace {

[[noreturn]] void refuse(const std::string& why) { throw Error(SOFTDECA_ERROR_FORMAT, why); }

class Sizes {
 public:
  StaticSizes result;

  void add(const std::string& name, const Tensor& t) {
    if (!tensors_.emplace(name, t).second) refuse("tensor '" + printable(name) + "' is defined twice");
    count(name, t.bytes());
  }
  void count(const std::string& name, std::uint64_t bytes) {
    result.bytes = add_sat(result.bytes, bytes);
    ++result.tensors;
    if (bytes > result.largest_bytes || result.largest.empty()) {
      result.largest_bytes = bytes;
      result.largest = name;
    }
  }
  const Tensor* find(const std::string& name) const {
    const auto it = tensors_.find(name);
    return it == tensors_.end() ? nullptr : &it->second;
  }

 private:
  std::map<std::string, Tensor> tensors_;
};

}  // namespace

StaticSizes static_sizes(const Graph& graph, const std::map<std::string, std::vector<std::uint64_t>>& fed) {
  Sizes sizes;
  for (const Initializer& i : graph.initializers) {
    if (i.name.empty()) sizes.count(i.name, i.tensor.bytes());  // read, though nothing can name it
    else sizes.add(i.name, i.tensor);
  }
  for (const GraphInput& in : graph.inputs) {
    if (sizes.find(in.name)) continue;  // an initializer listed as an input too: its data decide
    const auto it = fed.find(in.name);
    if (it == fed.end()) refuse("graph input '" + printable(in.name) + "' is not one the runtime feeds (docs/bundle.md)");
    if (element_size(in.dtype) == 0) refuse("graph input '" + printable(in.name) + "' is not a tensor of numbers");
    sizes.add(in.name, Tensor{in.dtype, it->second});
  }

  // Dependency order (Kahn): a node is inferred once every tensor it reads is.
  const std::vector<Node>& nodes = graph.nodes;
  std::map<std::string, std::size_t> producer;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Node& n = nodes[i];
    if (n.outputs.size() != 1 || n.outputs[0].empty()) refuse(n.label() + ": one output expected");
    if (sizes.find(n.outputs[0]) || !producer.emplace(n.outputs[0], i).second)
      refuse("tensor '" + printable(n.outputs[0]) + "' is defined twice");
  }
  std::vector<std::size_t> waiting(nodes.size(), 0);
  std::map<std::string, std::vector<std::size_t>> readers;
  std::deque<std::size_t> ready;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    for (const std::string& name : nodes[i].inputs) {
      if (name.empty() || sizes.find(name)) continue;
      if (!producer.count(name))
        refuse(nodes[i].label() + ": input '" + printable(name) + "' is defined nowhere in the graph");
      readers[name].push_back(i);
      ++waiting[i];
    }
    if (waiting[i] == 0) ready.push_back(i);
  }
  std::size_t done = 0;
  for (; !ready.empty(); ++done) {
    const Node& n = nodes[ready.front()];
    ready.pop_front();
    std::vector<const Tensor*> inputs;
    for (const std::string& name : n.inputs) inputs.push_back(name.empty() ? nullptr : sizes.find(name));
    Tensor out;
    try {
      out = infer_output(n, inputs);
    } catch (const Error& e) {
      refuse(n.label() + ": " + e.what());
    }
    sizes.add(n.outputs[0], out);
    const auto it = readers.find(n.outputs[0]);
    if (it == readers.end()) continue;
    for (const std::size_t r : it->second)
      if (--waiting[r] == 0) ready.push_back(r);
  }
  if (done != nodes.size()) refuse("the graph has a cycle");
  return sizes.result;
}

}  // namespace softdeca::bundle::onnx
