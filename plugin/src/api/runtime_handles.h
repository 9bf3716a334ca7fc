// The C ABI's runtime handles, shared by the runtime and the fit parts of the ABI.
#pragma once

#include <memory>
#include <string>

#include "api/error_boundary.h"

#include "fit/avatar_fit.h"
#include "runtime/avatar.h"
#include "runtime/fitted_avatar.h"
#include "runtime/model.h"

struct softdeca_model {
  std::shared_ptr<const softdeca::runtime::Model> model;
};

// Every avatar, whichever mesh: on its fit, or on the identity fit of the template's topology
// (runtime/fitted_avatar.h); its core holds parameters, identity, preparation and dynamics.
struct softdeca_avatar {
  std::unique_ptr<softdeca::runtime::FittedAvatar> avatar;
};

struct softdeca_avatar_fit {
  softdeca::fit::AvatarFit fit;
  std::string bundle_sha256;
};

namespace softdeca::api {

inline const runtime::Model& model_of(const softdeca_model* m) {
  require_not_null(m, "model");
  return *m->model;
}

// A softdeca_precision value, checked; DEFAULT is `model_default`.
inline kernels::Precision precision_of(int32_t precision, kernels::Precision model_default, const char* name) {
  switch (precision) {
    case SOFTDECA_PRECISION_DEFAULT: return model_default;
    case SOFTDECA_PRECISION_HALF: return kernels::Precision::Half;
    case SOFTDECA_PRECISION_FLOAT: return kernels::Precision::Float;
    case SOFTDECA_PRECISION_INT8: return kernels::Precision::Int8;
    default:
      throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, std::string(name) + " is " + std::to_string(precision) +
                                                       ", not a softdeca_precision (0 default, 1 half, 2 float, 3 int8)");
  }
}

// Each model's precision from the desc: DEFAULT is the library's choice for that model
// (runtime::Precisions as constructed).
inline runtime::Precisions precisions_of(const softdeca_avatar_desc& desc) {
  const runtime::Precisions library;
  return {precision_of(desc.precision, library.softdeca, "desc->precision"),
          precision_of(desc.sparse_precision, library.sparse, "desc->sparse_precision")};
}

// The avatar on `mesh` (fit_api.cpp): through `fit`, its bundle and the mesh checked; without
// one, the mesh in the template's topology as the identity fit. softdeca_avatar_create's one way.
std::unique_ptr<runtime::FittedAvatar> avatar_on_mesh(const softdeca_model* model, const softdeca_avatar_mesh* mesh,
                                                      const softdeca_avatar_fit* fit, std::size_t threads,
                                                      const runtime::Precisions& precisions);

}  // namespace softdeca::api
