// A bundle as a tar in memory (how Unity hands one over): the archive reader, then the
// manifest and the ONNX scan of every member, as Model::load runs them before ONNX Runtime.
#include <cstddef>
#include <cstdint>
#include <string>

#include "api/error_boundary.h"
#include "bundle/bundle_files.h"
#include "bundle/manifest.h"
#include "bundle/onnx_model_scan.h"
#include "fuzz_check.h"

using namespace softdeca::bundle;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    BundleLimits limits;
    limits.max_file_bytes = 1 << 16;
    const BundleFiles files = BundleFiles::from_tar(data, size, limits);
    const Bytes& m = files.get("manifest.json");
    FUZZ_CHECK(m.size() <= limits.max_file_bytes);
    try {
      const Manifest manifest = parse_manifest(std::string(m.begin(), m.end()));
      for (const auto& [key, n] : manifest.networks) {
        if (!files.has(n.file)) continue;
        const Bytes& onnx = files.get(n.file);
        scan_onnx_model(onnx.data(), onnx.size(), n.inputs);
      }
    } catch (const softdeca::Error&) {
    }
  } catch (const softdeca::Error&) {
  }
  return 0;
}
