// An avatar's frames in its parts' own coordinates. The runtime works on the joined mesh in the
// file's common space; a point cache or OBJ for a DCC or Unity holds each mesh as its node
// places it, in its own vertex order, units and axes: the inverse of each part's transform.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "imported_avatar.h"

namespace softdeca::cli {

class PartSpace {
 public:
  PartSpace(const std::vector<AvatarPart>& parts, const std::vector<std::int32_t>& triangles, std::size_t vertex_count);
  explicit PartSpace(const AvatarFile& avatar) : PartSpace(avatar.parts, avatar.triangles, avatar.vertex_count()) {}

  std::size_t vertex_count() const { return vertex_count_; }
  // A whole frame (vertex_count points, common space) in the parts' own coordinates, all parts
  // in part order; the pointer stays valid until the next call.
  const float* to_local(const float* common);
  // The triangles over those vertices, turned as in the file.
  const std::vector<std::int32_t>& local_triangles() const { return triangles_; }
  // An OBJ of a frame in the parts' own coordinates, an `o <part>` before each part's faces;
  // `normals` (common space, may be null) turned with them.
  void write_obj(const std::string& path, const float* common, const float* normals, const std::string& comment);

 private:
  struct Part {
    std::string name;
    std::size_t first = 0, count = 0, first_triangle = 0;
    bool identity = true;
    double inverse[12];  // row-major 3x4: common -> own
    double linear[9];    // row-major 3x3: own -> common, normals go back by its transpose
  };
  std::vector<Part> parts_;
  std::vector<std::int32_t> triangles_;
  std::size_t vertex_count_;
  std::vector<float> buffer_, normals_;
};

}  // namespace softdeca::cli
