// The C API library's side of the vision module (see ../README.md "Two binaries").
#pragma once

namespace planarvo::capi::host {

// The vision module's function `name`, loading the module on the first call (thread-safe); or
// nullptr, with the reason recorded as the calling thread's last error.
void* vision_symbol(const char* name) noexcept;

}  // namespace planarvo::capi::host
