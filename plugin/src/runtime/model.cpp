#include "runtime/model.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>

#include "bundle/onnx_graph.h"
#include "bundle/onnx_model_scan.h"
#include "bundle/sha256.h"
#include "core/error.h"

namespace softdeca::runtime {

namespace {
[[noreturn]] void fail(const std::string& message) { throw Error(SOFTDECA_ERROR_FORMAT, message); }

// The order of Model::networks_ (the accessors in model.h index it).
const char* const kNetworkKeys[] = {"identity_encoder", "softdeca.f_w",    "softdeca.f_ph",  "softdeca.f_dyn",
                                    "sparse.f_l",       "sparse.f_ph_v",   "sparse.f_dyn",   "softdeca.f_ph_v",
                                    "softdeca.f_r_ph",  "softdeca.f_r_w"};

std::string mib(std::uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

// The file's bytes, once their sha256 matches the manifest's.
const bundle::Bytes& verified(const bundle::BundleFiles& files, const std::string& name, const std::string& sha256) {
  const bundle::Bytes& bytes = files.get(name);
  if (bundle::sha256_hex(bytes.data(), bytes.size()) != sha256)
    fail(name + ": sha256 does not match the manifest (the file was changed or damaged)");
  return bytes;
}

// Refuses external data and graphs outside the exporter's operators or without static shapes,
// and adds what the network may allocate to the estimate; returns its weights' bytes.
std::uint64_t scan_network(const bundle::Bytes& bytes, const bundle::NetworkSpec& spec, MemoryEstimate& estimate) {
  const bundle::OnnxModelScan scan = [&] {
    try {
      return bundle::scan_onnx_model(bytes.data(), bytes.size(), spec.inputs);
    } catch (const Error& e) {
      fail(spec.file + ": " + e.what());
    }
  }();
  if (!scan.external_tensors.empty())
    fail(spec.file + ": tensor '" + bundle::onnx::printable(scan.external_tensors.front()) +
         "' keeps its data in another file (ONNX external data); a bundle's networks must hold all their data");
  std::uint64_t contract = 0;
  for (const auto* side : {&spec.inputs, &spec.outputs})
    for (const bundle::TensorSpec& t : *side)
      contract = bundle::onnx::add_sat(contract, OnnxNetwork::element_count(t, bundle::kFedBatch) * sizeof(float));
  estimate.bytes = bundle::onnx::add_sat(estimate.bytes, bundle::onnx::add_sat(scan.bytes, contract));
  if (scan.largest_bytes > estimate.largest_bytes) {
    estimate.largest_bytes = scan.largest_bytes;
    estimate.largest = spec.file + " tensor '" + bundle::onnx::printable(scan.largest_tensor) + "'";
  }
  return scan.weight_bytes;
}
}  // namespace

std::shared_ptr<const Model> Model::load(const bundle::BundleFiles& files, const ModelOptions& options) {
  std::shared_ptr<Model> m(new Model());
  const bundle::Bytes& manifest_bytes = files.get("manifest.json");
  m->manifest_ = bundle::parse_manifest(std::string(manifest_bytes.begin(), manifest_bytes.end()));
  m->manifest_sha256_ = bundle::sha256_hex(manifest_bytes.data(), manifest_bytes.size());
  const bundle::Manifest& mf = m->manifest_;

  const bundle::Bytes& tri = verified(files, mf.skin_triangles_file, mf.skin_triangles_sha256);
  const std::size_t n_idx = static_cast<std::size_t>(mf.skin_triangles) * 3;
  if (tri.size() != n_idx * sizeof(std::int32_t))
    fail(mf.skin_triangles_file + ": " + std::to_string(tri.size()) + " bytes, expected " +
         std::to_string(n_idx * sizeof(std::int32_t)) + " (template.skin_triangles x 3 int32)");
  m->skin_triangles_.resize(n_idx);
  std::memcpy(m->skin_triangles_.data(), tri.data(), tri.size());  // little-endian hosts only
  std::vector<char> used(static_cast<std::size_t>(mf.skin_vertices), 0);
  for (std::size_t i = 0; i < n_idx; ++i) {
    const std::int32_t v = m->skin_triangles_[i];
    if (v < 0 || v >= mf.skin_vertices)
      fail(mf.skin_triangles_file + ": index " + std::to_string(v) + " at " + std::to_string(i) + " is not a skin vertex");
    used[static_cast<std::size_t>(v)] = 1;
  }
  for (std::size_t i = 0; i < n_idx; i += 3) {
    const std::int32_t* t = &m->skin_triangles_[i];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      fail(mf.skin_triangles_file + ": triangle " + std::to_string(i / 3) + " repeats a vertex");
  }
  for (std::size_t v = 0; v < used.size(); ++v)
    if (!used[v]) fail(mf.skin_triangles_file + ": skin vertex " + std::to_string(v) + " is in no triangle");

  const std::size_t non_skin = static_cast<std::size_t>(mf.head_vertices - mf.skin_vertices);
  const bundle::Bytes& bones = verified(files, mf.non_skin_bones_file, mf.non_skin_bones_sha256);
  if (bones.size() != non_skin)
    fail(mf.non_skin_bones_file + ": " + std::to_string(bones.size()) + " bytes, expected " + std::to_string(non_skin));
  bool any_jaw = false;
  for (const std::uint8_t b : bones) {
    if (b > 1) fail(mf.non_skin_bones_file + ": labels must be 0 (cranium) or 1 (jaw)");
    any_jaw = any_jaw || b == 1;
  }
  if (any_jaw && mf.jaw_anchors.size() < 3) fail("manifest: jaw vertices need at least 3 non_skin.jaw_anchors");
  m->non_skin_bones_.assign(bones.begin(), bones.end());

  if (mf.has_rest_physics) {
    const bundle::Bytes& data = verified(files, mf.rest_physics.file, mf.rest_physics.sha256);
    prepare::RestHead head = prepare::parse_rest_head(mf, data);
    m->rest_head_ = std::make_unique<const prepare::RestHead>(std::move(head));
  }

  if (mf.has_template_head)
    m->template_head_ = std::make_unique<const bundle::TemplateHead>(
        bundle::parse_template_head(mf, verified(files, mf.template_head_file, mf.template_head_sha256)));

  // Every network is verified and scanned before the first session exists: nothing a bundle
  // declares is allocated until the whole bundle fits the budget.
  MemoryEstimate estimate;
  std::vector<const bundle::Bytes*> network_bytes;
  std::vector<std::uint64_t> weight_bytes;
  for (const char* key : kNetworkKeys) {
    const auto it = mf.networks.find(key);
    if (it == mf.networks.end()) {
      network_bytes.push_back(nullptr);
      weight_bytes.push_back(0);
      continue;
    }
    network_bytes.push_back(&verified(files, it->second.file, it->second.sha256));
    weight_bytes.push_back(scan_network(*network_bytes.back(), it->second, estimate));
  }
  const std::uint64_t budget = options.memory_budget_bytes ? options.memory_budget_bytes : kDefaultMemoryBudget;
  if (estimate.bytes > budget)
    fail("the bundle's networks need an estimated " + mib(estimate.bytes) + " (largest: " + estimate.largest + ", " +
         mib(estimate.largest_bytes) + "), over the memory budget of " + mib(budget) +
         " (softdeca_model_options.memory_budget_mib; C++ ModelOptions::memory_budget_bytes)");

  try {
    m->env_ = std::make_unique<Ort::Env>(ORT_LOGGING_LEVEL_ERROR, "softdeca");
  } catch (const Ort::Exception& e) {
    throw Error(SOFTDECA_ERROR_INTERNAL, std::string("ONNX Runtime environment: ") + e.what());
  }
  for (std::size_t k = 0; k < std::size(kNetworkKeys); ++k) {
    const char* key = kNetworkKeys[k];
    const auto it = mf.networks.find(key);
    if (it == mf.networks.end()) {
      m->networks_.emplace_back();
      continue;
    }
    const bool per_frame = std::strcmp(key, "softdeca.f_w") == 0 || std::strcmp(key, "sparse.f_l") == 0 ||
                           std::strcmp(key, "softdeca.f_r_w") == 0;
    m->networks_.push_back(std::make_unique<OnnxNetwork>(*m->env_, *network_bytes[k], it->second,
                                                         per_frame ? 1 : options.prepare_threads, weight_bytes[k]));
  }
  return m;
}

}  // namespace softdeca::runtime

namespace softdeca::runtime {

std::vector<float> Model::encode_identity(const float* skin) const {
  std::vector<float> h(static_cast<std::size_t>(manifest_.identity));
  identity_encoder().run({skin}, {h.data()}, 1);
  for (const float x : h)
    if (!std::isfinite(x)) throw Error(SOFTDECA_ERROR_NON_FINITE, "the identity encoder produced a non-finite code");
  return h;
}

}  // namespace softdeca::runtime
