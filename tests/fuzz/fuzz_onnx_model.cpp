// The ONNX model scan a bundle's networks pass before ONNX Runtime sees them: any bytes are
// scanned or refused with softdeca::Error; never a crash or a read out of bounds. The bytes
// are scanned as a network fed one input, "x" of [batch, 3].
#include <cstddef>
#include <cstdint>

#include "api/error_boundary.h"
#include "bundle/onnx_model_scan.h"
#include "fuzz_check.h"

using namespace softdeca::bundle;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const OnnxModelScan s = scan_onnx_model(data, size, {{"x", {-1, 3}}});
    FUZZ_CHECK(s.bytes >= s.largest_bytes);
    FUZZ_CHECK(s.external_tensors.empty() || s.bytes == 0);  // with external data nothing is counted
  } catch (const softdeca::Error&) {
  }
  return 0;
}
