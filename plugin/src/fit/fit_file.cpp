#include "fit/fit_file.h"

#include <Eigen/LU>
#include <cmath>
#include <cstring>

#include "core/binary_reader.h"
#include "core/error.h"
#include "fit/limits.h"

namespace softdeca::fit {
namespace {

constexpr char kMagic[8] = {'S', 'D', 'E', 'C', 'A', 'F', 'I', 'T'};
constexpr std::uint32_t kMaxIdentity = 1000;  // identity modes a bundle may hold (bundle/manifest.cpp)

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

std::string text(BinaryReader& in, std::size_t max, const char* what) {
  const auto n = in.value<std::uint32_t>(what);
  if (n > max) fail(std::string(what) + " is longer than a fit can hold");
  std::string s(n, '\0');
  in.read(s.data(), n, what);
  return s;
}

void finite(const std::vector<float>& v, const std::string& name, const char* what) {
  for (const float x : v)
    if (!std::isfinite(x)) fail(name + ": " + what + " hold a non-finite value");
}

}  // namespace

std::vector<std::uint8_t> encode_fit(const AvatarFit& f, const std::string& bundle_sha256, std::size_t vs) {
  Writer w;
  w.put(kMagic, 8);
  w.value(kFitFileVersion);
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
  return std::move(w.out);
}

AvatarFit decode_fit(const std::uint8_t* data, std::size_t size, const std::string& name, const std::string& bundle_sha256,
                     std::size_t vh, std::size_t vs, std::size_t skin_triangles) {
  BinaryReader in(data, size, name);
  char magic[8];
  in.read(magic, 8, "the header");
  if (std::memcmp(magic, kMagic, 8) != 0) fail(name + ": not a SoftDECA fit file");
  const auto version = in.value<std::uint32_t>("the version");
  if (version != kFitFileVersion)
    fail(name + ": fit file version " + std::to_string(version) + "; this library reads version " +
         std::to_string(kFitFileVersion) + ": fit the avatar again");
  if (text(in, 64, "the bundle's hash") != bundle_sha256)
    fail(name + ": this fit was made for another bundle: fit the avatar again with this one");
  AvatarFit f;
  f.mesh_sha256 = text(in, 64, "the mesh's hash");
  f.vertex_count = in.value<std::uint32_t>("the vertex count");
  f.triangle_count = in.value<std::uint32_t>("the triangle count");
  if (f.vertex_count < 3 || f.vertex_count > kMaxAvatarVertices || f.triangle_count == 0 ||
      f.triangle_count > kMaxAvatarTriangles)
    fail(name + ": the avatar's sizes are out of range");
  in.read(f.placement.linear.data(), 9, "the placement");
  in.read(f.placement.offset.data(), 3, "the placement");
  if (!f.placement.linear.allFinite() || !f.placement.offset.allFinite() || std::fabs(f.placement.linear.determinant()) <= 0)
    fail(name + ": the placement is not an invertible finite transform");
  if (in.value<std::uint32_t>("the head's size") != vh) fail(name + ": the registered head does not match the bundle's template");
  f.registered = in.vector<float>(vh * 3, "the registered head");
  finite(f.registered, name, "the registered head's positions");
  if (in.value<std::uint32_t>("the skin's size") != vs) fail(name + ": the skin does not match the bundle's template");
  f.source.corners = in.vector<std::int32_t>(vs * 3, "the shapes' sources");
  f.source.bary = in.vector<float>(vs * 3, "the shapes' sources");
  f.source.weight = in.vector<float>(vs, "the shapes' sources");
  for (const std::int32_t c : f.source.corners)
    if (c < 0 || static_cast<std::size_t>(c) >= f.vertex_count) fail(name + ": a shape source is not a vertex of the avatar");
  finite(f.source.bary, name, "the shapes' sources");
  finite(f.source.weight, name, "the shapes' sources");
  for (ShapeOrigin& o : f.origin) {
    const auto b = in.value<std::uint8_t>("the shapes' origins");
    if (b > 2) fail(name + ": a shape's origin is unknown");
    o = static_cast<ShapeOrigin>(b);
  }
  const auto nh = in.value<std::uint32_t>("the identity's size");
  if (nh > kMaxIdentity) fail(name + ": the identity has more coefficients than any bundle");
  f.identity = in.vector<float>(nh, "the identity");
  finite(f.identity, name, "the identity's coefficients");
  const auto ne = in.value<std::uint32_t>("the embedding's size");
  if (ne > f.vertex_count) fail(name + ": the embedding has more entries than the avatar has vertices");
  f.embedding.vertex = in.vector<std::int32_t>(ne, "the embedding");
  f.embedding.triangle = in.vector<std::int32_t>(ne, "the embedding");
  f.embedding.bary = in.vector<float>(ne * std::size_t{3}, "the embedding");
  f.embedding.offset = in.vector<float>(ne, "the embedding");
  f.embedding.weight = in.vector<float>(ne, "the embedding");
  for (std::size_t i = 0; i < ne; ++i) {
    if (f.embedding.vertex[i] < 0 || static_cast<std::size_t>(f.embedding.vertex[i]) >= f.vertex_count)
      fail(name + ": an embedded vertex is not a vertex of the avatar");
    if (f.embedding.triangle[i] < 0 || static_cast<std::size_t>(f.embedding.triangle[i]) >= skin_triangles)
      fail(name + ": an embedding triangle is not a skin triangle");
    if (!(f.embedding.weight[i] > 0 && f.embedding.weight[i] <= 1)) fail(name + ": an embedding weight is outside (0, 1]");
  }
  finite(f.embedding.bary, name, "the embedding's weights");
  finite(f.embedding.offset, name, "the embedding's offsets");
  f.report = text(in, 1 << 20, "the report");
  in.finish();
  return f;
}

}  // namespace softdeca::fit
