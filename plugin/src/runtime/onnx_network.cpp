#include "runtime/onnx_network.h"

#include "core/error.h"

namespace softdeca::runtime {

namespace {
std::string shape_text(const std::vector<std::int64_t>& s) {
  std::string t = "[";
  for (std::size_t i = 0; i < s.size(); ++i) t += (i ? ", " : "") + (s[i] < 0 ? std::string("?") : std::to_string(s[i]));
  return t + "]";
}

// A model dimension satisfies the contract when it is free or equals the fixed size; a free
// contract dimension (the batch) is run with 1, so a model fixed at 1 is fine too.
bool dims_match(const std::vector<std::int64_t>& model, const std::vector<std::int64_t>& want) {
  if (model.size() != want.size()) return false;
  for (std::size_t i = 0; i < want.size(); ++i) {
    if (model[i] < 0) continue;
    if (want[i] < 0 ? model[i] != 1 : model[i] != want[i]) return false;
  }
  return true;
}

void check_side(Ort::Session& session, bool inputs, const std::vector<bundle::TensorSpec>& want,
                const bundle::NetworkSpec& spec) {
  const std::size_t n = inputs ? session.GetInputCount() : session.GetOutputCount();
  const char* side = inputs ? "input" : "output";
  if (n != want.size())
    throw Error(SOFTDECA_ERROR_FORMAT, spec.file + ": the model has " + std::to_string(n) + " " + side + "s, the contract " +
                                           std::to_string(want.size()));
  Ort::AllocatorWithDefaultOptions alloc;
  for (const bundle::TensorSpec& t : want) {
    bool found = false;
    for (std::size_t i = 0; i < n && !found; ++i) {
      auto name = inputs ? session.GetInputNameAllocated(i, alloc) : session.GetOutputNameAllocated(i, alloc);
      if (t.name != name.get()) continue;
      found = true;
      const Ort::TypeInfo info = inputs ? session.GetInputTypeInfo(i) : session.GetOutputTypeInfo(i);
      if (info.GetONNXType() != ONNX_TYPE_TENSOR)
        throw Error(SOFTDECA_ERROR_FORMAT, spec.file + ": " + side + " '" + t.name + "' is not a tensor");
      const auto ts = info.GetTensorTypeAndShapeInfo();
      if (ts.GetElementType() != ONNX_TENSOR_ELEMENT_DATA_TYPE_FLOAT)
        throw Error(SOFTDECA_ERROR_FORMAT, spec.file + ": " + side + " '" + t.name + "' is not float32");
      const auto shape = ts.GetShape();
      if (!dims_match(shape, t.shape))
        throw Error(SOFTDECA_ERROR_FORMAT, spec.file + ": " + side + " '" + t.name + "' has shape " + shape_text(shape) +
                                               ", the contract says " + shape_text(t.shape));
    }
    if (!found) throw Error(SOFTDECA_ERROR_FORMAT, spec.file + ": the model has no " + side + " named '" + t.name + "'");
  }
}
}  // namespace

OnnxNetwork::OnnxNetwork(Ort::Env& env, const bundle::Bytes& model, const bundle::NetworkSpec& spec, int threads,
                         std::uint64_t weight_bytes)
    : spec_(spec), weight_bytes_(weight_bytes), memory_(Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault)) {
  try {
    Ort::SessionOptions opts;
    opts.SetIntraOpNumThreads(threads < 1 ? 1 : threads);
    opts.SetInterOpNumThreads(1);
    opts.SetExecutionMode(ORT_SEQUENTIAL);
    opts.SetGraphOptimizationLevel(GraphOptimizationLevel::ORT_ENABLE_ALL);
    // Spinning worker threads would steal the cores the frame loop needs.
    opts.AddConfigEntry("session.intra_op.allow_spinning", "0");
    // No constant folding: a session then computes nothing while it is created, so loading
    // allocates no tensor of a bundle's graph beyond its initializers; the tensors a run makes
    // are bounded by the load-time check (bundle/onnx_model_scan.h, docs/security.md).
    opts.AddConfigEntry("optimization.disable_specified_optimizers", "ConstantFolding");
    session_ = std::make_unique<Ort::Session>(env, model.data(), model.size(), opts);
  } catch (const Ort::Exception& e) {
    throw Error(SOFTDECA_ERROR_FORMAT, spec.file + ": ONNX Runtime cannot load it: " + e.what());
  }
  try {
    check_side(*session_, true, spec.inputs, spec);
    check_side(*session_, false, spec.outputs, spec);
  } catch (const Ort::Exception& e) {
    throw Error(SOFTDECA_ERROR_FORMAT, spec.file + ": " + e.what());
  }
  for (const auto& t : spec_.inputs) input_names_.push_back(t.name.c_str());
  for (const auto& t : spec_.outputs) output_names_.push_back(t.name.c_str());
}

std::size_t OnnxNetwork::element_count(const bundle::TensorSpec& t, std::int64_t batch) {
  std::size_t n = 1;
  for (const std::int64_t d : t.shape) n *= static_cast<std::size_t>(d < 0 ? batch : d);
  return n;
}

OnnxNetwork::Binding OnnxNetwork::bind(const std::vector<const float*>& inputs, const std::vector<float*>& outputs,
                                       std::int64_t batch) const {
  if (inputs.size() != spec_.inputs.size() || outputs.size() != spec_.outputs.size())
    throw Error(SOFTDECA_ERROR_INTERNAL, spec_.key + ": wrong number of buffers");
  Binding b;
  const auto make = [&](const bundle::TensorSpec& t, float* data) {
    std::vector<std::int64_t> shape = t.shape;
    for (auto& d : shape)
      if (d < 0) d = batch;
    return Ort::Value::CreateTensor<float>(memory_, data, element_count(t, batch), shape.data(), shape.size());
  };
  try {
    for (std::size_t i = 0; i < inputs.size(); ++i)
      b.inputs_.push_back(make(spec_.inputs[i], const_cast<float*>(inputs[i])));  // ORT reads inputs only
    for (std::size_t i = 0; i < outputs.size(); ++i) b.outputs_.push_back(make(spec_.outputs[i], outputs[i]));
  } catch (const Ort::Exception& e) {
    throw Error(SOFTDECA_ERROR_INTERNAL, spec_.key + ": " + e.what());
  }
  return b;
}

void OnnxNetwork::run(Binding& b) const {
  try {
    session_->Run(Ort::RunOptions{nullptr}, input_names_.data(), b.inputs_.data(), b.inputs_.size(), output_names_.data(),
                  b.outputs_.data(), b.outputs_.size());
  } catch (const Ort::Exception& e) {
    throw Error(SOFTDECA_ERROR_INTERNAL, spec_.key + ": ONNX Runtime failed: " + e.what());
  }
}

void OnnxNetwork::run(const std::vector<const float*>& inputs, const std::vector<float*>& outputs, std::int64_t batch) const {
  Binding b = bind(inputs, outputs, batch);
  run(b);
}

}  // namespace softdeca::runtime
