// A loaded model bundle: the checked manifest, the topology data and one ONNX Runtime session
// per network. Immutable after loading and shared by every avatar made from it (sessions are
// safe to run from several threads at once), so a model may be destroyed before its avatars.
#pragma once

#include <onnxruntime_cxx_api.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bundle/bundle_files.h"
#include "bundle/manifest.h"
#include "bundle/template_head.h"
#include "prepare/rest_head.h"
#include "runtime/onnx_network.h"

namespace softdeca::runtime {

constexpr std::uint64_t kDefaultMemoryBudget = std::uint64_t{2} << 30;

struct ModelOptions {
  int prepare_threads = 1;  // intra-op threads of the per-avatar networks (f_ph, f_ph_v, f_r_ph, f_dyn)
  // Upper bound on what the bundle's networks may ask for (every tensor of their graphs at its
  // static size, and the contract's tensors), checked before any ONNX Runtime session is
  // created.
  std::uint64_t memory_budget_bytes = kDefaultMemoryBudget;
};

// The estimate the budget is checked against, with the largest single tensor for messages.
struct MemoryEstimate {
  std::uint64_t bytes = 0;
  std::string largest;  // "<file> tensor '<name>'"
  std::uint64_t largest_bytes = 0;
};

class Model {
 public:
  // Checks every file's sha256 against the manifest, refuses ONNX files with external data
  // and bundles over the memory budget, all before creating a session. Throws Error(FORMAT).
  static std::shared_ptr<const Model> load(const bundle::BundleFiles& files, const ModelOptions& options);

  const bundle::Manifest& manifest() const { return manifest_; }
  const std::vector<std::int32_t>& skin_triangles() const { return skin_triangles_; }  // F*3
  const std::vector<std::uint8_t>& non_skin_bones() const { return non_skin_bones_; }  // Vh-Vs, 0 cranium 1 jaw

  const OnnxNetwork& identity_encoder() const { return *networks_.at(0); }
  // The identity code h of a neutral skin (skin_vertices x 3): the identity encoder's output,
  // checked finite (Error(NON_FINITE) otherwise).
  std::vector<float> encode_identity(const float* skin) const;
  // Per model ("softdeca" or "sparse"): the per-frame encoder, the hypernetwork and dynamics.
  const OnnxNetwork* encoder(bool sparse) const { return networks_.at(sparse ? 4 : 1).get(); }
  const OnnxNetwork* hyper(bool sparse) const { return networks_.at(sparse ? 5 : 2).get(); }
  const OnnxNetwork* dynamics(bool sparse) const { return networks_.at(sparse ? 6 : 3).get(); }
  bool has(bool sparse) const { return sparse ? manifest_.has_sparse : manifest_.has_softdeca; }
  // SoftDECA's vertex stage L_v(p, h) (per skin vertex, like the sparse model's), or null.
  const OnnxNetwork* softdeca_vertex_stage() const { return networks_.at(7).get(); }
  // SoftDECA's residual stage: the prepare half (condition and modes from p) and the
  // per-frame half (coefficients from w and the condition), or null.
  const OnnxNetwork* residual_condition() const { return networks_.at(8).get(); }
  const OnnxNetwork* residual_coefficients() const { return networks_.at(9).get(); }
  // The physics at prepare's head (format version 4), or null.
  const prepare::RestHead* rest_head() const { return rest_head_.get(); }
  // The template head for fitting users' avatars (format version 5), or null.
  const bundle::TemplateHead* template_head() const { return template_head_.get(); }
  // SHA-256 of the manifest as loaded: a saved fit names the bundle it was made for.
  const std::string& manifest_sha256() const { return manifest_sha256_; }

 private:
  Model() = default;
  bundle::Manifest manifest_;
  std::vector<std::int32_t> skin_triangles_;
  std::vector<std::uint8_t> non_skin_bones_;
  std::unique_ptr<const prepare::RestHead> rest_head_;
  std::unique_ptr<const bundle::TemplateHead> template_head_;
  std::string manifest_sha256_;
  std::unique_ptr<Ort::Env> env_;  // before the sessions: they must go first
  std::vector<std::unique_ptr<OnnxNetwork>> networks_;
};

}  // namespace softdeca::runtime
