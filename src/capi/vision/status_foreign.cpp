// The engine's translation of its dependencies' exceptions (OpenCL's cl::Error, OpenCV's
// cv::Exception); the C API library, which has neither, has its own (host/status_foreign.cpp).
#include <string>

#include <CL/opencl.hpp>
#include <opencv2/core.hpp>

#include "capi/status.h"
#include "ocl/runtime.h"

namespace planarvo::capi {

planarvo_status translate_foreign_exception(const std::exception& e) noexcept {
  try {
    if (const auto* cl_error = dynamic_cast<const cl::Error*>(&e)) {
      const cl_int err = cl_error->err();
      const bool memory = err == CL_OUT_OF_HOST_MEMORY || err == CL_MEM_OBJECT_ALLOCATION_FAILURE;
      return fail(memory ? PLANARVO_ERROR_OUT_OF_MEMORY : PLANARVO_ERROR_OPENCL,
                  std::string(cl_error->what()) + " failed: " + ocl::error_name(err));
    }
    if (const auto* cv_error = dynamic_cast<const cv::Exception*>(&e))
      return fail(cv_error->code == cv::Error::StsNoMem ? PLANARVO_ERROR_OUT_OF_MEMORY : PLANARVO_ERROR_INTERNAL,
                  std::string("OpenCV: ") + e.what());
    return fail(PLANARVO_ERROR_INTERNAL, std::string("internal error: ") + e.what());
  } catch (...) {
    return fail(PLANARVO_ERROR_INTERNAL, "internal error");
  }
}

}  // namespace planarvo::capi
