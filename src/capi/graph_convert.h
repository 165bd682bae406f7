// The graph calibration's options and result across the C API, shared by planarvo_calibrate and
// the camera calibration (capi/vision/calibration.cpp).
#pragma once
#include "graph/calibration/calibration.h"
#include "planarvo/planarvo.h"

namespace planarvo::capi {

// The caller's options (NULL: the defaults) read as far as their struct_size reaches, validated
// (INVALID_ARGUMENT naming the field), and converted; *read receives the C struct as read (its
// log callback is for the caller). estimate_odometry_noise: the workflow's choice where the
// caller left the field at -1 (the default).
graph::CalibrationOptions calibration_options_from_c(const planarvo_calibration_options* options,
                                                     planarvo_calibration_options* read, bool estimate_odometry_noise);
planarvo_calibration_result calibration_result_to_c(const graph::CalibrationResult& result);

}  // namespace planarvo::capi
