// SoftDECA frames of several avatars in one call (softdeca_avatar_evaluate_weights_batch):
// the frame networks run once for all of them. f_w runs once over the weights of every avatar of
// one model, and the residual stage's f_r_w once over those of them prepared with the same
// condition (the same parameters), so those networks' weights are read once a call, not once an
// avatar: in a crowd they no longer stay in cache from one avatar's frame to the next. Each
// avatar's frame then runs as evaluate_weights with these codes, and equals its own call's.
#pragma once

#include <cstddef>
#include <vector>

#include "runtime/avatar.h"

namespace softdeca::runtime {

constexpr std::size_t kMaxBatchAvatars = 4096;  // a call's avatars at most (memory and time bounded)

// Error(INVALID_ARGUMENT) unless 1 <= count <= kMaxBatchAvatars.
void require_batch_size(std::size_t count);

struct FrameBatch {
  std::vector<float> z, c;        // each avatar's row: latent floats, then the residual stage's modes
  std::vector<FrameCodes> codes;  // per avatar
  std::vector<char> encoded;      // whether codes[i] holds avatar i's codes
  // Avatar i's codes; null where the batch left it to its own call (no SoftDECA, weights its
  // frame refuses, no preparation yet: that call reports it).
  const FrameCodes* of(std::size_t i) const { return encoded[i] ? &codes[i] : nullptr; }
};

// The codes of `count` avatars (null entries allowed: left out), avatar i's weights at
// weights + i * per_avatar. Error(INVALID_ARGUMENT) for a count out of range (require_batch_size)
// or a null `weights`; a network's failure throws as the avatar's own run would.
FrameBatch encode_weights_batch(Avatar* const* avatars, std::size_t count, const float* weights, std::size_t per_avatar);

}  // namespace softdeca::runtime
