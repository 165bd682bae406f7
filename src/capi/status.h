// Error translation for the C API: every entry point runs its body in guard(), which catches
// everything and turns it into a planarvo_status plus the calling thread's message.
#pragma once
#include <exception>
#include <stdexcept>
#include <string>

#include "planarvo/planarvo.h"

namespace planarvo::capi {

// A caller's output array too small for the result (PLANARVO_ERROR_BUFFER_TOO_SMALL).
struct BufferTooSmall : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Records message as the calling thread's last error and returns status.
planarvo_status fail(planarvo_status status, const std::string& message);
// Runs the current exception through the translation table (call inside a catch block).
planarvo_status translate_current_exception() noexcept;
// The status and message for an exception of a dependency (OpenCL, OpenCV): defined once per
// binary, by capi/vision/status_foreign.cpp in the engine and capi/host/status_foreign.cpp in the
// C API library, which has neither dependency (see README.md, "Two binaries").
planarvo_status translate_foreign_exception(const std::exception& e) noexcept;

// Where this binary's messages go: the engine module sends them to the C API library's
// thread-local slot, so that planarvo_last_error() sees them (nullptr: this binary's own slot).
using ErrorSink = void (*)(const char* message);
void set_error_sink(ErrorSink sink) noexcept;

template <class F>
planarvo_status guard(F&& body) noexcept {
  try {
    body();
    return PLANARVO_OK;
  } catch (...) {
    return translate_current_exception();
  }
}

// Argument checks that throw Error(InvalidArgument) naming the argument.
void require(bool condition, const char* message);
// "fn: path is NULL or empty" unless path is a non-empty string.
void require_path(const char* path, const char* fn);
template <class T>
void require_not_null(const T* p, const char* name) {
  require(p != nullptr, name);
}
// struct_size must be at least the size of the version-1 struct, i.e. up to and including the
// last field of the first release (offset_end).
void require_struct_size(size_t struct_size, size_t offset_end, const char* name);

}  // namespace planarvo::capi
