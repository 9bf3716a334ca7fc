// A bundle folder built from the input: regular files, links (inside and outside the bundle,
// dangling, to folders), FIFOs and subfolders. Reading every name must never hang (a FIFO
// opened for reading would), and must never return the bytes of the secret file beside the
// bundle, however the links point.
//
// Input: entries of [kind % 5][name length][name][content length][content]; kind 0 file,
// 1 link to content, 2 FIFO, 3 folder, 4 link to the secret file.
#include <sys/stat.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "api/error_boundary.h"
#include "bundle/bundle_files.h"
#include "fuzz_check.h"
#include "fuzz_files.h"

namespace fs = std::filesystem;
using namespace softdeca::bundle;

namespace {
const std::string kSecret = "secret: never in a bundle";

using softdeca::fuzz::write_file;

fs::path workspace() {
  static const fs::path dir = softdeca::fuzz::workspace("folder");
  return dir;
}

// Names stay inside the bundle folder: [a-z0-9._/], no leading slash, no "..".
std::string clean_name(const std::string& raw) {
  std::string out;
  for (const char c : raw) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '/';
    out += ok ? c : '_';
  }
  while (!out.empty() && out[0] == '/') out.erase(0, 1);
  while (out.find("..") != std::string::npos) out.replace(out.find(".."), 2, "_");
  return out.empty() ? "f" : out;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path bundle = workspace() / "bundle";
  std::error_code ec;
  fs::remove_all(bundle, ec);
  fs::create_directories(bundle);
  fs::remove(workspace() / "secret", ec);  // links in the last input may have replaced it
  write_file(workspace() / "secret", kSecret);
  std::vector<std::string> names = {"manifest.json"};
  std::size_t pos = 0;
  const auto take = [&](std::size_t n) {
    n = std::min(n, size - pos);
    std::string s(reinterpret_cast<const char*>(data + pos), n);
    pos += n;
    return s;
  };
  for (int entry = 0; entry < 8 && pos + 2 <= size; ++entry) {
    const int kind = data[pos++] % 5;
    const std::string name = clean_name(take(data[pos++] % 24));
    const std::string content = pos < size ? take(data[pos++]) : std::string();
    const fs::path path = bundle / name;
    fs::create_directories(path.parent_path(), ec);
    fs::remove_all(path, ec);
    switch (kind) {
      case 0: write_file(path, content); break;
      case 1: fs::create_symlink(content.empty() ? "x" : content, path, ec); break;
      case 2: ::mkfifo(path.c_str(), 0600); break;
      case 3: fs::create_directories(path, ec); break;
      case 4: fs::create_symlink(content.size() % 2 ? "../secret" : (workspace() / "secret").string(), path, ec); break;
    }
    names.push_back(name);
  }
  try {
    BundleLimits limits;
    limits.max_file_bytes = 200;
    limits.max_total_bytes = 600;
    const BundleFiles files = BundleFiles::from_path(bundle.string(), limits);
    for (const std::string& name : names) {
      try {
        const Bytes& b = files.get(name);
        FUZZ_CHECK(b.size() <= limits.max_file_bytes);
        FUZZ_CHECK(std::string(b.begin(), b.end()) != kSecret);
      } catch (const softdeca::Error&) {
      }
    }
  } catch (const softdeca::Error&) {
  }
  return 0;
}
