// One network of a bundle as an ONNX Runtime session whose inputs and outputs are checked
// against the contract (names, element type, shapes) when it is created.
#pragma once

#include <onnxruntime_cxx_api.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bundle/bundle_files.h"
#include "bundle/manifest.h"

namespace softdeca::runtime {

class OnnxNetwork {
 public:
  // `threads`: intra-op threads of this session (1 for per-frame networks: the runtime
  // parallelises around them). `weight_bytes`: its stored constants, as the bundle scan counted
  // them (bundle::OnnxModelScan). Throws Error(FORMAT) for bytes ONNX Runtime cannot load or a model
  // whose inputs/outputs differ from `spec`.
  OnnxNetwork(Ort::Env& env, const bundle::Bytes& model, const bundle::NetworkSpec& spec, int threads, std::uint64_t weight_bytes);

  const bundle::NetworkSpec& spec() const { return spec_; }
  // What one run reads of the network's weights, at their stored precision.
  std::uint64_t weight_bytes() const { return weight_bytes_; }

  // Tensors over caller memory, created once and reused every frame (no allocation by us).
  // `batch` resolves the free dimension. Buffers must outlive the binding.
  class Binding {
   public:
    Binding() = default;
    bool bound() const { return !inputs_.empty(); }

   private:
    friend class OnnxNetwork;
    std::vector<Ort::Value> inputs_, outputs_;
  };
  Binding bind(const std::vector<const float*>& inputs, const std::vector<float*>& outputs, std::int64_t batch) const;
  void run(Binding& binding) const;

  // One-off evaluation (prepare): same as bind + run.
  void run(const std::vector<const float*>& inputs, const std::vector<float*>& outputs, std::int64_t batch) const;

  static std::size_t element_count(const bundle::TensorSpec& t, std::int64_t batch);

 private:
  bundle::NetworkSpec spec_;
  std::uint64_t weight_bytes_ = 0;
  std::unique_ptr<Ort::Session> session_;
  Ort::MemoryInfo memory_;
  std::vector<const char*> input_names_, output_names_;
};

}  // namespace softdeca::runtime
