#include "fit/fit_file.h"

#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "bundle/sha256.h"
#include "core/binary_reader.h"
#include "core/error.h"
#include "fit/limits.h"

namespace softdeca::fit {
namespace {

constexpr char kMagic[8] = {'S', 'D', 'E', 'C', 'A', 'F', 'I', 'T'};
constexpr std::size_t kHashHex = 64;
constexpr std::size_t kMaxReportBytes = std::size_t{1} << 20;
// Barycentric weights are float32 copies of weights summing to 1 in double precision.
constexpr double kBaryTolerance = 1e-4;
// A float32 offset's rounding at the embedding's reach (metres).
constexpr double kOffsetTolerance = 1e-6;

class Writer {
 public:
  template <class T>
  void put(const T* p, std::size_t count) {
    const auto* b = reinterpret_cast<const std::uint8_t*>(p);
    out.insert(out.end(), b, b + count * sizeof(T));
  }
  template <class T>
  void value(T v) {
    put(&v, 1);
  }
  void text(const std::string& s) {
    value(static_cast<std::uint32_t>(s.size()));
    put(s.data(), s.size());
  }
  std::vector<std::uint8_t> out;
};

[[noreturn]] void fail(const std::string& m) { throw Error(SOFTDECA_ERROR_FORMAT, m); }

std::string damaged(const std::string& name, const std::string& why) {
  return name + " is damaged (" + why + "); fit the avatar again";
}

std::string text(BinaryReader& in, std::size_t max, const char* what, const std::string& name) {
  const auto n = in.value<std::uint32_t>(what);
  if (n > max) fail(damaged(name, std::string(what) + " is longer than a fit holds"));
  std::string s(n, '\0');
  in.read(s.data(), n, what);
  return s;
}

std::string number(double x) {
  char s[32];
  std::snprintf(s, sizeof s, "%.3g", x);
  return s;
}

bool is_hash(const std::string& s) {
  if (s.size() != kHashHex) return false;
  for (const char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

bool all_finite(const std::vector<float>& v) {
  for (const float x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

// Three barycentric weights of a point on a triangle: each within [0, 1], summing to 1.
bool barycentric(const float* b) {
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    if (!(b[k] >= -kBaryTolerance && b[k] <= 1 + kBaryTolerance)) return false;
    sum += b[k];
  }
  return std::fabs(sum - 1) <= kBaryTolerance;
}

bool index_below(std::int32_t i, std::size_t count) { return i >= 0 && static_cast<std::size_t>(i) < count; }

std::string placement_problem(const Placement& p) {
  if (!p.linear.allFinite() || !p.offset.allFinite()) return "its placement holds a non-finite value";
  const double unit = std::cbrt(std::fabs(p.linear.determinant()));
  if (!(unit >= kMinMetresPerUnit && unit <= kMaxMetresPerUnit))
    return "its unit is " + number(unit) + " m, outside " + metres_per_unit_range() + " m";
  // The placement turns (or mirrors) and scales: its linear part is the unit times an orthogonal matrix.
  const Eigen::Matrix3d gram = p.linear * p.linear.transpose() / (unit * unit);
  if ((gram - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6) return "its placement is not a turn and a scale";
  if (!(p.offset.norm() <= kPlacementReach))
    return "its placement moves the avatar " + number(p.offset.norm()) + " m, beyond " + number(kPlacementReach) + " m";
  return {};
}

std::string source_problem(const ShapeSource& s, std::size_t vertex_count, std::size_t vs) {
  if (s.corners.size() != 3 * vs || s.bary.size() != 3 * vs || s.weight.size() != vs)
    return "its shape sources do not match the bundle's skin";
  for (const std::int32_t c : s.corners)
    if (!index_below(c, vertex_count)) return "a shape source is not a vertex of the avatar";
  for (std::size_t v = 0; v < vs; ++v) {
    const float w = s.weight[v];
    if (!(w >= 0 && w <= 1)) return "a shape source's weight is outside [0, 1]";
    const float* b = &s.bary[3 * v];
    const bool none = w == 0 && b[0] == 0 && b[1] == 0 && b[2] == 0;  // a skin vertex with no avatar surface near it
    if (!none && !barycentric(b)) return "a shape source's barycentric weights are outside [0, 1] or do not sum to 1";
  }
  return {};
}

std::string embedding_problem(const Embedding& e, std::size_t vertex_count, std::size_t skin_triangles) {
  const std::size_t n = e.size();
  if (e.triangle.size() != n || e.bary.size() != 3 * n || e.offset.size() != n || e.weight.size() != n)
    return "its embedding's arrays differ in length";
  for (std::size_t i = 0; i < n; ++i) {
    if (!index_below(e.vertex[i], vertex_count)) return "an embedded vertex is not a vertex of the avatar";
    if (i > 0 && e.vertex[i] <= e.vertex[i - 1]) return "its embedding lists a vertex twice or out of order";
    if (!index_below(e.triangle[i], skin_triangles)) return "an embedding triangle is not a skin triangle";
    if (!barycentric(&e.bary[3 * i])) return "an embedding's barycentric weights are outside [0, 1] or do not sum to 1";
    if (!(std::fabs(e.offset[i]) <= kEmbeddingReach + kOffsetTolerance))
      return "an embedding offset lies " + number(e.offset[i]) + " m from the skin, beyond the fit's " +
             number(kEmbeddingReach * 1000) + " mm";
    if (!(e.weight[i] > 0 && e.weight[i] <= 1)) return "an embedding weight is outside (0, 1]";
  }
  return {};
}

}  // namespace

std::string fit_out_of_range(const AvatarFit& f, const FitSizes& sizes) {
  if (!is_hash(f.mesh_sha256)) return "its mesh's SHA-256 is not 64 hex digits";
  if (f.vertex_count < 3 || f.vertex_count > kMaxAvatarVertices || f.triangle_count == 0 ||
      f.triangle_count > kMaxAvatarTriangles)
    return "the avatar's sizes are out of range";
  if (std::string p = placement_problem(f.placement); !p.empty()) return p;
  if (f.registered.size() != 3 * sizes.head_vertices) return "its registered head does not match the bundle's template";
  if (!all_finite(f.registered)) return "its registered head holds a non-finite value";
  for (std::size_t v = 0; v < sizes.head_vertices; ++v) {
    const double d = Eigen::Vector3d(f.registered[3 * v], f.registered[3 * v + 1], f.registered[3 * v + 2]).norm();
    if (d > kRegisteredReach)
      return "a registered vertex lies " + number(d) + " m from the template's origin, beyond " + number(kRegisteredReach) + " m";
  }
  if (std::string p = source_problem(f.source, f.vertex_count, sizes.skin_vertices); !p.empty()) return p;
  for (const ShapeOrigin o : f.origin)
    if (static_cast<std::uint8_t>(o) > static_cast<std::uint8_t>(ShapeOrigin::Template)) return "a shape's origin is unknown";
  if (f.identity.size() != sizes.identity_modes) return "its identity does not match the bundle's identity modes";
  for (const float h : f.identity)
    if (!(std::fabs(h) <= kMaxIdentityCoefficient))
      return "an identity coefficient is " + number(h) + ", beyond " + number(kMaxIdentityCoefficient);
  if (std::string p = embedding_problem(f.embedding, f.vertex_count, sizes.skin_triangles); !p.empty()) return p;
  if (f.report.size() > kMaxReportBytes || f.report.find('\0') != std::string::npos) return "its report is not text of a fit's size";
  return {};
}

std::vector<std::uint8_t> encode_fit(const AvatarFit& f, const std::string& bundle_sha256, std::size_t vs) {
  Writer w;
  w.put(kMagic, 8);
  w.value(kFitFileVersion);
  w.out.resize(kFitHeaderBytes);  // the checksum, once the content is written
  w.text(bundle_sha256);
  w.text(f.mesh_sha256);
  w.value(static_cast<std::uint32_t>(f.vertex_count));
  w.value(static_cast<std::uint32_t>(f.triangle_count));
  w.put(f.placement.linear.data(), 9);
  w.put(f.placement.offset.data(), 3);
  w.value(static_cast<std::uint32_t>(f.registered.size() / 3));
  w.put(f.registered.data(), f.registered.size());
  w.value(static_cast<std::uint32_t>(vs));
  w.put(f.source.corners.data(), vs * 3);
  w.put(f.source.bary.data(), vs * 3);
  w.put(f.source.weight.data(), vs);
  for (const ShapeOrigin o : f.origin) w.value(static_cast<std::uint8_t>(o));
  w.value(static_cast<std::uint32_t>(f.identity.size()));
  w.put(f.identity.data(), f.identity.size());
  w.value(static_cast<std::uint32_t>(f.embedding.size()));
  w.put(f.embedding.vertex.data(), f.embedding.size());
  w.put(f.embedding.triangle.data(), f.embedding.size());
  w.put(f.embedding.bary.data(), f.embedding.size() * 3);
  w.put(f.embedding.offset.data(), f.embedding.size());
  w.put(f.embedding.weight.data(), f.embedding.size());
  w.text(f.report);
  const std::string sum = bundle::sha256_hex(w.out.data() + kFitHeaderBytes, w.out.size() - kFitHeaderBytes);
  std::memcpy(w.out.data() + 12, sum.data(), kHashHex);
  return std::move(w.out);
}

AvatarFit decode_fit(const std::uint8_t* data, std::size_t size, const std::string& name, const std::string& bundle_sha256,
                     const FitSizes& sizes) {
  if (size < 8 || std::memcmp(data, kMagic, 8) != 0) fail(name + " is not a SoftDECA fit file");
  if (size < kFitHeaderBytes) fail(damaged(name, "it is cut short"));
  std::uint32_t version = 0;
  std::memcpy(&version, data + 8, 4);
  if (version == 1)
    fail(name + " was saved by an earlier SoftDECA (fit file version 1, without a checksum); fit the avatar again");
  if (version != kFitFileVersion)
    fail(name + " is fit file version " + std::to_string(version) + "; this library reads version " +
         std::to_string(kFitFileVersion) + ": fit the avatar again");
  if (bundle::sha256_hex(data + kFitHeaderBytes, size - kFitHeaderBytes) !=
      std::string(reinterpret_cast<const char*>(data) + 12, kHashHex))
    fail(damaged(name, "its checksum does not match"));

  BinaryReader in(data + kFitHeaderBytes, size - kFitHeaderBytes, name);
  if (text(in, kHashHex, "the bundle's hash", name) != bundle_sha256)
    fail(name + ": this fit was made for another bundle: fit the avatar again with this one");
  AvatarFit f;
  f.mesh_sha256 = text(in, kHashHex, "the mesh's hash", name);
  f.vertex_count = in.value<std::uint32_t>("the vertex count");
  f.triangle_count = in.value<std::uint32_t>("the triangle count");
  if (f.vertex_count < 3 || f.vertex_count > kMaxAvatarVertices || f.triangle_count == 0 ||
      f.triangle_count > kMaxAvatarTriangles)
    fail(damaged(name, "the avatar's sizes are out of range"));
  in.read(f.placement.linear.data(), 9, "the placement");
  in.read(f.placement.offset.data(), 3, "the placement");
  // Every count is checked before its array is allocated.
  if (in.value<std::uint32_t>("the head's size") != sizes.head_vertices)
    fail(name + ": the registered head does not match the bundle's template");
  f.registered = in.vector<float>(sizes.head_vertices * 3, "the registered head");
  const std::size_t vs = sizes.skin_vertices;
  if (in.value<std::uint32_t>("the skin's size") != vs) fail(name + ": the skin does not match the bundle's template");
  f.source.corners = in.vector<std::int32_t>(vs * 3, "the shapes' sources");
  f.source.bary = in.vector<float>(vs * 3, "the shapes' sources");
  f.source.weight = in.vector<float>(vs, "the shapes' sources");
  for (ShapeOrigin& o : f.origin) {
    const auto b = in.value<std::uint8_t>("the shapes' origins");
    if (b > static_cast<std::uint8_t>(ShapeOrigin::Template)) fail(damaged(name, "a shape's origin is unknown"));
    o = static_cast<ShapeOrigin>(b);
  }
  if (in.value<std::uint32_t>("the identity's size") != sizes.identity_modes)
    fail(name + ": the identity does not match the bundle's identity modes");
  f.identity = in.vector<float>(sizes.identity_modes, "the identity");
  const auto ne = in.value<std::uint32_t>("the embedding's size");
  if (ne > f.vertex_count) fail(damaged(name, "the embedding has more entries than the avatar has vertices"));
  f.embedding.vertex = in.vector<std::int32_t>(ne, "the embedding");
  f.embedding.triangle = in.vector<std::int32_t>(ne, "the embedding");
  f.embedding.bary = in.vector<float>(ne * std::size_t{3}, "the embedding");
  f.embedding.offset = in.vector<float>(ne, "the embedding");
  f.embedding.weight = in.vector<float>(ne, "the embedding");
  f.report = text(in, kMaxReportBytes, "the report", name);
  in.finish();
  if (const std::string problem = fit_out_of_range(f, sizes); !problem.empty()) fail(damaged(name, problem));
  return f;
}

}  // namespace softdeca::fit
