// Mesh files the runtime tools write: OBJ (vertices, triangles, optional normals) and PC2 point
// caches (Blender's Mesh Cache modifier reads them onto the neutral OBJ). OBJ files are read by
// the import layer (plugin/import/obj_reader.h), named here for the tools.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "obj_reader.h"

namespace softdeca::cli {

using avatar_import::ObjMesh;
using avatar_import::read_obj;

// A named part of an OBJ: an `o <name>` line before its first triangle.
struct ObjGroup {
  std::string name;
  std::size_t first_triangle = 0;
};

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
