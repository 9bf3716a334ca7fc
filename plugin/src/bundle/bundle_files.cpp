#include "bundle/bundle_files.h"

#include <cstring>

#include "bundle/bundle_folder_io.h"
#include "core/error.h"

namespace softdeca::bundle {

namespace {
std::string mib(std::uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

const char* kind_name(EntryKind kind) {
  switch (kind) {
    case EntryKind::fifo: return "a FIFO";
    case EntryKind::folder: return "a folder";
    case EntryKind::device: return "a device";
    case EntryKind::socket: return "a socket";
    default: return "not a regular file";
  }
}

// Reads a regular file. Its kind first, then an open that follows no link and does not block
// (a FIFO swapped in between opens at once and fails the second check): nothing but a regular
// file is ever read. `label` names the file in messages.
Bytes read_regular(const std::string& path, const std::string& label, std::uint64_t max_bytes) {
  const EntryKind kind = entry_kind(path);
  if (kind == EntryKind::missing) throw Error(SOFTDECA_ERROR_IO, "cannot open " + label);
  if (kind != EntryKind::regular) throw Error(SOFTDECA_ERROR_FORMAT, label + " is " + kind_name(kind) + ", not a regular file");
  ReadOnlyFile file(path);
  if (!file.is_open()) throw Error(SOFTDECA_ERROR_IO, "cannot open " + label);
  if (!file.is_regular()) throw Error(SOFTDECA_ERROR_FORMAT, label + " is not a regular file");
  const std::uint64_t size = file.size();
  if (size > max_bytes)
    throw Error(SOFTDECA_ERROR_FORMAT, label + " is " + mib(size) + ", over the limit of " + mib(max_bytes));
  Bytes data(static_cast<std::size_t>(size));
  if (!file.read(data.data(), data.size())) throw Error(SOFTDECA_ERROR_IO, "cannot read " + label);
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

// A name as messages show it: control bytes (a NUL would end the C ABI's message) as \xNN.
std::string printable(const std::string& name) {
  std::string out;
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u != 0x7f) {
      out += c;
      continue;
    }
    static const char kHex[] = "0123456789abcdef";
    out += "\\x";
    out += kHex[u >> 4];
    out += kHex[u & 15];
  }
  return out;
}

void check_name(const std::string& name) {
  if (name.empty() || name.find("..") != std::string::npos || name[0] == '/' || name.find('\0') != std::string::npos)
    throw Error(SOFTDECA_ERROR_FORMAT, "bundle file name '" + printable(name) + "' is not a plain relative path");
}
}  // namespace

BundleFiles BundleFiles::from_path(const std::string& path, const BundleLimits& limits) {
  const EntryKind kind = target_kind(path);
  if (kind == EntryKind::missing) throw Error(SOFTDECA_ERROR_IO, "cannot open " + path);
  if (kind != EntryKind::folder) {
    // A .tar: the path itself may be a link (the caller chose it), its target must be regular.
    const std::string target = resolve_path(path);
    if (target.empty()) throw Error(SOFTDECA_ERROR_IO, "cannot open " + path);
    const Bytes data = read_regular(target, path, limits.max_total_bytes);
    BundleFiles b = from_tar(data.data(), data.size(), limits);
    b.origin_ = path;
    return b;
  }
  BundleFiles b;
  b.origin_ = path;
  b.root_ = resolve_path(path);
  if (b.root_.empty()) throw Error(SOFTDECA_ERROR_IO, "cannot open " + path);
  b.lazy_ = true;
  b.limits_ = limits;
  return b;
}

BundleFiles BundleFiles::from_tar(const std::uint8_t* data, std::size_t size, const BundleLimits& limits) {
  BundleFiles b;
  b.origin_ = "memory";
  b.limits_ = limits;
  if (size > limits.max_total_bytes)
    throw Error(SOFTDECA_ERROR_FORMAT, "tar: the archive is " + mib(size) + ", over the limit of " + mib(limits.max_total_bytes));
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
      if (n > limits.max_file_bytes)
        throw Error(SOFTDECA_ERROR_FORMAT, "tar: member " + name + " is " + mib(n) + ", over the limit of " +
                                               mib(limits.max_file_bytes));
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
  const EntryKind kind = entry_kind(join_path(root_, name));
  return kind == EntryKind::regular || kind == EntryKind::link;
}

const Bytes& BundleFiles::get(const std::string& name) const {
  check_name(name);
  if (!lazy_) {
    const auto it = files_.find(name);
    if (it == files_.end()) throw Error(SOFTDECA_ERROR_FORMAT, origin_ + ": bundle has no file " + name);
    return it->second;
  }
  auto it = cache_.find(name);
  if (it == cache_.end()) {
    const std::string path = join_path(root_, name);
    const std::string label = origin_ + ": bundle file " + name;
    const EntryKind kind = entry_kind(path);
    if (kind == EntryKind::missing) throw Error(SOFTDECA_ERROR_FORMAT, origin_ + ": bundle has no file " + name);
    if (kind != EntryKind::regular && kind != EntryKind::link)
      throw Error(SOFTDECA_ERROR_FORMAT, label + " is " + kind_name(kind) + ", not a regular file");
    // Resolve links (in any component) and require the result inside the bundle's folder.
    const std::string resolved = resolve_path(path);
    if (resolved.empty()) throw Error(SOFTDECA_ERROR_FORMAT, label + " is a broken link");
    if (!path_inside(root_, resolved)) throw Error(SOFTDECA_ERROR_FORMAT, label + " is a link that leaves the bundle");
    const std::uint64_t left = limits_.max_total_bytes - bytes_read_;
    Bytes data = read_regular(resolved, label, left < limits_.max_file_bytes ? left : limits_.max_file_bytes);
    bytes_read_ += data.size();
    it = cache_.emplace(name, std::move(data)).first;
  }
  return it->second;
}

}  // namespace softdeca::bundle
