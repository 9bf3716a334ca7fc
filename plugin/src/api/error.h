// Error plumbing for the C ABI: a thread-local last-error text and a guard that turns every
// C++ exception into a status, so nothing ever unwinds across the boundary.
#pragma once

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "softdeca/softdeca.h"

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

void set_last_error(const std::string& message);
void clear_last_error();
const char* last_error_text();

// Runs `body` and maps exceptions to statuses. Use in every exported function.
template <class F>
softdeca_status guarded(const char* function, F&& body) noexcept {
  try {
    clear_last_error();
    body();
    return SOFTDECA_OK;
  } catch (const Error& e) {
    set_last_error(std::string(function) + ": " + e.what());
    return e.status();
  } catch (const std::bad_alloc&) {
    set_last_error(std::string(function) + ": out of memory");
    return SOFTDECA_ERROR_INTERNAL;
  } catch (const std::exception& e) {
    set_last_error(std::string(function) + ": internal error: " + e.what());
    return SOFTDECA_ERROR_INTERNAL;
  } catch (...) {
    set_last_error(std::string(function) + ": unknown internal error");
    return SOFTDECA_ERROR_INTERNAL;
  }
}

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

// The ABI's struct rule: non-null, struct_size at least this library's sizeof (trailing fields
// of a newer caller are ignored). The message names the struct and both sizes.
template <class T>
void require_struct(const T* s, const char* name) {
  require_not_null(s, name);
  if (s->struct_size < sizeof(T))
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT, std::string(name) + "->struct_size is " + std::to_string(s->struct_size) +
                                                     ", expected sizeof = " + std::to_string(sizeof(T)) +
                                                     ": set struct_size to sizeof the struct before the call");
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
