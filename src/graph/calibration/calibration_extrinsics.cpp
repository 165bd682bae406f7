#include "graph/calibration/calibration_extrinsics.h"

namespace planarvo::graph {

ExtrinsicsEstimate as_extrinsics(const CalibrationResult& g, bool metric_sensor) {
  ExtrinsicsEstimate out;
  out.value = Extrinsics{g.value[0], g.value[1], metric_sensor ? 0.0 : g.value[2], 0.0, 0.0, g.value[3]};
  // The graph's parameters x, y, scale, yaw sit at x, y, z, yaw.
  constexpr std::array<int, 4> at = {0, 1, 2, 5};
  std::array<bool, 4> kept = g.estimated;
  if (metric_sensor) kept[2] = false;
  for (size_t i = 0; i < 4; ++i) {
    out.estimated[static_cast<size_t>(at[i])] = kept[i];
    out.observable[static_cast<size_t>(at[i])] = kept[i] && g.observable[i];
    for (size_t j = 0; j < 4; ++j)
      if (kept[i] && kept[j]) out.covariance(at[i], at[j]) = g.covariance(static_cast<int>(i), static_cast<int>(j));
  }
  return out;
}

const char* describe_method(CalibrationMethod method) {
  return method == CalibrationMethod::Odometry ? "graph calibration against wheel odometry"
                                                : "nonholonomic graph calibration";
}

}  // namespace planarvo::graph
