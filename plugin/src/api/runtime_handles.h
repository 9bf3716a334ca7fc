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

// A softdeca_precision value, checked.
inline kernels::Precision precision_of(int32_t precision, const char* name) {
  require(precision >= SOFTDECA_PRECISION_HALF && precision <= SOFTDECA_PRECISION_INT8,
          std::string(name) + " is not a softdeca_precision");
  return precision == SOFTDECA_PRECISION_FLOAT  ? kernels::Precision::Float
         : precision == SOFTDECA_PRECISION_INT8 ? kernels::Precision::Int8
                                                : kernels::Precision::Half;
}

// The avatar on `mesh` (fit_api.cpp): through `fit`, its bundle and the mesh checked; without
// one, the mesh in the template's topology as the identity fit. softdeca_avatar_create's one way.
std::unique_ptr<runtime::FittedAvatar> avatar_on_mesh(const softdeca_model* model, const softdeca_avatar_mesh* mesh,
                                                      const softdeca_avatar_fit* fit, std::size_t threads,
                                                      kernels::Precision precision);

}  // namespace softdeca::api
