// Shared inputs of the runtime tests: the folder the ctest fixture `runtime_test_data` writes
// (python -m softdeca_train runtime-test-data), read into arrays, and RAII handles.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "softdeca/softdeca.h"

namespace rt {

inline std::string data_dir() {
  const char* d = std::getenv("SOFTDECA_TEST_DATA");
  return d ? d : "";
}

template <class T>
std::vector<T> read_raw(const std::string& name) {
  std::ifstream in(data_dir() + "/" + name, std::ios::binary | std::ios::ate);
  if (!in) return {};
  const auto size = static_cast<std::size_t>(in.tellg());
  std::vector<T> out(size / sizeof(T));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(size));
  return out;
}

inline std::vector<char> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::vector<char> out(in ? static_cast<std::size_t>(in.tellg()) : 0);
  in.seekg(0);
  in.read(out.data(), static_cast<std::streamsize>(out.size()));
  return out;
}

struct Head {
  std::vector<float> neutral, blendshapes, user_neutral, user_deltas;
  std::vector<int32_t> triangles;
  std::size_t vertices() const { return neutral.size() / 3; }
  std::size_t user_vertices() const { return user_neutral.size() / 3; }
  static Head load() {
    Head h;
    h.neutral = read_raw<float>("neutral.f32");
    h.blendshapes = read_raw<float>("blendshapes.f32");
    h.user_neutral = read_raw<float>("user_neutral.f32");
    h.user_deltas = read_raw<float>("user_deltas.f32");
    h.triangles = read_raw<int32_t>("triangles.i32");
    return h;
  }
  std::vector<float> user_face(const float* w) const {
    std::vector<float> p = user_neutral;
    for (std::size_t s = 0; s < 52; ++s)
      for (std::size_t i = 0; i < p.size(); ++i) p[i] += w[s] * user_deltas[s * p.size() + i];
    return p;
  }
};

struct ModelPtr {
  softdeca_model* p = nullptr;
  ~ModelPtr() { softdeca_model_destroy(p); }
};
struct AvatarPtr {
  softdeca_avatar* p = nullptr;
  ~AvatarPtr() { softdeca_avatar_destroy(p); }
};

// An avatar desc with the mesh it points to, kept together: a copy points at its own mesh.
struct Described : softdeca_avatar_desc {
  softdeca_avatar_mesh m{};
  Described() : softdeca_avatar_desc{} { mesh = &m; }
  Described(const Described& o) : softdeca_avatar_desc(o), m(o.m) { mesh = &m; }
  Described& operator=(const Described& o) {
    softdeca_avatar_desc::operator=(o);
    m = o.m;
    mesh = &m;
    return *this;
  }
};

// softdeca_avatar_create of `mesh` on the fit made for it, both models' tables at `precision`.
inline softdeca_status create_on_fit(softdeca_model* model, const softdeca_avatar_fit* fit, const softdeca_avatar_mesh* mesh,
                                     uint32_t threads, int32_t precision, softdeca_avatar** out) {
  softdeca_avatar_desc d{};
  d.struct_size = sizeof d;
  d.mesh = mesh;
  d.fit = fit;
  d.threads = threads;
  d.precision = precision;
  d.sparse_precision = precision;
  return softdeca_avatar_create(model, &d, out);
}

// The template path's desc of `h` (no fit), both models' tables at `precision`.
inline Described describe(const Head& h, uint32_t threads = 1, int32_t precision = SOFTDECA_PRECISION_HALF) {
  Described d;
  d.struct_size = sizeof(softdeca_avatar_desc);
  d.m.struct_size = sizeof d.m;
  d.m.neutral = h.neutral.data();
  d.m.vertex_count = h.vertices();
  d.m.triangles = h.triangles.data();
  d.m.triangle_count = h.triangles.size() / 3;
  d.m.blendshapes = h.blendshapes.data();
  d.m.blendshape_count = 52;
  d.threads = threads;
  d.precision = precision;
  d.sparse_precision = precision;
  return d;
}

struct Buffers {
  std::vector<float> vertices, normals;
  softdeca_output out{};
  explicit Buffers(std::size_t n, float fill = 0.0f) : vertices(3 * n, fill), normals(3 * n, fill) {
    out = {sizeof(softdeca_output), vertices.data(), static_cast<uint32_t>(n), normals.data(), static_cast<uint32_t>(n)};
  }
};

// `frame(weights, what)` for three random weight vectors at the defaults, and again with the
// physics at prepare's offset (a head twice as heavy), `avatar` prepared for each.
template <class Frame>
void at_defaults_and_a_rest_offset(softdeca_model* model, softdeca_avatar* avatar, unsigned seed, Frame&& frame) {
  uint32_t gravity = 0;
  ASSERT_EQ(softdeca_model_find_parameter(model, "gravity_strength", &gravity), SOFTDECA_OK);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (const double g : {1.0, 2.0}) {
    ASSERT_EQ(softdeca_avatar_set_parameter(avatar, gravity, g), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_prepare(avatar), SOFTDECA_OK) << softdeca_last_error();
    for (int f = 0; f < 3; ++f) {
      std::vector<float> w(52);
      for (float& x : w) x = unit(rng);
      frame(w, "gravity " + std::to_string(g) + " frame " + std::to_string(f));
    }
  }
}

// A temporary copy of a bundle folder, removed at the end of the test.
struct BundleCopy {
  std::filesystem::path dir;
  explicit BundleCopy(const std::string& source, const std::string& tag) {
    dir = std::filesystem::temp_directory_path() /
          ("softdeca-bundle-" + tag + "-" + std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    std::filesystem::remove_all(dir);
    std::filesystem::copy(source, dir, std::filesystem::copy_options::recursive);
  }
  ~BundleCopy() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
  std::string path() const { return dir.string(); }
  std::string file(const std::string& name) const { return (dir / name).string(); }
  void replace_in(const std::string& name, const std::string& from, const std::string& to) const {
    std::ifstream in(file(name));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(file(name), std::ios::trunc) << text;
  }
  void write(const std::string& name, const std::string& bytes) const {
    std::ofstream(file(name), std::ios::binary | std::ios::trunc) << bytes;
  }
};

}  // namespace rt

#define REQUIRE_TEST_DATA()                                                                     \
  do {                                                                                          \
    if (rt::data_dir().empty()) GTEST_FAIL() << "SOFTDECA_TEST_DATA is not set (ctest fixture)"; \
  } while (0)
