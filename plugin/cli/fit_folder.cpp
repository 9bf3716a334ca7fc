#include "fit_folder.h"

#include <filesystem>
#include <stdexcept>

#include "bundle/json.h"
#include "input_files.h"
#include "json.h"

namespace softdeca::cli {

namespace fs = std::filesystem;

namespace {
constexpr std::uintmax_t kMaxFitJsonBytes = 64u << 20;

std::string absolute(const std::string& path) {
  std::error_code error;
  const fs::path p = fs::weakly_canonical(fs::absolute(path), error);
  return error ? fs::absolute(path).lexically_normal().string() : p.string();
}

std::string transform_json(const double* m) {
  std::string out = "[";
  for (int i = 0; i < 16; ++i) out += (i ? "," : "") + json_number(m[i]);
  return out + "]";
}

std::string source_json(const AvatarFile& avatar, const std::string& dir) {
  const std::string mesh = absolute(avatar.path);
  JsonObject o;
  o.text("path", mesh)
      .text("path_from_fit", fs::path(mesh).lexically_relative(absolute(dir)).generic_string())
      .text("format", avatar.format)
      .text("names_file", avatar.names_file.empty() ? "" : absolute(avatar.names_file))
      .text("mesh_sha256", avatar_mesh_sha256(avatar))
      .text("vertex_order", avatar.vertex_order)
      .text("declared_unit", avatar.declared_unit)
      .raw("declared_metres_per_unit", avatar.declared_metres_per_unit > 0 ? json_number(avatar.declared_metres_per_unit) : "null");
  return o.str();
}

std::string parts_json(const AvatarFile& avatar) {
  std::string parts = "[";
  for (const AvatarPart& p : avatar.parts) {
    JsonObject o;
    o.text("name", p.name)
        .number("first_vertex", static_cast<double>(p.first_vertex))
        .number("vertex_count", static_cast<double>(p.vertex_count))
        .number("triangle_count", static_cast<double>(p.triangle_count))
        .raw("transform", transform_json(p.transform))
        .raw("mirrored", p.mirrored ? "true" : "false");
    parts += (parts.size() > 1 ? "," : "") + o.str();
  }
  return parts + "]";
}

std::string left_out_json(const AvatarFile& avatar) {
  std::string out = "[";
  for (const LeftOutMesh& m : avatar.left_out) {
    JsonObject o;
    o.text("name", m.name).number("vertex_count", static_cast<double>(m.vertex_count)).text("reason", m.reason);
    out += (out.size() > 1 ? "," : "") + o.str();
  }
  return out + "]";
}

// Each ARKit shape: the rig's name for it per part, or null where no part has it.
std::string shapes_json(const AvatarFile& avatar) {
  JsonObject shapes;
  for (std::size_t k = 0; k < 52; ++k) {
    if (avatar.shape_sources[k].empty()) {
      shapes.raw(softdeca_blendshape_get_name(static_cast<uint32_t>(k)), "null");
      continue;
    }
    JsonObject parts;
    for (const ShapeSource& s : avatar.shape_sources[k]) parts.text(s.part, s.rig_name);
    shapes.raw(softdeca_blendshape_get_name(static_cast<uint32_t>(k)), parts.str());
  }
  return shapes.str(true);
}

std::string unused_json(const AvatarFile& avatar) {
  std::string out = "[";
  for (const UnusedName& u : avatar.names_not_used) {
    JsonObject o;
    o.text("mesh", u.mesh).text("name", u.name).text("reason", u.reason);
    out += (out.size() > 1 ? ",\n    " : "") + o.str();
  }
  return out + "]";
}

// fit.json as the import reads any file: opened once, never waiting on a FIFO, within its bound.
std::string read_small_file(const std::string& path) {
  return avatar_import::read_named_file(path, kMaxFitJsonBytes, "a fit's report");
}

// The recorded mesh: its absolute path, else its path from the fit folder (both moved together).
std::string locate_mesh(const std::string& dir, const std::string& recorded, const std::string& from_fit) {
  std::error_code error;
  if (fs::exists(recorded, error)) return recorded;
  const std::string moved = (fs::path(dir) / from_fit).lexically_normal().string();
  if (!from_fit.empty() && fs::exists(moved, error)) return moved;
  throw std::runtime_error(dir + ": the fitted mesh is neither at " + recorded + " nor at " + moved);
}
}  // namespace

std::vector<std::string> fit_folder_files() { return {"avatar.fit", "fit.json", "fit.png"}; }

bool is_fit_folder(const std::string& dir) {
  std::error_code error;
  return fs::is_directory(dir, error) && fs::is_regular_file(fit_file(dir), error);
}

std::string fit_file(const std::string& dir) { return (fs::path(dir) / "avatar.fit").string(); }

std::string fit_json(const AvatarFile& avatar, const std::string& dir, const std::string& library_report, bool poor) {
  JsonObject o;
  o.raw("poor_fit", poor ? "true" : "false")
      .raw("source", source_json(avatar, dir))
      .number("vertices", static_cast<double>(avatar.vertex_count()))
      .number("triangles", static_cast<double>(avatar.triangles.size() / 3))
      .raw("parts", parts_json(avatar))
      .raw("left_out", left_out_json(avatar))
      .number("shapes_found", static_cast<double>(avatar.shape_count()))
      .raw("shapes", shapes_json(avatar))
      .raw("names_not_used", unused_json(avatar))
      .raw("fit", library_report);
  return o.str(true) + "\n";
}

AvatarFile read_fitted_mesh(const std::string& dir, const ImportLimits& limits) {
  const std::string report = (fs::path(dir) / "fit.json").string();
  std::string recorded, from_fit, names_file, want;
  try {
    const bundle::Json json = bundle::Json::parse(read_small_file(report));
    const bundle::Json& source = json.at("source", "fit.json");
    recorded = source.at("path", "source").string("source.path");
    from_fit = source.at("path_from_fit", "source").string("source.path_from_fit");
    names_file = source.at("names_file", "source").string("source.names_file");
    want = source.at("mesh_sha256", "source").string("source.mesh_sha256");
  } catch (const std::exception& e) {
    throw std::runtime_error(report + ": " + e.what());
  }
  const std::string mesh = locate_mesh(dir, recorded, from_fit);
  const ShapeNames names = names_file.empty() ? ShapeNames() : ShapeNames::from_file(names_file);
  AvatarFile avatar = read_avatar_file(mesh, names, limits);
  if (avatar_mesh_sha256(avatar) != want)
    throw std::runtime_error(mesh + " is not the mesh fitted in " + dir + " (its SHA-256 differs: the mesh or its names "
                             "changed); fit it again: softdeca fit " + mesh + " --bundle B --out " + dir);
  return avatar;
}

}  // namespace softdeca::cli
