// Second-order dynamics per skin vertex (paper eq. 21): X_t = gamma Y_t + 2 alpha X_{t-1}
// - beta X_{t-2}, with coefficients from the bundle's f_dyn inside the stable set where
// gamma + 2 alpha - beta = 1 (a constant input stays constant). The state rotates through
// three buffers, so a frame copies nothing and a rejected frame leaves the state as it was.
#pragma once

#include <cstddef>

#include "bundle/manifest.h"
#include "kernels/aligned.h"

namespace softdeca::runtime {

struct DynamicsCoefficients {
  kernels::AlignedArray<float> alpha, beta, gamma;
  bool empty() const { return alpha.size() == 0; }
  std::size_t bytes() const { return alpha.bytes() + beta.bytes() + gamma.bytes(); }
  // Takes the network's outputs; throws Error(FORMAT) naming the network when a coefficient is
  // non-finite or outside the stable, equilibrium-preserving set the manifest declares.
  void check(const bundle::Manifest& m, const char* network) const;
};

class DynamicsState {
 public:
  explicit DynamicsState(std::size_t n_vertices = 0);
  std::size_t bytes() const { return 3 * buffer_[0].bytes(); }

  void invalidate() { valid_ = false; }
  bool valid(int model) const { return valid_ && model_ == model; }
  // The buffer the next step writes into.
  float* next() { return buffer_[(head_ + 2) % 3].data(); }
  // next()[v] for vertices [v0, v1) from the static output y (x_{t-1} = x_{t-2} = y when the
  // state is not valid for `model`).
  void step(const DynamicsCoefficients& c, int model, const float* y, std::size_t v0, std::size_t v1);
  // Accept next() as the newest state.
  void commit(int model);

 private:
  kernels::AlignedArray<float> buffer_[3];
  std::size_t head_ = 0;  // buffer_[head_] = x_{t-1}, buffer_[(head_+1)%3] = x_{t-2}
  bool valid_ = false;
  int model_ = -1;
};

}  // namespace softdeca::runtime
