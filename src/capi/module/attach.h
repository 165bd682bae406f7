// The vision module's entry point, which the C API library calls once after loading it (see
// ../README.md, "Two binaries"): its version, and the function that records an error as the
// calling thread's planarvo_last_error(). Returns 0 when the module accepts them.
#pragma once
#include "capi/status.h"

extern "C" int planarvo_vision_attach(int version, planarvo::capi::ErrorSink sink);
