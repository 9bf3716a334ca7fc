// bench-reliability's bundle memory run: what loading a bundle costs in resident memory when
// its network asks for large constant-foldable tensors, against the memory budget
// (docs/security.md, "Memory budget"). Copies of a small bundle get one extra fragment each
// (a ConstantOfShape, an Expand, a ConstantOfShape of a shape made by a Mul, a Gather or a
// Shape and Concat, a self-Concat, a MatMul outer product), sized just under the budget, just
// over it and far over it (ONNX Runtime's constant folding is off for bundle networks, so a
// copy that loads computes none of it); each copy is loaded in a child
// process so that one load's peak does not hide another's. The child has loaded the bundle
// unchanged first: ONNX Runtime's start, the same for every bundle and once a process, is
// measured on its own.
#pragma once

#include <cstdint>
#include <string>

namespace softdeca::cli {

struct BundleMemory {
  double worst_ratio = 0;  // peak RSS increase while loading / budget, worst case
  std::string worst;       // "<family> <size>, loaded|refused"
  int bundles = 0, loaded = 0, refused = 0;
  std::uint64_t runtime_start_bytes = 0;  // peak RSS increase of the first load in a process
};

// `bundle`: a bundle folder to copy; copies go under `scratch` and are removed. Throws
// std::runtime_error when a child dies or a bundle expected to load is refused.
BundleMemory bundle_memory_run(const std::string& bundle, const std::string& scratch, std::uint64_t budget);

}  // namespace softdeca::cli
