// What the runtime sub-commands share: C ABI handles with RAII, status checks that throw with
// the library's message, and the avatar folder layout the replay tools read:
//   <dir>/neutral.obj                 the avatar's neutral head in template topology
//   <dir>/blendshapes/<name>.obj      its ARKit shapes as full meshes (missing: does not move)
//   <dir>/user_face/neutral.obj       optional: an ARKit face mesh (1220 vertices) and its
//   <dir>/user_face/blendshapes/*.obj shapes, whose blend stands in for a phone's tracked face
#pragma once

#include <string>
#include <vector>

#include "mesh_io.h"
#include "options.h"
#include "softdeca/softdeca.h"

namespace softdeca::cli {

// Throws std::runtime_error("<what>: <status>: <softdeca_last_error()>") unless OK.
void check(softdeca_status status, const std::string& what);

struct Model {
  softdeca_model* handle = nullptr;
  softdeca_model_info info{};
  explicit Model(const std::string& bundle, unsigned prepare_threads = 1);
  ~Model() { softdeca_model_destroy(handle); }
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;
  int parameter(const std::string& name) const;
};

// A user's own mesh fitted to the bundle's template: made from the mesh, or loaded from a file.
struct Fit {
  softdeca_avatar_fit* handle = nullptr;
  Fit(const Model& model, const softdeca_avatar_mesh& mesh, const softdeca_fit_options& options);
  Fit(const Model& model, const std::string& path);
  ~Fit() { softdeca_avatar_fit_destroy(handle); }
  Fit(const Fit&) = delete;
  Fit& operator=(const Fit&) = delete;
  void save(const std::string& path) const;
  std::string report() const;  // the library's JSON
  std::vector<float> registered(const Model& model) const;  // the template's skin on the avatar
};

// The storage precision of each model's tables (softdeca_precision values): as constructed, the
// library's choice per model (SOFTDECA_PRECISION_DEFAULT).
struct AvatarPrecisions {
  int32_t softdeca = SOFTDECA_PRECISION_DEFAULT;  // softdeca_avatar_desc.precision
  int32_t sparse = SOFTDECA_PRECISION_DEFAULT;    // softdeca_avatar_desc.sparse_precision
};

struct Avatar {
  softdeca_avatar* handle = nullptr;
  Avatar(const Model& model, const ObjMesh& neutral, const std::vector<float>& deltas, unsigned threads,
         AvatarPrecisions precisions = {});
  // On the user's own mesh, through its fit (outputs hold the mesh's vertices).
  Avatar(const Model& model, const Fit& fit, const softdeca_avatar_mesh& mesh, unsigned threads,
         AvatarPrecisions precisions = {});
  ~Avatar() { softdeca_avatar_destroy(handle); }
  Avatar(const Avatar&) = delete;
  Avatar& operator=(const Avatar&) = delete;
  softdeca_stats stats() const;

 private:
  void create(const Model& model, const softdeca_avatar_mesh& mesh, const softdeca_avatar_fit* fit, unsigned threads,
              AvatarPrecisions precisions);
};

struct FaceRig {  // a neutral mesh and 52 blendshape deltas
  ObjMesh neutral;
  std::vector<float> deltas;  // 52 x V x 3, zeros for missing shapes
  std::size_t present = 0;
  bool empty() const { return neutral.vertices.empty(); }
  void blend(const float* weights, float* out) const;
};

// Reads <dir>/<sub>/neutral.obj and <dir>/<sub>/blendshapes/*.obj (`sub` "" or a folder such as
// "user_face"); with `optional`, a missing neutral.obj gives an empty rig instead of an error.
// Read through the avatar's folder (read_avatar_obj).
FaceRig read_rig(const std::string& dir, const std::string& sub = "", bool optional = false);

// <dir>/<relative> read through the folder (input_files.h): no link below `dir` is followed and
// no FIFO opened; refusals name the file and why.
ObjMesh read_avatar_obj(const std::string& dir, const std::string& relative);

bool file_exists(const std::string& path);

// The --bundle and --avatar options of the commands that run the models on an avatar (replay,
// bench-runtime), and the check after parsing that both were given.
void declare_model_inputs(Options& o);
void require_model_inputs(const Options& o);
void make_directories(const std::string& path);
double median(std::vector<double> v);
double percentile(std::vector<double> v, double q);

}  // namespace softdeca::cli
