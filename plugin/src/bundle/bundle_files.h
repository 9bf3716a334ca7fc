// The files of a model bundle, from a folder or from one uncompressed tar archive in memory
// (how hosts such as Unity ship a bundle as a single asset). A bundle is untrusted input: a
// folder's files must be regular files inside it (symlinks only when they resolve inside the
// bundle; FIFOs and devices are refused without being opened for reading), and sizes are capped.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace softdeca::bundle {

using Bytes = std::vector<std::uint8_t>;

struct BundleLimits {
  std::uint64_t max_file_bytes = std::uint64_t{1} << 30;   // any one file (or tar member)
  std::uint64_t max_total_bytes = std::uint64_t{2} << 30;  // all files read, and a .tar itself
};

class BundleFiles {
 public:
  // A folder, or a path to a .tar file. Throws Error(SOFTDECA_ERROR_IO) when unreadable,
  // Error(FORMAT) for a file that is not regular, leaves the bundle or exceeds a limit.
  static BundleFiles from_path(const std::string& path, const BundleLimits& limits = {});
  // A ustar archive; members may sit in one top-level folder. Throws Error(FORMAT) when damaged
  // or over a limit.
  static BundleFiles from_tar(const std::uint8_t* data, std::size_t size, const BundleLimits& limits = {});

  // The bytes of `name` (a path relative to the bundle root). Throws Error(FORMAT) when missing.
  const Bytes& get(const std::string& name) const;
  bool has(const std::string& name) const;
  const std::string& origin() const { return origin_; }

 private:
  std::map<std::string, Bytes> files_;
  std::string origin_;  // for messages: the folder, or "memory"
  std::string root_;    // folder: its canonical path (symlinks resolved)
  bool lazy_ = false;   // folder: files are read on first get()
  BundleLimits limits_;
  mutable std::map<std::string, Bytes> cache_;
  mutable std::uint64_t bytes_read_ = 0;
};

}  // namespace softdeca::bundle
