// The library's error type and the checks that raise it, used by every area. An Error carries
// the status the C ABI returns for it; api/error_boundary.h turns it into that status at the boundary.
// The library has no logging of its own: failures travel as Errors to the caller.
#pragma once

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "softdeca/softdeca.h"  // softdeca_status only

namespace softdeca {

// Thrown inside the library; carries the status the C ABI returns.
class Error : public std::runtime_error {
 public:
  Error(softdeca_status status, const std::string& message)
      : std::runtime_error(message), status_(status) {}
  softdeca_status status() const { return status_; }

 private:
  softdeca_status status_;
};

inline void require(bool condition, const std::string& message,
                    softdeca_status status = SOFTDECA_ERROR_INVALID_ARGUMENT) {
  if (!condition) throw Error(status, message);
}

// A literal message: no string is built unless the check fails (checks on per-frame paths).
inline void require(bool condition, const char* message,
                    softdeca_status status = SOFTDECA_ERROR_INVALID_ARGUMENT) {
  if (!condition) throw Error(status, message);
}

inline void require_not_null(const void* p, const char* name) {
  if (p == nullptr) throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, std::string(name) + " is null");
}

// For per-frame paths: the message (a callable returning it) is built only on failure, so a
// passing check allocates nothing.
template <class Message>
inline void expect(bool condition, Message&& message, softdeca_status status = SOFTDECA_ERROR_INVALID_ARGUMENT) {
  if (!condition) throw Error(status, message());
}

// Rejects NaN and infinity; `name` appears in the message with the first bad index.
inline void require_finite(const float* values, std::size_t count, const char* name) {
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i]))
      throw Error(SOFTDECA_ERROR_NON_FINITE,
                  std::string(name) + "[" + std::to_string(i) + "] is not finite");
}

}  // namespace softdeca
