#include "mesh_io.h"

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace softdeca::cli {

void write_obj(const std::string& path, const float* v, std::size_t nv, const float* n, const std::int32_t* t, std::size_t nt,
               const std::string& comment, const std::vector<ObjGroup>& groups) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + path);
  std::fprintf(f, "# %s\n", comment.c_str());
  for (std::size_t i = 0; i < nv; ++i) std::fprintf(f, "v %.6f %.6f %.6f\n", v[3 * i], v[3 * i + 1], v[3 * i + 2]);
  if (n)
    for (std::size_t i = 0; i < nv; ++i) std::fprintf(f, "vn %.5f %.5f %.5f\n", n[3 * i], n[3 * i + 1], n[3 * i + 2]);
  std::size_t group = 0;
  for (std::size_t i = 0; i < nt; ++i) {
    for (; group < groups.size() && groups[group].first_triangle <= i; ++group) {
      std::string name = groups[group].name;  // a file's own names: no line breaks into the OBJ
      for (char& ch : name)
        if (static_cast<unsigned char>(ch) < 0x20) ch = '_';
      std::fprintf(f, "o %s\n", name.c_str());
    }
    const long a = t[3 * i] + 1, b = t[3 * i + 1] + 1, c = t[3 * i + 2] + 1;
    if (n) std::fprintf(f, "f %ld//%ld %ld//%ld %ld//%ld\n", a, a, b, b, c, c);
    else std::fprintf(f, "f %ld %ld %ld\n", a, b, c);
  }
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path);
}

Pc2Writer::Pc2Writer(const std::string& path, std::size_t points, float start_frame, float sample_rate)
    : path_(path), points_(points) {
  if (points > 0x7fffffffu) throw std::runtime_error(path + ": a PC2 file holds at most 2^31 - 1 points");
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw std::runtime_error("cannot write " + path);
  char signature[12] = "POINTCACHE2";
  const std::int32_t version = 1, n = static_cast<std::int32_t>(points), zero = 0;
  std::fwrite(signature, 1, 12, file_);
  std::fwrite(&version, 4, 1, file_);
  std::fwrite(&n, 4, 1, file_);
  std::fwrite(&start_frame, 4, 1, file_);
  std::fwrite(&sample_rate, 4, 1, file_);
  std::fwrite(&zero, 4, 1, file_);
}

Pc2Writer::~Pc2Writer() {
  if (file_) std::fclose(file_);
}

void Pc2Writer::add(const float* xyz) {
  if (std::fwrite(xyz, sizeof(float), points_ * 3, file_) != points_ * 3) throw std::runtime_error("cannot write " + path_);
  ++frames_;
}

void Pc2Writer::close() {
  if (!file_) return;
  const std::int32_t n = static_cast<std::int32_t>(frames_);
  const bool ok = std::fseek(file_, 28, SEEK_SET) == 0 && std::fwrite(&n, 4, 1, file_) == 1;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) throw std::runtime_error("cannot finish " + path_);
}

}  // namespace softdeca::cli
