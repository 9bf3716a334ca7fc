// The C ABI's opaque handles: made whole before the caller sees them, destroyed behind the
// exception barrier. Every *_create / *_open / *_load hands out through create_handle and every
// *_destroy goes through destroy_handle.
#pragma once

#include <memory>

#include "api/error_boundary.h"

namespace softdeca::api {

// A new Handle filled by `fill` (which may throw: then nothing is handed out and *out is left
// as it was), released into *out.
template <class Handle, class Fill>
void create_handle(Handle** out, const char* out_name, Fill&& fill) {
  require_not_null(out, out_name);
  auto handle = std::make_unique<Handle>();
  fill(*handle);
  *out = handle.release();
}

// Deletes a handle (null is a no-op); a destructor's exception becomes the last error.
template <class Handle>
void destroy_handle(const char* function, Handle* handle) noexcept {
  guarded(function, [&] { delete handle; });
}

}  // namespace softdeca::api
