#include "obj_reader.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "input_files.h"

namespace softdeca::avatar_import {

namespace {
struct Line {
  const char* begin;
  const char* end;
};

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// One index of a face record ("7", "7/1", "-2//3"); advances `p` past it. 0 when there is none.
long face_index(const char*& p, const char* end, bool& bad) {
  while (p < end && blank(*p)) ++p;
  if (p == end) return 0;
  const char* start = p;
  bool negative = false;
  if (*p == '-' || *p == '+') negative = *p++ == '-';
  long value = 0;
  const char* digits = p;
  while (p < end && *p >= '0' && *p <= '9' && value <= 0x7fffffffL) value = 10 * value + (*p++ - '0');
  if (p == digits || value > 0x7fffffffL || value == 0) {
    bad = true;
    p = start;
    return 0;
  }
  while (p < end && !blank(*p)) ++p;  // the /vt/vn part
  return negative ? -value : value;
}
}  // namespace

ObjMesh parse_obj(const std::string& text, const std::string& name, const ImportLimits& limits) {
  ObjMesh mesh;
  std::vector<std::int32_t> polygon;
  std::size_t line_number = 0;
  const char* p = text.data();
  const char* const stop = p + text.size();
  const auto fail = [&](const std::string& what) -> std::runtime_error {
    return std::runtime_error(name + ":" + std::to_string(line_number) + ": " + what);
  };
  while (p < stop) {
    ++line_number;
    const char* end = p;
    while (end < stop && *end != '\n') ++end;
    const char* s = p;
    p = end < stop ? end + 1 : stop;
    while (s < end && blank(*s)) ++s;
    if (end - s < 2 || !blank(s[1])) continue;
    if (s[0] == 'v') {
      if (mesh.vertex_count() == limits.max_vertices)
        throw std::runtime_error(name + ": more than the " + std::to_string(limits.max_vertices) + " vertices an avatar may have");
      // strtof stops at the line's end: the record is copied so it cannot read into the next.
      std::string record(s + 2, end);
      const char* q = record.c_str();
      for (int k = 0; k < 3; ++k) {
        char* after = nullptr;
        const float v = std::strtof(q, &after);
        if (after == q) throw fail("bad vertex");
        if (!std::isfinite(v)) throw fail("a vertex coordinate is not finite");
        mesh.vertices.push_back(v);
        q = after;
      }
    } else if (s[0] == 'f') {
      polygon.clear();
      const char* q = s + 2;
      bool bad = false;
      while (true) {
        const long index = face_index(q, end, bad);
        if (bad) throw fail("bad face");
        if (index == 0) break;
        // A negative index counts back from the vertices so far; a positive one may name a vertex
        // defined further down (checked once all are read).
        const long n = static_cast<long>(mesh.vertex_count());
        const long resolved = index < 0 ? n + index : index - 1;
        if (resolved < 0) throw fail("face index " + std::to_string(index) + " is before the first vertex");
        polygon.push_back(static_cast<std::int32_t>(resolved));
      }
      if (polygon.size() < 3) continue;  // points and lines
      if (mesh.triangles.size() / 3 + polygon.size() - 2 > limits.max_triangles)
        throw std::runtime_error(name + ": more than the " + std::to_string(limits.max_triangles) + " triangles an avatar may have");
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k) mesh.triangles.insert(mesh.triangles.end(), {polygon[0], polygon[k], polygon[k + 1]});
    }
  }
  for (const std::int32_t index : mesh.triangles)
    if (static_cast<std::size_t>(index) >= mesh.vertex_count())
      throw std::runtime_error(name + ": a face names vertex " + std::to_string(index + 1) + " of only " +
                               std::to_string(mesh.vertex_count()));
  return mesh;
}

ObjMesh read_obj(const std::string& path, const ImportLimits& limits) {
  return parse_obj(read_named_file(path, limits.max_file_bytes, "an OBJ file"), path, limits);
}

}  // namespace softdeca::avatar_import
