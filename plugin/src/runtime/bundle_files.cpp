#include "runtime/bundle_files.h"

#include <cstring>
#include <fstream>
#include <sys/stat.h>

#include "core/error.h"

namespace softdeca::runtime {

namespace {
bool is_directory(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

Bytes read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw Error(SOFTDECA_ERROR_IO, "cannot open " + path);
  const std::streamoff size = in.tellg();
  if (size < 0) throw Error(SOFTDECA_ERROR_IO, "cannot read " + path);
  Bytes data(static_cast<std::size_t>(size));
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(data.data()), size))
    throw Error(SOFTDECA_ERROR_IO, "cannot read " + path);
  return data;
}

// ustar numeric fields: octal text, NUL or space terminated.
std::uint64_t octal(const std::uint8_t* field, std::size_t n, const std::string& what) {
  std::uint64_t v = 0;
  std::size_t i = 0;
  while (i < n && field[i] == ' ') ++i;
  bool any = false;
  for (; i < n && field[i] >= '0' && field[i] <= '7'; ++i) {
    if (v > (std::uint64_t{1} << 60)) throw Error(SOFTDECA_ERROR_FORMAT, "tar: " + what + " too large");
    v = v * 8 + (field[i] - '0');
    any = true;
  }
  if (!any || (i < n && field[i] != 0 && field[i] != ' '))
    throw Error(SOFTDECA_ERROR_FORMAT, "tar: bad " + what + " field");
  return v;
}

std::string field_text(const std::uint8_t* field, std::size_t n) {
  std::size_t len = 0;
  while (len < n && field[len]) ++len;
  return std::string(reinterpret_cast<const char*>(field), len);
}
}  // namespace

BundleFiles BundleFiles::from_path(const std::string& path) {
  if (!is_directory(path)) {
    const Bytes data = read_file(path);
    BundleFiles b = from_tar(data.data(), data.size());
    b.origin_ = path;
    return b;
  }
  BundleFiles b;
  b.origin_ = path;
  b.lazy_ = true;
  return b;
}

BundleFiles BundleFiles::from_tar(const std::uint8_t* data, std::size_t size) {
  BundleFiles b;
  b.origin_ = "memory";
  std::size_t pos = 0;
  bool ended = false;
  while (pos + 512 <= size) {
    const std::uint8_t* h = data + pos;
    bool zero = true;
    for (int i = 0; i < 512 && zero; ++i) zero = h[i] == 0;
    if (zero) { ended = true; break; }
    // Checksum: sum of the header bytes with the checksum field read as spaces.
    std::uint64_t sum = 0;
    for (int i = 0; i < 512; ++i) sum += (i >= 148 && i < 156) ? ' ' : h[i];
    if (octal(h + 148, 8, "checksum") != sum) throw Error(SOFTDECA_ERROR_FORMAT, "tar: header checksum mismatch");
    const std::uint64_t n = octal(h + 124, 12, "size");
    std::string name = field_text(h, 100);
    if (std::memcmp(h + 257, "ustar", 5) == 0 && h[345]) name = field_text(h + 345, 155) + "/" + name;
    const char type = static_cast<char>(h[156]);
    pos += 512;
    if (n > size - pos) throw Error(SOFTDECA_ERROR_FORMAT, "tar: member " + name + " runs past the end");
    if (type == '0' || type == '\0') {
      while (name.compare(0, 2, "./") == 0) name.erase(0, 2);
      b.files_[name] = Bytes(data + pos, data + pos + n);
    }
    pos += (n + 511) / 512 * 512;
  }
  if (!ended && pos != size) throw Error(SOFTDECA_ERROR_FORMAT, "tar: truncated archive");
  if (b.files_.empty()) throw Error(SOFTDECA_ERROR_FORMAT, "tar: no files in the archive");
  // Members inside one top-level folder are addressed relative to it.
  if (!b.files_.count("manifest.json")) {
    std::map<std::string, Bytes> stripped;
    for (auto& [name, bytes] : b.files_) {
      const std::size_t slash = name.find('/');
      if (slash != std::string::npos) stripped[name.substr(slash + 1)] = std::move(bytes);
    }
    if (stripped.count("manifest.json")) b.files_ = std::move(stripped);
  }
  return b;
}

bool BundleFiles::has(const std::string& name) const {
  if (!lazy_) return files_.count(name) > 0;
  struct stat st {};
  return ::stat((origin_ + "/" + name).c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

const Bytes& BundleFiles::get(const std::string& name) const {
  if (name.empty() || name.find("..") != std::string::npos || name[0] == '/')
    throw Error(SOFTDECA_ERROR_FORMAT, "bundle file name '" + name + "' is not a plain relative path");
  if (!lazy_) {
    const auto it = files_.find(name);
    if (it == files_.end()) throw Error(SOFTDECA_ERROR_FORMAT, origin_ + ": bundle has no file " + name);
    return it->second;
  }
  auto it = cache_.find(name);
  if (it == cache_.end()) {
    const std::string path = origin_ + "/" + name;
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) throw Error(SOFTDECA_ERROR_FORMAT, origin_ + ": bundle has no file " + name);
    it = cache_.emplace(name, read_file(path)).first;
  }
  return it->second;
}

}  // namespace softdeca::runtime
