#include "runtime/dynamics.h"

#include <cmath>
#include <cstring>
#include <string>

#include "core/error.h"

namespace softdeca::runtime {

void DynamicsCoefficients::check(const bundle::Manifest& m, const char* network) const {
  constexpr double kTol = 1e-5;
  for (std::size_t v = 0; v < alpha.size(); ++v) {
    const double a = alpha[v], b = beta[v], g = gamma[v];
    const bool ok = std::isfinite(a) && std::isfinite(b) && std::isfinite(g) && b >= -kTol && b <= m.beta_max + kTol &&
                    g >= m.gamma_min - kTol && g <= m.gamma_max + kTol && std::fabs(g + 2 * a - b - 1) <= 1e-4;
    if (!ok)
      throw Error(SOFTDECA_ERROR_FORMAT, std::string(network) + " gives vertex " + std::to_string(v) + " alpha=" +
                                             std::to_string(a) + " beta=" + std::to_string(b) + " gamma=" + std::to_string(g) +
                                             ", outside the stable set with gamma + 2 alpha - beta = 1");
  }
}

DynamicsState::DynamicsState(std::size_t n) {
  for (auto& b : buffer_) b.resize(3 * n);
}

void DynamicsState::step(const DynamicsCoefficients& c, int model, const float* y, std::size_t v0, std::size_t v1) {
  float* out = next();
  if (!valid(model)) {  // at rest: both past frames equal the current target, so X = Y
    std::memcpy(out + 3 * v0, y + 3 * v0, (v1 - v0) * 3 * sizeof(float));
    return;
  }
  const float* x1 = buffer_[head_].data();
  const float* x2 = buffer_[(head_ + 1) % 3].data();
  for (std::size_t v = v0; v < v1; ++v) {
    const float g = c.gamma[v], a2 = 2.0f * c.alpha[v], b = c.beta[v];
    for (std::size_t k = 3 * v; k < 3 * v + 3; ++k) out[k] = g * y[k] + a2 * x1[k] - b * x2[k];
  }
}

void DynamicsState::commit(int model) {
  const std::size_t written = (head_ + 2) % 3;
  if (!valid(model)) {  // the first frame fills both past frames
    std::memcpy(buffer_[(written + 1) % 3].data(), buffer_[written].data(), buffer_[written].bytes());
  }
  head_ = written;  // x_{t-1} = written; x_{t-2} = old x_{t-1}; the old x_{t-2} is reused next
  valid_ = true;
  model_ = model;
}

}  // namespace softdeca::runtime
