#include "capi/status.h"

#include <algorithm>
#include <atomic>
#include <new>
#include <stdexcept>

#include "capi/convert.h"
#include "core/error.h"

namespace planarvo::capi {
namespace {

thread_local std::string t_last_error;
std::atomic<ErrorSink> g_error_sink{nullptr};

planarvo_status to_status(ErrorCode code) {
  switch (code) {
    case ErrorCode::InvalidArgument: return PLANARVO_ERROR_INVALID_ARGUMENT;
    case ErrorCode::InvalidInput: return PLANARVO_ERROR_INVALID_INPUT;
    case ErrorCode::Io: return PLANARVO_ERROR_IO;
    case ErrorCode::NoDevice: return PLANARVO_ERROR_NO_DEVICE;
    case ErrorCode::OpenCL: return PLANARVO_ERROR_OPENCL;
    case ErrorCode::Failed: return PLANARVO_ERROR_FAILED;
    case ErrorCode::Cancelled: return PLANARVO_ERROR_CANCELLED;
    case ErrorCode::OutOfMemory: return PLANARVO_ERROR_OUT_OF_MEMORY;
    case ErrorCode::Internal: return PLANARVO_ERROR_INTERNAL;
  }
  return PLANARVO_ERROR_INTERNAL;
}

}  // namespace

void set_error_sink(ErrorSink sink) noexcept { g_error_sink.store(sink); }

planarvo_status fail(planarvo_status status, const std::string& message) {
  try {
    if (const ErrorSink sink = g_error_sink.load()) {
      sink(printable_message(message).c_str());
      return status;
    }
    t_last_error = printable_message(message);
  } catch (...) {
    // Out of memory while recording the message: keep the status, lose the text.
  }
  return status;
}

planarvo_status translate_current_exception() noexcept {
  try {
    throw;
  } catch (const Error& e) {
    return fail(to_status(e.code()), e.what());
  } catch (const BufferTooSmall& e) {
    return fail(PLANARVO_ERROR_BUFFER_TOO_SMALL, e.what());
  } catch (const std::bad_alloc&) {
    return fail(PLANARVO_ERROR_OUT_OF_MEMORY, "out of memory: an allocation failed");
  } catch (const std::exception& e) {
    return translate_foreign_exception(e);
  } catch (...) {
    return fail(PLANARVO_ERROR_INTERNAL, "internal error: unknown exception");
  }
}

void require(bool condition, const char* message) {
  if (!condition) throw Error(ErrorCode::InvalidArgument, message);
}

void require_path(const char* path, const char* fn) {
  if (path == nullptr || *path == '\0') throw Error(ErrorCode::InvalidArgument, std::string(fn) + ": path is NULL or empty");
}

void require_struct_size(size_t struct_size, size_t offset_end, const char* name) {
  if (struct_size < offset_end)
    throw Error(ErrorCode::InvalidArgument,
                std::string(name) + ".struct_size is " + std::to_string(struct_size) +
                    ": set it to sizeof(" + name + ") and initialise with the _init function");
}

}  // namespace planarvo::capi

extern "C" {

PLANARVO_API const char* planarvo_last_error(void) {
  return planarvo::capi::t_last_error.c_str();
}

PLANARVO_API const char* planarvo_status_name(planarvo_status status) {
  // A C caller may pass any int: switching on the enum itself would load an out-of-range value,
  // which is undefined in C++ (found by fuzzing, UBSan "invalid value for type").
  switch (planarvo::capi::enum_value(status)) {
    case PLANARVO_OK: return "PLANARVO_OK";
    case PLANARVO_ERROR_INVALID_ARGUMENT: return "PLANARVO_ERROR_INVALID_ARGUMENT";
    case PLANARVO_ERROR_INVALID_INPUT: return "PLANARVO_ERROR_INVALID_INPUT";
    case PLANARVO_ERROR_IO: return "PLANARVO_ERROR_IO";
    case PLANARVO_ERROR_NO_DEVICE: return "PLANARVO_ERROR_NO_DEVICE";
    case PLANARVO_ERROR_OPENCL: return "PLANARVO_ERROR_OPENCL";
    case PLANARVO_ERROR_FAILED: return "PLANARVO_ERROR_FAILED";
    case PLANARVO_ERROR_CANCELLED: return "PLANARVO_ERROR_CANCELLED";
    case PLANARVO_ERROR_BUFFER_TOO_SMALL: return "PLANARVO_ERROR_BUFFER_TOO_SMALL";
    case PLANARVO_ERROR_INTERNAL: return "PLANARVO_ERROR_INTERNAL";
    case PLANARVO_ERROR_OUT_OF_MEMORY: return "PLANARVO_ERROR_OUT_OF_MEMORY";
  }
  return "PLANARVO_ERROR_UNKNOWN";
}

}  // extern "C"
