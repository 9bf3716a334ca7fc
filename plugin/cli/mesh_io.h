// Mesh files of the runtime tools: OBJ in and out (vertices, triangles, optional normals) and
// PC2 point caches (Blender's Mesh Cache modifier reads them onto the neutral OBJ).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace softdeca::cli {

struct ObjMesh {
  std::vector<float> vertices;       // xyz
  std::vector<std::int32_t> triangles;  // polygons fan-triangulated
  std::size_t vertex_count() const { return vertices.size() / 3; }
};

// A named part of an OBJ: an `o <name>` line before its first triangle.
struct ObjGroup {
  std::string name;
  std::size_t first_triangle = 0;
};

// Reads `v` and `f` records (f may use v/vt/vn and negative indices). Throws std::runtime_error.
ObjMesh read_obj(const std::string& path);
void write_obj(const std::string& path, const float* vertices, std::size_t vertex_count, const float* normals,
               const std::int32_t* triangles, std::size_t triangle_count, const std::string& comment,
               const std::vector<ObjGroup>& groups = {});

// PC2: "POINTCACHE2\0", version 1, point count, start frame, sample rate, frame count, then
// float xyz per point per frame. The frame count is written when the file is closed.
class Pc2Writer {
 public:
  Pc2Writer(const std::string& path, std::size_t points, float start_frame = 0.0f, float sample_rate = 1.0f);
  ~Pc2Writer();
  Pc2Writer(const Pc2Writer&) = delete;
  Pc2Writer& operator=(const Pc2Writer&) = delete;
  void add(const float* xyz);
  void close();
  std::size_t frames() const { return frames_; }

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  std::size_t points_, frames_ = 0;
};

}  // namespace softdeca::cli
