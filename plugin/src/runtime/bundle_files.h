// The files of a model bundle, from a folder or from one uncompressed tar archive in memory
// (how hosts such as Unity ship a bundle as a single asset).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace softdeca::runtime {

using Bytes = std::vector<std::uint8_t>;

class BundleFiles {
 public:
  // A folder, or a path to a .tar file. Throws Error(SOFTDECA_ERROR_IO) when unreadable.
  static BundleFiles from_path(const std::string& path);
  // A ustar archive; members may sit in one top-level folder. Throws Error(FORMAT) when damaged.
  static BundleFiles from_tar(const std::uint8_t* data, std::size_t size);

  // The bytes of `name` (a path relative to the bundle root). Throws Error(FORMAT) when missing.
  const Bytes& get(const std::string& name) const;
  bool has(const std::string& name) const;
  const std::string& origin() const { return origin_; }

 private:
  std::map<std::string, Bytes> files_;
  std::string origin_;  // for messages: the folder, or "memory"
  bool lazy_ = false;   // folder: files are read on first get()
  mutable std::map<std::string, Bytes> cache_;
};

}  // namespace softdeca::runtime
