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

// A template-topology avatar, or a user's own avatar on its fit (then `fitted` is set and
// `avatar` is null: the registered template's avatar is fitted->core()).
struct softdeca_avatar {
  std::unique_ptr<softdeca::runtime::Avatar> avatar;
  std::unique_ptr<softdeca::runtime::FittedAvatar> fitted;
};

struct softdeca_avatar_fit {
  softdeca::fit::AvatarFit fit;
  std::string bundle_sha256;
};

namespace softdeca {

inline const runtime::Model& model_of(const softdeca_model* m) {
  require_not_null(m, "model");
  return *m->model;
}

// A softdeca_precision value, checked.
inline runtime::Precision precision_of(int32_t precision, const char* name) {
  require(precision >= SOFTDECA_PRECISION_HALF && precision <= SOFTDECA_PRECISION_INT8,
          std::string(name) + " is not a softdeca_precision");
  return precision == SOFTDECA_PRECISION_FLOAT  ? runtime::Precision::Float
         : precision == SOFTDECA_PRECISION_INT8 ? runtime::Precision::Int8
                                                : runtime::Precision::Half;
}

// A user's own avatar on the fit made for `mesh` (fit_api.cpp): the fit's bundle and the mesh
// checked, then the avatar made; softdeca_avatar_create's way for a desc with a fit.
std::unique_ptr<runtime::FittedAvatar> fitted_avatar(const softdeca_model* model, const softdeca_avatar_fit* fit,
                                                     const softdeca_avatar_mesh* mesh, std::size_t threads,
                                                     runtime::Precision precision);

}  // namespace softdeca
