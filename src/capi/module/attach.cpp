// The vision module's entry point (attach.h).
#include "capi/module/attach.h"

#include "planarvo/planarvo.h"

extern "C" PLANARVO_API int planarvo_vision_attach(int version, planarvo::capi::ErrorSink sink) {
  if (version != PLANARVO_VERSION_NUMBER || sink == nullptr) return 1;
  planarvo::capi::set_error_sink(sink);
  return 0;
}
