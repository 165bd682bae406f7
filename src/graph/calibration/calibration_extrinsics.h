// A graph calibration's (x, y, scale, yaw) as the camera's extrinsics (core/extrinsics_estimate.h):
// the one mapping from the graph's four parameters to the six, for motion pairs alone
// (`calibrate --motions`) and as the start of the whole camera calibration's composition
// (calib/extrinsics_estimate.h), and the one sentence that says how each method found them.
#pragma once
#include "core/extrinsics_estimate.h"
#include "graph/calibration/calibration.h"

namespace planarvo::graph {

// x, y, scale, yaw at x, y, z, yaw; roll and pitch 0, not estimated (they come from images). With
// metric_sensor (the pairs' sensor measured metres, e.g. a laser scan matcher) the scale is not a
// camera height: z is 0, not estimated. Covariance entries only between estimated parameters.
// No method sentence (describe_method gives the graph's), no notes.
ExtrinsicsEstimate as_extrinsics(const CalibrationResult& result, bool metric_sensor);

// How the method finds the parameters, one sentence (extrinsics.yaml's method).
const char* describe_method(CalibrationMethod method);

}  // namespace planarvo::graph
