#include "api/error_boundary.h"

namespace softdeca::api {
namespace {
// Thread-local (the C ABI convention of softdeca.h): each host thread sees its own last failure.
std::string& last_error_slot() {
  thread_local std::string text;
  return text;
}
}  // namespace

void set_last_error(const std::string& message) { last_error_slot() = message; }
void clear_last_error() { last_error_slot().clear(); }
const char* last_error_text() { return last_error_slot().c_str(); }

}  // namespace softdeca::api
