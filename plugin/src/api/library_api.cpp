// Library-level C ABI: version, errors, status names.
#include "api/error_boundary.h"

extern "C" {

SOFTDECA_API uint32_t softdeca_abi_version(void) { return SOFTDECA_ABI_VERSION; }

SOFTDECA_API const char* softdeca_version(void) { return SOFTDECA_VERSION_STRING; }

SOFTDECA_API const char* softdeca_last_error(void) { return softdeca::api::last_error_text(); }

SOFTDECA_API const char* softdeca_status_name(softdeca_status status) {
  switch (status) {
    case SOFTDECA_OK: return "ok";
    case SOFTDECA_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case SOFTDECA_ERROR_NON_FINITE: return "non-finite input";
    case SOFTDECA_ERROR_BUFFER_TOO_SMALL: return "buffer too small";
    case SOFTDECA_ERROR_IO: return "i/o error";
    case SOFTDECA_ERROR_FORMAT: return "format error";
    case SOFTDECA_ERROR_INTERNAL: return "internal error";
    case SOFTDECA_ERROR_BUSY: return "busy";
    case SOFTDECA_ERROR_NOT_READY: return "not ready";
  }
  return "unknown status";
}

}  // extern "C"
