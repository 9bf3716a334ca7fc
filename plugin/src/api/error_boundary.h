// Error plumbing for the C ABI: a thread-local last-error text, a guard that turns every
// C++ exception into a status, so nothing ever unwinds across the boundary, and the ABI's rule
// for structs. The Error type itself is core/error.h, which every area below the ABI includes.
#pragma once

#include <exception>
#include <new>
#include <string>

#include "core/error.h"
#include "softdeca/softdeca.h"

namespace softdeca::api {

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

// A struct the library fills for its caller (after require_struct): every field reset to its
// zero default but struct_size, which keeps the caller's value, the size it was built with.
template <class T>
void reset_struct(T* s) {
  const uint32_t struct_size = s->struct_size;
  *s = T{};
  s->struct_size = struct_size;
}

}  // namespace softdeca::api
