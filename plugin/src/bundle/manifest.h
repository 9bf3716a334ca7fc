// The bundle manifest (docs/bundle.md), parsed and checked for internal consistency: every
// size, index and tensor shape the runtime relies on is verified here, once, at load.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/parameter_spec.h"
#include "stream/arkit_names.h"

namespace softdeca::bundle {

// Versions this runtime reads: 1, 2 (adds SoftDECA's optional vertex stage), 3 (adds its
// optional residual stage), 4 (adds the optional physics at prepare, `rest_physics`), 5
// (adds the optional template head for fitting users' avatars, `template_head`), 6 (adds
// SoftDECA's optional rest gate, `rest_gate`) and 7 (adds `rest_changes`: SoftDECA trained on
// the rest physics).
constexpr int kBundleFormatVersionMin = 1, kBundleFormatVersion = 7;
constexpr const char* kBundleFormat = "softdeca-bundle";
constexpr const char* kDtFormulation = "cotangent-poisson-1";
// The 52 ARKit shapes in canonical order: names from the one definition, stream/arkit_names.h.
constexpr int kBlendshapeCount = static_cast<int>(stream::kBlendshapeCount);

struct TensorSpec {
  std::string name;
  std::vector<std::int64_t> shape;  // -1: a free (batch) dimension
};

struct NetworkSpec {
  std::string key;  // "softdeca.f_ph", ...
  std::string file;
  std::string sha256;  // lower-case hex, checked before the file is used
  std::vector<TensorSpec> inputs, outputs;
  std::vector<int> parameter_columns;  // indices into Manifest::parameters
};

struct LandmarkSpec {
  std::string name;
  int arkit_vertex = 0;
  int triangle = 0;
  double bary[3] = {0, 0, 0};
};

// The physics at prepare (docs/bundle.md, "Rest physics"): the sizes of rest_head.bin's arrays
// and the solver's settings; the arrays themselves are read by prepare/rest_head.h.
struct RestPhysicsSpec {
  std::string file, sha256;
  int fill_vertices = 0, soft_tets = 0, muscle_tets = 0, teeth_upper = 0, teeth_lower = 0, cranium = 0, jaw = 0;
  int upper_teeth_triangles = 0, lower_teeth_triangles = 0;
  // The lip and lid sets' rules (prepare/contact_sets.h); absent: no collision sets.
  bool has_contacts = false;
  int lid_candidates = 0;
  double lip_radius = 0, lip_corner_radius = 0, lid_reach = 0, lid_corner_radius = 0, eye_zone_share = 0;
  std::vector<int> inert_parameters;  // indices into Manifest::parameters
  double carry_smoothness = 0, tolerance = 0;
  int max_iterations = 0;
};

struct Manifest {
  int format_version = 0;
  bool untrained = false;
  std::string description, template_name;
  int head_vertices = 0, skin_vertices = 0, skin_triangles = 0;
  int latent = 0, identity = 0;
  std::vector<ParameterSpec> parameters;  // the manifest's "min"/"max" as minimum/maximum
  int arkit_vertex_count = 0;
  std::vector<LandmarkSpec> landmarks;
  std::vector<int> jaw_anchors;
  std::string skin_triangles_file, non_skin_bones_file;
  std::string skin_triangles_sha256, non_skin_bones_sha256;
  double dt_regularisation = 0;
  double frame_rate_hz = 0;
  double beta_max = 0, gamma_min = 0, gamma_max = 0;
  std::map<std::string, NetworkSpec> networks;
  bool has_softdeca = false, has_sparse = false;
  bool has_softdeca_vertex_stage = false;  // softdeca.f_ph_v present (format version 2)
  // SoftDECA's residual stage (softdeca.f_r_ph, softdeca.f_r_w; format version 3): its modes
  // (incl. the mean) and the length of the condition the prepare half hands the frame half.
  bool has_softdeca_residual_stage = false;
  int residual_modes = 0, residual_condition = 0;
  bool has_rest_physics = false;  // format version 4
  RestPhysicsSpec rest_physics;
  // SoftDECA's rest gate tau (format version 6; 0: none): z's last entry is then
  // |w|^2 / (|w|^2 + tau^2), not a constant 1, and the physics at prepare weighs the networks'
  // rest response with it (docs/bundle.md, "Rest physics").
  double rest_gate = 0;
  // SoftDECA trained on S_t + Pd, Pd the physics' rest change (format version 7): the physics
  // at prepare adds Pd whole and takes nothing of the networks off (docs/bundle.md).
  bool rest_changes = false;
  // The template head (format version 5): the neutral head (float32), the 52 ARKit shapes
  // and template_identity_modes identity modes over the skin (float16) in one file.
  bool has_template_head = false;
  std::string template_head_file, template_head_sha256;
  int template_identity_modes = 0;

  const NetworkSpec& network(const std::string& key) const;
  int find_parameter(const std::string& name) const;  // -1 when absent
};

// Throws Error(SOFTDECA_ERROR_FORMAT) naming the first problem.
Manifest parse_manifest(const std::string& json_text);

// The shapes the runtime requires of each network, given the manifest's sizes.
NetworkSpec expected_network(const Manifest& m, const std::string& key, int parameter_count);

}  // namespace softdeca::bundle
