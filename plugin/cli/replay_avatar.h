// What `softdeca replay --avatar X` animates, and how its frames go to files:
//   - a fit folder (softdeca fit --out DIR): the user's mesh read again and checked against the
//     fit (fit_folder.h), the fit loaded;
//   - an avatar folder in the bundle's template topology (neutral.obj with the bundle's head
//     vertex count, e.g. python -m softdeca_train avatar): the template's own heads;
//   - any other avatar (glTF, FBX, an avatar folder of another topology): fitted now.
// A fitted avatar's frames are the user's own vertices; they are written in its parts' own
// coordinates (part_space.h). A folder's optional user_face/ rig (a fit folder's, else its
// avatar folder's) stands in for a phone's face.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "imported_avatar.h"
#include "part_space.h"
#include "runtime_session.h"
#include "surface_points.h"

namespace softdeca::cli {

struct ReplayAvatar {
  std::string kind;  // "template topology", "fit folder" or "fitted now"
  FaceRig rig;       // template topology: its neutral and shapes
  FaceRig user;      // a folder's user_face rig, or empty
  std::unique_ptr<AvatarFile> mesh;  // fitted: the user's mesh
  std::unique_ptr<Fit> fit;
  std::unique_ptr<Avatar> avatar;
  std::unique_ptr<PartSpace> space;
  // Fitted: the bundle's landmarks on the user's mesh (the template's are the bundle's own).
  std::unique_ptr<SurfacePoints> landmarks;
  // What SparseSoftDECA is calibrated with: the user_face rig's neutral, or a fitted avatar's
  // landmarks at rest (in its own units and axes, which the calibration maps to the
  // template's); empty: none (the template's own landmarks need none).
  std::vector<float> calibration;
  // Where per-face parameter maps' faces lie: the skin's triangles over the template's neutral,
  // or the user's triangles over its neutral.
  std::vector<float> map_vertices;
  std::vector<std::int32_t> map_triangles;
  std::size_t vertex_count = 0;
  bool fitted() const { return fit != nullptr; }
};

// `names` and `options` are those of an avatar fitted now.
ReplayAvatar open_replay_avatar(const Model& model, const std::string& path, const ShapeNames& names,
                                const softdeca_fit_options& options, unsigned threads, AvatarPrecisions precisions);

}  // namespace softdeca::cli
