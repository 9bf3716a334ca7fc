#include "runtime/model.h"

#include <cstring>

#include "core/error.h"

namespace softdeca::runtime {

namespace {
[[noreturn]] void fail(const std::string& message) { throw Error(SOFTDECA_ERROR_FORMAT, message); }

const char* const kNetworkKeys[] = {"identity_encoder", "softdeca.f_w", "softdeca.f_ph", "softdeca.f_dyn",
                                    "sparse.f_l",       "sparse.f_ph_v", "sparse.f_dyn"};
}  // namespace

std::shared_ptr<const Model> Model::load(const BundleFiles& files, const ModelOptions& options) {
  std::shared_ptr<Model> m(new Model());
  const Bytes& manifest_bytes = files.get("manifest.json");
  m->manifest_ = parse_manifest(std::string(manifest_bytes.begin(), manifest_bytes.end()));
  const Manifest& mf = m->manifest_;

  const Bytes& tri = files.get(mf.skin_triangles_file);
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
  const Bytes& bones = files.get(mf.non_skin_bones_file);
  if (bones.size() != non_skin)
    fail(mf.non_skin_bones_file + ": " + std::to_string(bones.size()) + " bytes, expected " + std::to_string(non_skin));
  bool any_jaw = false;
  for (const std::uint8_t b : bones) {
    if (b > 1) fail(mf.non_skin_bones_file + ": labels must be 0 (cranium) or 1 (jaw)");
    any_jaw = any_jaw || b == 1;
  }
  if (any_jaw && mf.jaw_anchors.size() < 3) fail("manifest: jaw vertices need at least 3 non_skin.jaw_anchors");
  m->non_skin_bones_.assign(bones.begin(), bones.end());

  try {
    m->env_ = std::make_unique<Ort::Env>(ORT_LOGGING_LEVEL_ERROR, "softdeca");
  } catch (const Ort::Exception& e) {
    throw Error(SOFTDECA_ERROR_INTERNAL, std::string("ONNX Runtime environment: ") + e.what());
  }
  for (const char* key : kNetworkKeys) {
    const auto it = mf.networks.find(key);
    if (it == mf.networks.end()) {
      m->networks_.emplace_back();
      continue;
    }
    const bool per_frame = std::strcmp(key, "softdeca.f_w") == 0 || std::strcmp(key, "sparse.f_l") == 0;
    m->networks_.push_back(std::make_unique<OnnxNetwork>(*m->env_, files.get(it->second.file), it->second,
                                                         per_frame ? 1 : options.prepare_threads));
  }
  return m;
}

}  // namespace softdeca::runtime
