#include "core/extrinsics_estimate.h"

namespace planarvo {

int extrinsics_index(std::string_view name) {
  for (size_t i = 0; i < kExtrinsicsNames.size(); ++i)
    if (name == kExtrinsicsNames[i]) return static_cast<int>(i);
  return -1;
}

}  // namespace planarvo
