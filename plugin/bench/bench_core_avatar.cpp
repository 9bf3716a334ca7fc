#include "bench_core_avatar.h"

#include "bundle/bundle_files.h"
#include "runtime/avatar.h"
#include "runtime/model.h"

namespace softdeca::cli {

struct CoreAvatar::State {
  std::shared_ptr<const runtime::Model> model;
  std::unique_ptr<runtime::Avatar> avatar;
};

CoreAvatar::CoreAvatar(const std::string& bundle_path, const std::vector<float>& neutral,
                       const std::vector<std::int32_t>& triangles, const std::vector<float>& deltas)
    : state_(std::make_unique<State>()) {
  state_->model = runtime::Model::load(bundle::BundleFiles::from_path(bundle_path), {});
  runtime::AvatarDesc desc;
  desc.neutral = neutral.data();
  desc.vertex_count = neutral.size() / 3;
  desc.triangles = triangles.data();
  desc.triangle_count = triangles.size() / 3;
  desc.blendshapes = deltas.empty() ? nullptr : deltas.data();
  desc.blendshape_count = deltas.empty() ? 0 : 52;
  desc.precisions = {kernels::Precision::Half, kernels::Precision::Half};
  state_->avatar = std::make_unique<runtime::Avatar>(state_->model, desc);
  state_->avatar->prepare();
}

CoreAvatar::~CoreAvatar() = default;

void CoreAvatar::evaluate_weights(const float* weights, float* vertices, float* normals, std::size_t capacity) {
  state_->avatar->evaluate_weights(weights, 52, runtime::Output{vertices, capacity, normals, capacity});
}

}  // namespace softdeca::cli
