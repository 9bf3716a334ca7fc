#include "runtime/frame_batch.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <unordered_map>

#include "core/error.h"
#include "runtime/model.h"

namespace softdeca::runtime {

namespace {
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// The residual stage's modes of the model's frames (0 without one).
std::size_t modes_of(const Model& model) {
  return model.residual_condition() ? static_cast<std::size_t>(model.manifest().residual_modes) : 0;
}

// The rows `members` of a row-major matrix with `width` columns, gathered contiguously.
std::vector<float> gather(const std::vector<float>& rows, std::size_t width, const std::vector<std::size_t>& members) {
  std::vector<float> out(members.size() * width);
  for (std::size_t j = 0; j < members.size(); ++j)
    std::memcpy(out.data() + j * width, rows.data() + members[j] * width, width * sizeof(float));
  return out;
}

// Block row j (`width` floats) into row members[j] of `rows` (`stride` floats a row).
void scatter(const std::vector<float>& block, std::size_t width, const std::vector<std::size_t>& members,
             std::size_t stride, std::vector<float>& rows) {
  for (std::size_t j = 0; j < members.size(); ++j)
    std::memcpy(rows.data() + members[j] * stride, block.data() + j * width, width * sizeof(float));
}

// The avatars of one model among those the batch encodes (`members`): f_w once over all of
// them, f_r_w once per group prepared with the same condition; into rows of `z_stride` and
// `c_stride` floats of batch.z and batch.c.
void encode_model_group(const Model& model, const std::vector<std::size_t>& members, const std::vector<float>& weights,
                        FrameBatch& batch, std::size_t z_stride, std::size_t c_stride) {
  const bundle::Manifest& m = model.manifest();
  const auto latent = static_cast<std::size_t>(m.latent);
  const std::size_t modes = modes_of(model);
  const auto t = Clock::now();
  const auto n = static_cast<std::int64_t>(members.size());
  const std::vector<float> w = gather(weights, bundle::kBlendshapeCount, members);
  std::vector<float> z(members.size() * latent);
  model.encoder(false)->run({w.data()}, {z.data()}, n);
  scatter(z, latent, members, z_stride, batch.z);
  if (modes > 0) {
    // groups by condition, bit for bit (keyed by its bytes: linear in the batch's size)
    std::unordered_map<std::string, std::vector<std::size_t>> groups;
    std::vector<const std::string*> order;
    for (const std::size_t i : members) {
      const std::vector<float>& condition = batch.codes[i].prep->residual_condition;
      std::string key(reinterpret_cast<const char*>(condition.data()), condition.size() * sizeof(float));
      auto [it, added] = groups.try_emplace(std::move(key));
      if (added) order.push_back(&it->first);
      it->second.push_back(i);
    }
    for (const std::string* key : order) {
      const std::vector<std::size_t>& same = groups.at(*key);
      const std::vector<float>& condition = batch.codes[same.front()].prep->residual_condition;
      const std::vector<float> ws = gather(weights, bundle::kBlendshapeCount, same);
      std::vector<float> c(same.size() * modes);
      model.residual_coefficients()->run({ws.data(), condition.data()}, {c.data()},
                                         static_cast<std::int64_t>(same.size()));
      scatter(c, modes, same, c_stride, batch.c);
    }
  }
  const double share = ms_since(t) / static_cast<double>(members.size());
  for (const std::size_t i : members) {
    batch.codes[i].z = batch.z.data() + i * z_stride;
    batch.codes[i].c = modes > 0 ? batch.c.data() + i * c_stride : nullptr;
    batch.codes[i].network_ms = share;
    batch.encoded[i] = 1;
  }
}

}  // namespace

void require_batch_size(std::size_t count) {
  expect(count >= 1 && count <= kMaxBatchAvatars, [&] {
    return "a batch holds 1 to " + std::to_string(kMaxBatchAvatars) + " avatars, not " + std::to_string(count);
  });
}

FrameBatch encode_weights_batch(Avatar* const* avatars, std::size_t count, const float* weights, std::size_t per_avatar) {
  require_not_null(avatars, "avatars");
  require_not_null(weights, "weights");
  require_batch_size(count);
  FrameBatch batch;
  batch.codes.resize(count);
  batch.encoded.assign(count, 0);
  // Each avatar's weights as its frame will read them; an avatar whose frame would refuse them
  // (or has no SoftDECA, or no preparation) is left to its own call, which says why.
  const std::size_t nw = bundle::kBlendshapeCount;
  std::vector<float> checked(count * nw, 0.0f);
  std::vector<const Model*> models;  // distinct, in order of appearance
  std::vector<char> eligible(count, 0);
  for (std::size_t i = 0; i < count; ++i) {
    Avatar* a = avatars[i];
    if (!a || !a->model().has(false)) continue;
    try {
      Avatar::check_weights(weights + i * per_avatar, per_avatar, checked.data() + i * nw);
      batch.codes[i].prep = a->prepared();
    } catch (const Error&) {
      continue;
    }
    eligible[i] = 1;
    if (std::find(models.begin(), models.end(), &a->model()) == models.end()) models.push_back(&a->model());
  }
  // a row per avatar of the call, as wide as the widest model's, so that codes point into storage
  // that stays where it is
  std::size_t z_stride = 0, c_stride = 0;
  for (const Model* model : models) {
    z_stride = std::max(z_stride, static_cast<std::size_t>(model->manifest().latent));
    c_stride = std::max(c_stride, modes_of(*model));
  }
  batch.z.assign(count * z_stride, 0.0f);
  batch.c.assign(count * c_stride, 0.0f);
  for (const Model* model : models) {
    std::vector<std::size_t> members;
    for (std::size_t i = 0; i < count; ++i)
      if (eligible[i] && &avatars[i]->model() == model) members.push_back(i);
    encode_model_group(*model, members, checked, batch, z_stride, c_stride);
  }
  return batch;
}

}  // namespace softdeca::runtime
