// The ONNX model scan a bundle's networks pass before ONNX Runtime sees them: any bytes are
// scanned or refused with softdeca::Error; never a crash or a read out of bounds.
#include <cstddef>
#include <cstdint>

#include "api/error_boundary.h"
#include "bundle/onnx_model_scan.h"
#include "fuzz_check.h"

using namespace softdeca::runtime;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const OnnxModelScan s = scan_onnx_model(data, size);
    FUZZ_CHECK(s.total_bytes() >= s.initializer_bytes);
    FUZZ_CHECK(s.total_bytes() >= s.largest_bytes || s.largest_tensor.empty() || s.largest_bytes == 0 ||
               s.total_bytes() == UINT64_MAX);
  } catch (const softdeca::Error&) {
  }
  return 0;
}
