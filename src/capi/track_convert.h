// The tracker's options and frames across the C API, shared by the tracker's calls and the
// calibration's (capi/vision/calibration.cpp).
#pragma once
#include <cstddef>
#include <cstdint>

#include <opencv2/core.hpp>

#include "planarvo/planarvo.h"
#include "track/tracker.h"

namespace planarvo::capi {

// The caller's options (NULL: the defaults), validated (INVALID_ARGUMENT naming the field).
track::TrackerOptions tracker_options_from_c(const planarvo_tracker_options* options);
// The frame as 8-bit grey: a view of the caller's memory when it already is, else converted into
// buffer. *stride receives the grey image's row stride. The image must have been checked for
// data, size and format; its stride is checked here (InvalidArgument naming `function`), before
// OpenCV sees it.
const uint8_t* grey_view(const planarvo_image& image, cv::Mat& buffer, size_t* stride, const char* function);

}  // namespace planarvo::capi
