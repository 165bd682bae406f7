// The C API library's translation of exceptions from outside the project: it links neither
// OpenCL nor OpenCV (their exceptions arise only in the engine module, which translates them),
// so anything else is an internal error.
#include <string>

#include "capi/status.h"

namespace planarvo::capi {

planarvo_status translate_foreign_exception(const std::exception& e) noexcept {
  try {
    return fail(PLANARVO_ERROR_INTERNAL, std::string("internal error: ") + e.what());
  } catch (...) {
    return fail(PLANARVO_ERROR_INTERNAL, "internal error");
  }
}

}  // namespace planarvo::capi
