// C API: the names of the extrinsics' parameters (core/extrinsics_estimate.h), in the base library.
#include "core/extrinsics_estimate.h"
#include "planarvo/planarvo.h"

extern "C" {
PLANARVO_API const char* planarvo_extrinsics_name(int32_t index) {
  return index >= 0 && index < 6 ? planarvo::kExtrinsicsNames[static_cast<size_t>(index)] : nullptr;
}
}
