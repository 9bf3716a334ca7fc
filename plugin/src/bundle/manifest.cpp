#include "bundle/manifest.h"

#include <cmath>
#include <set>

#include "bundle/json.h"
#include "core/error.h"
#include "softdeca/softdeca.h"

namespace softdeca::bundle {

static_assert(kBundleFormatVersion == SOFTDECA_BUNDLE_FORMAT_VERSION, "the public header states the version read here");

namespace {
[[noreturn]] void fail(const std::string& message) { throw Error(SOFTDECA_ERROR_FORMAT, "manifest: " + message); }
void check(bool ok, const std::string& message) {
  if (!ok) fail(message);
}

int bounded_int(const Json& j, const std::string& what, long long lo, long long hi) {
  const long long v = j.integer(what);
  check(v >= lo && v <= hi, what + " = " + std::to_string(v) + " is outside [" + std::to_string(lo) + ", " +
                                std::to_string(hi) + "]");
  return static_cast<int>(v);
}

double finite(const Json& j, const std::string& what) {
  const double v = j.number(what);
  check(std::isfinite(v), what + " is not finite");
  return v;
}

constexpr long long kMaxElements = 1 << 24;

std::string sha256_of(const Json& j, const std::string& what) {
  const std::string h = j.at("sha256", what).string(what + ".sha256");
  bool hex = h.size() == 64;
  for (const char c : h) hex = hex && ((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'));
  check(hex, what + ".sha256 must be 64 lower-case hex digits");
  return h;
}

// A bundle file a section names: its name (what.file) and its checked sha256 (what.sha256).
void file_entry(const Json& j, const std::string& what, std::string& file, std::string& sha256) {
  file = j.at("file", what).string(what + ".file");
  sha256 = sha256_of(j, what);
}

// The optional top-level section `what`, which needs format version `version` (`purpose`, what
// it is for, goes into the refusal), or null when the manifest has none.
const Json* optional_section(const Json& doc, const std::string& what, int version, const char* purpose, const Manifest& m) {
  if (!doc.has(what)) return nullptr;
  check(m.format_version >= version,
        what + " (" + purpose + ") needs bundle format version " + std::to_string(version));
  return &doc.at(what, "manifest");
}

std::vector<std::int64_t> shape_of(const Json& j, const std::string& what) {
  std::vector<std::int64_t> shape;
  for (const Json& d : j.array(what)) {
    if (d.is_string()) shape.push_back(-1);
    else shape.push_back(bounded_int(d, what, 1, kMaxElements));
  }
  return shape;
}

std::string shape_text(const std::vector<std::int64_t>& s) {
  std::string t = "[";
  for (std::size_t i = 0; i < s.size(); ++i) t += (i ? ", " : "") + (s[i] < 0 ? std::string("batch") : std::to_string(s[i]));
  return t + "]";
}

void check_tensors(const std::vector<TensorSpec>& got, const std::vector<TensorSpec>& want, const std::string& what) {
  check(got.size() == want.size(), what + ": expected " + std::to_string(want.size()) + " tensors, found " +
                                       std::to_string(got.size()));
  for (std::size_t i = 0; i < want.size(); ++i) {
    check(got[i].name == want[i].name, what + ": tensor " + std::to_string(i) + " must be named '" + want[i].name +
                                           "', not '" + got[i].name + "'");
    check(got[i].shape == want[i].shape, what + "." + want[i].name + ": shape " + shape_text(got[i].shape) +
                                             " does not match the template's " + shape_text(want[i].shape));
  }
}
}  // namespace

const NetworkSpec& Manifest::network(const std::string& key) const {
  const auto it = networks.find(key);
  if (it == networks.end()) throw Error(SOFTDECA_ERROR_FORMAT, "bundle has no network " + key);
  return it->second;
}

int Manifest::find_parameter(const std::string& name) const {
  for (std::size_t i = 0; i < parameters.size(); ++i)
    if (parameters[i].name == name) return static_cast<int>(i);
  return -1;
}

NetworkSpec expected_network(const Manifest& m, const std::string& key, int p) {
  const std::int64_t F = m.skin_triangles, V = m.skin_vertices, L = m.latent, H = m.identity;
  NetworkSpec n;
  n.key = key;
  const std::vector<TensorSpec> per_vertex = {{"parameters", {V, p}}, {"identity", {1, H}}};
  const std::vector<TensorSpec> dyn_out = {{"alpha", {V}}, {"beta", {V}}, {"gamma", {V}}};
  if (key == "identity_encoder") {
    n.inputs = {{"neutral", {1, V, 3}}};
    n.outputs = {{"identity", {1, H}}};
  } else if (key == "softdeca.f_w") {
    n.inputs = {{"weights", {-1, kBlendshapeCount}}};
    n.outputs = {{"z", {-1, L}}};
  } else if (key == "softdeca.f_ph") {
    n.inputs = {{"parameters", {F, p}}, {"identity", {1, H}}};
    n.outputs = {{"L", {F, L, 9}}};
  } else if (key == "sparse.f_l") {
    n.inputs = {{"landmark_offsets", {-1, 3 * static_cast<std::int64_t>(m.landmarks.size())}}};
    n.outputs = {{"z", {-1, L}}};
  } else if (key == "sparse.f_ph_v" || key == "softdeca.f_ph_v") {
    n.inputs = per_vertex;
    n.outputs = {{"L", {V, L, 3}}};
  } else if (key == "softdeca.f_r_ph") {
    n.inputs = {{"parameters", {V, p}}};
    n.outputs = {{"condition", {1, m.residual_condition}}, {"modes", {V, m.residual_modes, 3}}};
  } else if (key == "softdeca.f_r_w") {
    n.inputs = {{"weights", {-1, kBlendshapeCount}}, {"condition", {1, m.residual_condition}}};
    n.outputs = {{"coefficients", {-1, m.residual_modes}}};
  } else if (key == "softdeca.f_dyn" || key == "sparse.f_dyn") {
    n.inputs = per_vertex;
    n.outputs = dyn_out;
  } else {
    fail("unknown network " + key);
  }
  return n;
}

namespace {
// parse_manifest's steps, in the order the manifest is read: later steps check against what the
// earlier ones filled in (sizes, parameters), so the order matters.

void parse_header(const Json& doc, Manifest& m) {
  check(doc.is_object(), "the manifest must be a JSON object");
  const std::string format = doc.has("format") && doc.at("format", "manifest").is_string()
                                 ? doc.at("format", "manifest").string("format")
                                 : std::string("?");
  check(format == kBundleFormat, "not a SoftDECA model bundle (format '" + format + "', expected '" + kBundleFormat + "')");
  m.format_version = static_cast<int>(doc.at("format_version", "manifest").integer("format_version"));
  if (m.format_version < kBundleFormatVersionMin || m.format_version > kBundleFormatVersion)
    fail("bundle format version " + std::to_string(m.format_version) + " is not supported; this runtime reads versions " +
         std::to_string(kBundleFormatVersionMin) + " to " + std::to_string(kBundleFormatVersion));
  m.untrained = doc.at("untrained", "manifest").boolean("untrained");
  if (doc.has("description") && doc.at("description", "manifest").is_string())
    m.description = doc.at("description", "manifest").string("description");
  check(doc.at("units", "manifest").string("units") == "metre", "units must be \"metre\"");
}

void parse_sizes(const Json& doc, Manifest& m) {
  const Json& t = doc.at("template", "manifest");
  m.template_name = t.at("name", "template").string("template.name");
  m.head_vertices = bounded_int(t.at("head_vertices", "template"), "template.head_vertices", 3, kMaxElements);
  m.skin_vertices = bounded_int(t.at("skin_vertices", "template"), "template.skin_vertices", 3, m.head_vertices);
  m.skin_triangles = bounded_int(t.at("skin_triangles", "template"), "template.skin_triangles", 1, kMaxElements);
  m.latent = bounded_int(doc.at("latent_size", "manifest"), "latent_size", 1, 1024);
  if (doc.has("residual_stage")) {
    const Json& r = doc.at("residual_stage", "manifest");
    m.residual_modes = bounded_int(r.at("modes", "residual_stage"), "residual_stage.modes", 1, 1024);
    m.residual_condition = bounded_int(r.at("condition", "residual_stage"), "residual_stage.condition", 1, 1 << 16);
  }
  m.identity = bounded_int(doc.at("identity_size", "manifest"), "identity_size", 1, 4096);

  const auto& names = doc.at("blendshapes", "manifest").array("blendshapes");
  check(names.size() == kBlendshapeCount, "blendshapes must list the 52 ARKit names");
  for (int i = 0; i < kBlendshapeCount; ++i)
    check(names[static_cast<std::size_t>(i)].string("blendshapes") == stream::blendshape_name(static_cast<std::size_t>(i)),
          "blendshapes[" + std::to_string(i) + "] must be " + stream::blendshape_name(static_cast<std::size_t>(i)) +
              " (canonical ARKit order)");
}

ParameterSpec parse_parameter(const Json& p, std::set<std::string>& seen) {
  ParameterSpec s;
  s.name = p.at("name", "parameter").string("parameter.name");
  const std::string what = "parameter " + s.name;
  check(!s.name.empty() && seen.insert(s.name).second, what + ": names must be unique and non-empty");
  s.default_value = finite(p.at("default", what), what + ".default");
  s.minimum = finite(p.at("min", what), what + ".min");
  s.maximum = finite(p.at("max", what), what + ".max");
  const std::string scale = p.at("scale", what).string(what + ".scale");
  check(scale == "linear" || scale == "log", what + ": scale must be linear or log");
  s.log_scale = scale == "log";
  s.localisable = p.at("localisable", what).boolean(what + ".localisable");
  if (p.has("unit")) s.unit = p.at("unit", what).string(what + ".unit");
  if (p.has("symbol")) s.symbol = p.at("symbol", what).string(what + ".symbol");
  if (p.has("domain")) s.domain = p.at("domain", what).string(what + ".domain");
  if (p.has("description")) s.description = p.at("description", what).string(what + ".description");
  check(s.minimum < s.maximum && s.default_value >= s.minimum && s.default_value <= s.maximum,
        what + ": needs min < max and default in range");
  check(!s.log_scale || s.minimum > 0, what + ": log scale needs min > 0");
  return s;
}

LandmarkSpec parse_landmark(const Json& p, const Manifest& m) {
  LandmarkSpec s;
  s.name = p.at("name", "landmark").string("landmark.name");
  const std::string what = "landmark " + s.name;
  s.arkit_vertex = bounded_int(p.at("arkit_vertex", what), what + ".arkit_vertex", 0, m.arkit_vertex_count - 1);
  s.triangle = bounded_int(p.at("triangle", what), what + ".triangle", 0, m.skin_triangles - 1);
  const auto& b = p.at("bary", what).array(what + ".bary");
  check(b.size() == 3, what + ".bary must have 3 entries");
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    s.bary[k] = finite(b[static_cast<std::size_t>(k)], what + ".bary");
    check(s.bary[k] >= -1e-6 && s.bary[k] <= 1 + 1e-6, what + ".bary entries must lie in [0, 1]");
    sum += s.bary[k];
  }
  check(std::fabs(sum - 1.0) < 1e-4, what + ".bary must sum to 1");
  return s;
}

void parse_parameters_and_landmarks(const Json& doc, Manifest& m) {
  std::set<std::string> seen;
  for (const Json& p : doc.at("parameters", "manifest").array("parameters")) m.parameters.push_back(parse_parameter(p, seen));
  check(!m.parameters.empty(), "at least one parameter is needed");

  const Json& lm = doc.at("landmarks", "manifest");
  m.arkit_vertex_count = bounded_int(lm.at("arkit_vertex_count", "landmarks"), "landmarks.arkit_vertex_count", 1, kMaxElements);
  for (const Json& p : lm.at("points", "landmarks").array("landmarks.points")) m.landmarks.push_back(parse_landmark(p, m));
  check(static_cast<long long>(m.landmarks.size()) == lm.at("count", "landmarks").integer("landmarks.count"),
        "landmarks.count does not match the points");
  check(m.landmarks.size() >= 3, "at least 3 landmarks are needed");
}

void parse_files(const Json& doc, Manifest& m) {
  const Json& files = doc.at("files", "manifest");
  const Json& tri = files.at("skin_triangles", "files");
  m.skin_triangles_file = tri.at("path", "files.skin_triangles").string("files.skin_triangles.path");
  m.skin_triangles_sha256 = sha256_of(tri, "files.skin_triangles");
  check(tri.at("dtype", "files.skin_triangles").string("dtype") == "int32", "files.skin_triangles.dtype must be int32");
  check(shape_of(tri.at("shape", "files.skin_triangles"), "files.skin_triangles.shape") ==
            std::vector<std::int64_t>{m.skin_triangles, 3},
        "files.skin_triangles.shape must be [template.skin_triangles, 3]");
  const Json& bones = files.at("non_skin_bones", "files");
  m.non_skin_bones_file = bones.at("path", "files.non_skin_bones").string("files.non_skin_bones.path");
  m.non_skin_bones_sha256 = sha256_of(bones, "files.non_skin_bones");
  check(bones.at("dtype", "files.non_skin_bones").string("dtype") == "uint8", "files.non_skin_bones.dtype must be uint8");
  const auto bone_shape = shape_of(bones.at("shape", "files.non_skin_bones"), "files.non_skin_bones.shape");
  const std::int64_t non_skin = m.head_vertices - m.skin_vertices;
  check(non_skin == 0 ? bone_shape.empty() || bone_shape == std::vector<std::int64_t>{0}
                      : bone_shape == std::vector<std::int64_t>{non_skin},
        "files.non_skin_bones.shape must be [head_vertices - skin_vertices]");

  for (const Json& a : doc.at("non_skin", "manifest").at("jaw_anchors", "non_skin").array("non_skin.jaw_anchors"))
    m.jaw_anchors.push_back(bounded_int(a, "non_skin.jaw_anchors", 0, m.skin_vertices - 1));
}

void parse_deformation_and_dynamics(const Json& doc, Manifest& m) {
  const Json& dt = doc.at("deformation_transfer", "manifest");
  const std::string formulation = dt.at("formulation", "deformation_transfer").string("deformation_transfer.formulation");
  check(formulation == kDtFormulation, "deformation_transfer.formulation '" + formulation + "' is unknown (this runtime implements '" +
                                           kDtFormulation + "')");
  m.dt_regularisation = finite(dt.at("regularisation", "deformation_transfer"), "deformation_transfer.regularisation");
  check(m.dt_regularisation > 0, "deformation_transfer.regularisation must be positive");

  const Json& dyn = doc.at("dynamics", "manifest");
  m.frame_rate_hz = dyn.at("frame_rate_hz", "dynamics").is_null() ? 0.0 : finite(dyn.at("frame_rate_hz", "dynamics"), "dynamics.frame_rate_hz");
  m.beta_max = finite(dyn.at("beta_max", "dynamics"), "dynamics.beta_max");
  const auto& gr = dyn.at("gamma_range", "dynamics").array("dynamics.gamma_range");
  check(gr.size() == 2, "dynamics.gamma_range must be [min, max]");
  m.gamma_min = finite(gr[0], "dynamics.gamma_range");
  m.gamma_max = finite(gr[1], "dynamics.gamma_range");
  check(m.beta_max >= 0 && m.beta_max < 1 && m.gamma_min > 0 && m.gamma_max < 2 && m.gamma_min <= m.gamma_max,
        "dynamics: the declared ranges are outside the stable set (0 <= beta < 1, 0 < gamma < 2)");
}

NetworkSpec parse_network(const Json& j, const char* key, const Manifest& m) {
  const std::string what = std::string("networks.") + key;
  NetworkSpec n;
  n.key = key;
  file_entry(j, what, n.file, n.sha256);
  if (j.has("parameter_columns")) {
    for (const Json& c : j.at("parameter_columns", what).array(what + ".parameter_columns")) {
      const int idx = m.find_parameter(c.string(what + ".parameter_columns"));
      check(idx >= 0, what + ": parameter column '" + c.string("") + "' is not a bundle parameter");
      n.parameter_columns.push_back(idx);
    }
  }
  for (const char* side : {"inputs", "outputs"})
    for (const Json& tj : j.at(side, what).array(what + "." + side)) {
      TensorSpec ts;
      ts.name = tj.at("name", what).string(what + ".name");
      check(tj.at("dtype", what).string(what + ".dtype") == "float32", what + "." + ts.name + ": dtype must be float32");
      ts.shape = shape_of(tj.at("shape", what), what + "." + ts.name + ".shape");
      (std::string(side) == "inputs" ? n.inputs : n.outputs).push_back(std::move(ts));
    }
  const NetworkSpec want = expected_network(m, key, static_cast<int>(n.parameter_columns.size()));
  check_tensors(n.inputs, want.inputs, what + ".inputs");
  check_tensors(n.outputs, want.outputs, what + ".outputs");
  const bool per_element = want.inputs[0].name == "parameters";
  check(per_element == !n.parameter_columns.empty(), what + ": parameter_columns must be given exactly for per-element networks");
  return n;
}

void parse_networks(const Json& doc, Manifest& m) {
  const Json& nets = doc.at("networks", "manifest");
  for (const char* key : {"identity_encoder", "softdeca.f_w", "softdeca.f_ph", "softdeca.f_dyn", "softdeca.f_ph_v",
                          "softdeca.f_r_ph", "softdeca.f_r_w", "sparse.f_l", "sparse.f_ph_v", "sparse.f_dyn"}) {
    if (!nets.has(key)) continue;
    const bool residual = std::string(key).rfind("softdeca.f_r_", 0) == 0;
    check(!residual || m.residual_modes > 0,
          std::string(key) + " (SoftDECA's residual stage) needs the manifest's residual_stage sizes");
    m.networks[key] = parse_network(nets.at(key, "networks"), key, m);
  }
  check(m.networks.count("identity_encoder") > 0, "networks.identity_encoder is required");
  // SoftDECA's optional vertex stage (X = DT(S_t, I + z.L) + z.L_v) belongs to its model.
  m.has_softdeca_vertex_stage = m.networks.count("softdeca.f_ph_v") > 0;
  check(!m.has_softdeca_vertex_stage || m.format_version >= 2,
        "softdeca.f_ph_v (SoftDECA's vertex stage) needs bundle format version 2");
  const auto count = [&](std::initializer_list<const char*> keys) {
    int c = 0;
    for (const char* k : keys) c += static_cast<int>(m.networks.count(k));
    return c;
  };
  const int residual = count({"softdeca.f_r_ph", "softdeca.f_r_w"});
  check(residual == 0 || residual == 2, "SoftDECA's residual stage needs both softdeca.f_r_ph and softdeca.f_r_w");
  m.has_softdeca_residual_stage = residual == 2;
  check(!m.has_softdeca_residual_stage || m.format_version >= 3,
        "softdeca.f_r_ph and softdeca.f_r_w (SoftDECA's residual stage) need bundle format version 3");
  const int sd = count({"softdeca.f_w", "softdeca.f_ph", "softdeca.f_dyn"});
  const int sp = count({"sparse.f_l", "sparse.f_ph_v", "sparse.f_dyn"});
  check(sd == 0 || sd == 3, "the SoftDECA model needs softdeca.f_w, softdeca.f_ph and softdeca.f_dyn");
  check(sp == 0 || sp == 3, "the SparseSoftDECA model needs sparse.f_l, sparse.f_ph_v and sparse.f_dyn");
  m.has_softdeca = sd == 3;
  m.has_sparse = sp == 3;
  check(!m.has_softdeca_vertex_stage || m.has_softdeca,
        "softdeca.f_ph_v (SoftDECA's vertex stage) needs the SoftDECA model (softdeca.f_w, softdeca.f_ph, softdeca.f_dyn)");
  check(!m.has_softdeca_residual_stage || m.has_softdeca,
        "SoftDECA's residual stage needs the SoftDECA model (softdeca.f_w, softdeca.f_ph, softdeca.f_dyn)");
  check(m.has_softdeca || m.has_sparse, "the bundle holds neither model");
}
}  // namespace

namespace {
void parse_rest_physics(const Json& r, Manifest& m) {
  const std::string what = "rest_physics";
  check(m.has_softdeca, "rest_physics corrects the SoftDECA model: the bundle has none");
  RestPhysicsSpec& s = m.rest_physics;
  file_entry(r, what, s.file, s.sha256);
  const auto count = [&](const Json& j, const char* key, long long lo) {
    return bounded_int(j.at(key, what), what + "." + key, lo, kMaxElements);
  };
  s.fill_vertices = count(r, "fill_vertices", 4);
  s.soft_tets = count(r, "soft_tets", 1);
  s.muscle_tets = count(r, "muscle_tets", 0);
  s.teeth_upper = count(r, "teeth_upper", 0);
  s.teeth_lower = count(r, "teeth_lower", 0);
  s.cranium = count(r, "cranium", 0);
  s.jaw = count(r, "jaw", 0);
  s.upper_teeth_triangles = count(r, "upper_teeth_triangles", 0);
  s.lower_teeth_triangles = count(r, "lower_teeth_triangles", 0);
  check(s.teeth_upper + s.teeth_lower <= m.head_vertices - m.skin_vertices,
        what + ": more teeth vertices than the head has non-skin vertices");
  const Json& c = r.at("contacts", what);
  if (!c.is_null()) {
    s.has_contacts = true;
    s.lid_candidates = bounded_int(c.at("lid_candidates", what), what + ".contacts.lid_candidates", 0, m.skin_vertices);
    const auto length = [&](const char* key) {
      const double v = finite(c.at(key, what), what + ".contacts." + key);
      check(v > 0 && v < 1, what + ".contacts." + key + " must lie in (0, 1)");
      return v;
    };
    s.lip_radius = length("lip_radius");
    s.lip_corner_radius = length("lip_corner_radius");
    s.lid_reach = length("lid_reach");
    s.lid_corner_radius = length("lid_corner_radius");
    s.eye_zone_share = length("eye_zone_share");
    check(m.skin_vertices >= 68, what + ".contacts need the 68 landmarks on the skin");
  }
  for (const Json& name : r.at("inert_parameters", what).array(what + ".inert_parameters")) {
    const int index = m.find_parameter(name.string(what + ".inert_parameters"));
    check(index >= 0, what + ".inert_parameters: " + name.string("name") + " is not one of the bundle's parameters");
    s.inert_parameters.push_back(index);
  }
  s.carry_smoothness = finite(r.at("carry_smoothness", what), what + ".carry_smoothness");
  s.tolerance = finite(r.at("tolerance", what), what + ".tolerance");
  check(s.carry_smoothness > 0 && s.tolerance > 0, what + ": carry_smoothness and tolerance must be positive");
  s.max_iterations = bounded_int(r.at("max_iterations", what), what + ".max_iterations", 1, 100000);
  m.has_rest_physics = true;
}
}  // namespace

namespace {
void parse_template_head(const Json& t, Manifest& m) {
  const std::string what = "template_head";
  file_entry(t, what, m.template_head_file, m.template_head_sha256);
  const Json& modes = t.at("identity_modes", what).at("shape", what);
  const auto& mdims = modes.array(what + ".identity_modes.shape");
  check(!mdims.empty(), what + ".identity_modes.shape has the wrong rank");
  m.template_identity_modes = bounded_int(mdims[0], what + ".identity_modes.shape[0]", 0, 1000);
  const auto shape = [&](const char* key, const char* dtype, std::vector<long long> expected) {
    const Json& e = t.at(key, what);
    check(e.at("dtype", what).string(what + "." + key + ".dtype") == dtype, what + "." + key + ".dtype must be " + dtype);
    const auto& dims = e.at("shape", what).array(what + "." + key + ".shape");
    check(dims.size() == expected.size(), what + "." + key + ".shape has the wrong rank");
    for (std::size_t i = 0; i < dims.size(); ++i)
      check(dims[i].integer(what + "." + key + ".shape") == expected[i],
            what + "." + key + ".shape does not match the template's sizes");
  };
  shape("neutral", "float32", {m.head_vertices, 3});
  shape("shapes", "float16", {kBlendshapeCount, m.skin_vertices, 3});
  shape("identity_modes", "float16", {m.template_identity_modes, m.skin_vertices, 3});
  m.has_template_head = true;
}
}  // namespace

namespace {
void parse_rest_gate(const Json& j, Manifest& m) {
  m.rest_gate = finite(j, "rest_gate");
  check(m.rest_gate > 0, "rest_gate (SoftDECA's rest gate tau) must be positive");
  check(m.has_softdeca_vertex_stage,
        "rest_gate (SoftDECA's rest gate) needs SoftDECA's vertex stage (softdeca.f_ph_v), where the runtime weighs the "
        "physics at prepare with the gate");
}
}  // namespace

Manifest parse_manifest(const std::string& text) {
  const Json doc = Json::parse(text);
  Manifest m;
  parse_header(doc, m);
  parse_sizes(doc, m);
  parse_parameters_and_landmarks(doc, m);
  parse_files(doc, m);
  parse_deformation_and_dynamics(doc, m);
  parse_networks(doc, m);
  if (const Json* r = optional_section(doc, "rest_physics", 4, "the physics at prepare", m)) parse_rest_physics(*r, m);
  if (const Json* t = optional_section(doc, "template_head", 5, "fitting users' avatars", m)) parse_template_head(*t, m);
  if (const Json* g = optional_section(doc, "rest_gate", 6, "SoftDECA's rest gate", m)) parse_rest_gate(*g, m);
  if (const Json* c = optional_section(doc, "rest_changes", 7, "SoftDECA trained on the rest physics", m)) {
    m.rest_changes = c->boolean("rest_changes");
    check(!m.rest_changes || m.has_rest_physics,
          "rest_changes (SoftDECA trained on the rest physics) needs the physics at prepare (rest_physics)");
  }
  return m;
}

}  // namespace softdeca::bundle
