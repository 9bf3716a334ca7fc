// The core avatar of the runtime (runtime::Avatar) on a template-topology head, made and run
// directly, not through the C ABI: what bench-runtime times the handle's template path against
// (runtime.identity_fit_overhead). The one benchmark file that names the runtime's avatar.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace softdeca::cli {

class CoreAvatar {
 public:
  // `deltas`: 52 x vertices x 3 (empty: no blendshapes). Both models' tables in half, as the
  // handle it is timed against (cmd_bench_runtime.cpp); prepared at the defaults.
  CoreAvatar(const std::string& bundle_path, const std::vector<float>& neutral, const std::vector<std::int32_t>& triangles,
             const std::vector<float>& deltas);
  ~CoreAvatar();
  CoreAvatar(const CoreAvatar&) = delete;
  CoreAvatar& operator=(const CoreAvatar&) = delete;

  // One frame from 52 weights into caller buffers of `vertices` points each.
  void evaluate_weights(const float* weights, float* vertices, float* normals, std::size_t capacity);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace softdeca::cli
