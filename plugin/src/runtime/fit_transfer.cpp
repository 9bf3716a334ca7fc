#include "runtime/fit_transfer.h"

#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "geometry/normals.h"
#include "runtime/blendshapes.h"

namespace softdeca::runtime {
namespace {

class IdentityTransfer final : public FitTransfer {
 public:
  Output core_output(const Output& out) override { return out; }
  Output surface_output(const Output& out) override { return out; }
  void softdeca(Avatar& core, const float* weights, std::size_t count, const Output& out, const FrameCodes* codes) override {
    core.evaluate_weights(weights, count, out, codes);
  }
  void linear(Avatar& core, const float* weights, std::size_t count, const Output& out) override {
    core.evaluate_linear(weights, count, out);
  }
  void rest(const Output&) override {}
  void carry(const float*, const Output&) override {}
  void finish(const Output&) override {}  // the core wrote the normals
  void set_parameter_faces(Avatar& core, int index, const float* values, std::size_t count) override {
    core.set_parameter_faces(index, values, count);
  }
  void set_parameter_vertices(Avatar& core, int index, const float* values, std::size_t count) override {
    core.set_parameter_vertices(index, values, count);
  }
  std::size_t bytes() const override { return 0; }
};

class EmbeddingTransfer final : public FitTransfer {
 public:
  EmbeddingTransfer(const fit::TemplateData& t, const fit::AvatarMesh& a, const fit::AvatarFit& f, const float* core_shapes,
                    std::shared_ptr<const CarryMap> carry)
      : n_(a.vertex_count),
        vs_(t.skin_vertices),
        vh_(t.head_vertices),
        neutral_(a.neutral, a.neutral + n_ * 3),
        triangles_(a.triangles, a.triangles + a.triangle_count * 3),
        carry_(std::move(carry)),
        source_(f.source) {
    // The avatar's own shapes; a shape its rig lacks is the template's, carried back onto the
    // avatar's face through the embedding, so a rig without some (or any) shapes animates fully.
    std::vector<float> own(bundle::kBlendshapeCount * n_ * 3, 0.0f);
    for (std::size_t k = 0; k < static_cast<std::size_t>(bundle::kBlendshapeCount); ++k) {
      if (a.deltas[k]) std::memcpy(own.data() + k * n_ * 3, a.deltas[k], n_ * 3 * sizeof(float));
      else if (f.origin[k] == fit::ShapeOrigin::Template) carry_->add_field(core_shapes + k * vh_ * 3, own.data() + k * n_ * 3);
    }
    blendshapes_ = Blendshapes(own.data(), bundle::kBlendshapeCount, n_, 1);
    head_out_.resize(vh_ * 3);
    field_.resize(vs_ * 3);
    carried_.resize(carry_->size() * 3);
    normals_ = geometry::Normals(triangles_, n_);
  }

  Output core_output(const Output& out) override {
    check_output_capacity(out, n_);
    Output inner;
    inner.vertices = head_out_.data();
    inner.vertex_capacity = vh_;
    return inner;
  }

  Output surface_output(const Output&) override {
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT,
                "evaluate_surface takes a surface in the template's topology: an avatar on its own mesh takes weights or "
                "landmarks");
  }

  void softdeca(Avatar& core, const float* weights, std::size_t count, const Output& out, const FrameCodes* codes) override {
    check_output_capacity(out, n_);
    core.evaluate_carried(weights, count, carried_.data(), codes);  // checks the weights; out untouched on error
    blendshapes_.blend(core.weights(), neutral_.data(), out.vertices, 0);
    carry_->add(carried_.data(), out.vertices);
  }

  void linear(Avatar& core, const float* weights, std::size_t count, const Output& out) override {
    check_output_capacity(out, n_);
    core.read_frame_weights(weights, count);
    blendshapes_.blend(core.weights(), neutral_.data(), out.vertices, 0);
  }

  void rest(const Output& out) override { std::memcpy(out.vertices, neutral_.data(), n_ * 3 * sizeof(float)); }

  void carry(const float* base, const Output& out) override {
    for (std::size_t i = 0; i < vs_ * 3; ++i) field_[i] = head_out_[i] - base[i];
    carry_->add_field(field_.data(), out.vertices);
  }

  void finish(const Output& out) override {
    if (!out.normals) return;
    normals_.faces(out.vertices, 0, 1);
    normals_.vertices(out.normals, 0, 1);
  }

  void set_parameter_vertices(Avatar& core, int index, const float* values, std::size_t count) override {
    require_not_null(values, "values");
    expect(count == n_, [&] {
      return "a fitted avatar's vertex map has one value per avatar vertex (" + std::to_string(n_) + "), got " +
             std::to_string(count);
    });
    require_finite(values, count, "values");
    // Each template skin vertex reads the map where it reads the avatar's shapes.
    std::vector<float> skin(vs_);
    for (std::size_t v = 0; v < vs_; ++v) {
      double x = 0;
      for (std::size_t k = 0; k < 3; ++k)
        x += source_.bary[3 * v + k] * values[static_cast<std::size_t>(source_.corners[3 * v + k])];
      skin[v] = static_cast<float>(x);
    }
    core.set_parameter_vertices(index, skin.data(), skin.size());
  }

  void set_parameter_faces(Avatar& core, int index, const float* values, std::size_t count) override {
    require_not_null(values, "values");
    const std::size_t nt = triangles_.size() / 3;
    expect(count == nt, [&] {
      return "a fitted avatar's face map has one value per avatar triangle (" + std::to_string(nt) + "), got " +
             std::to_string(count);
    });
    require_finite(values, count, "values");
    // Face values to vertex values (mean of the incident faces), then as a vertex map.
    std::vector<double> sum(n_, 0.0);
    std::vector<int> uses(n_, 0);
    for (std::size_t f = 0; f < nt; ++f)
      for (std::size_t k = 0; k < 3; ++k) {
        const auto v = static_cast<std::size_t>(triangles_[3 * f + k]);
        sum[v] += values[f];
        ++uses[v];
      }
    std::vector<float> vertex(n_);
    for (std::size_t v = 0; v < n_; ++v) vertex[v] = uses[v] ? static_cast<float>(sum[v] / uses[v]) : values[0];
    set_parameter_vertices(core, index, vertex.data(), vertex.size());
  }

  std::size_t bytes() const override {
    return (neutral_.size() + head_out_.size() + field_.size() + carried_.size()) * 4 + triangles_.size() * 4 +
           blendshapes_.bytes() + normals_.bytes() + carry_->bytes() + source_.corners.size() * 4 + source_.bary.size() * 4 +
           source_.weight.size() * 4;
  }

 private:
  std::size_t n_, vs_, vh_;
  // the avatar's own rig
  std::vector<float> neutral_;  // n x 3
  std::vector<std::int32_t> triangles_;
  Blendshapes blendshapes_;
  geometry::Normals normals_;
  // the fit: where the avatar's vertices sit on the template's skin, and where the skin reads the avatar
  std::shared_ptr<const CarryMap> carry_;
  fit::ShapeSource source_;
  // frame buffers
  std::vector<float> head_out_, field_, carried_;
};

}  // namespace

std::unique_ptr<FitTransfer> identity_transfer() { return std::make_unique<IdentityTransfer>(); }

std::unique_ptr<FitTransfer> embedding_transfer(const fit::TemplateData& t, const fit::AvatarMesh& mesh,
                                                const fit::AvatarFit& f, const float* core_shapes,
                                                std::shared_ptr<const CarryMap> carry) {
  return std::make_unique<EmbeddingTransfer>(t, mesh, f, core_shapes, std::move(carry));
}

}  // namespace softdeca::runtime
