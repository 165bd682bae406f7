// Error translation for the C API: every entry point runs its body in guard(), which catches
// everything and turns it into a planarvo_status plus the calling thread's message.
#pragma once
#include <string>

#include "planarvo/planarvo.h"

namespace planarvo::capi {

// Records message as the calling thread's last error and returns status.
planarvo_status fail(planarvo_status status, const std::string& message);
// Runs the current exception through the translation table (call inside a catch block).
planarvo_status translate_current_exception() noexcept;

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
template <class T>
void require_not_null(const T* p, const char* name) {
  require(p != nullptr, name);
}
// struct_size must be at least the size of the version-1 struct, i.e. up to and including the
// last field of the first release (offset_end).
void require_struct_size(size_t struct_size, size_t offset_end, const char* name);

}  // namespace planarvo::capi
