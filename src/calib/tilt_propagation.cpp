#include "calib/tilt_propagation.h"

#include <array>
#include <cmath>

namespace planarvo::calib {

std::optional<Eigen::Matrix<double, 4, 2>> graph_tilt_jacobian(
    const std::vector<graph::MotionSample>& samples, const std::vector<Eigen::Matrix<double, 3, 2>>& tilt_jacobians,
    const graph::CalibrationOptions& options, const graph::CalibrationResult& result, double step) {
  if (tilt_jacobians.size() != samples.size()) return std::nullopt;
  // A solve that ended at a scale of 0 or less (a wrong tilt's motions can take it there) is no
  // start for the graph: nothing to propagate (the result is not ok either).
  if (!options.fix_scale && options.method == graph::CalibrationMethod::Odometry && !(result.value[2] > 0.0))
    return std::nullopt;
  graph::CalibrationOptions o = options;
  o.initial = result.value;
  std::vector<bool> outlier(samples.size(), false);
  for (int i : result.outlier_samples)
    if (i >= 0 && static_cast<size_t>(i) < samples.size()) outlier[static_cast<size_t>(i)] = true;
  Eigen::Matrix<double, 4, 2> J = Eigen::Matrix<double, 4, 2>::Zero();
  for (int c = 0; c < 2; ++c) {
    std::array<Eigen::Vector4d, 2> value;
    for (int s = 0; s < 2; ++s) {
      const double delta = s == 0 ? step : -step;
      std::vector<graph::MotionSample> moved;
      moved.reserve(samples.size());
      for (size_t i = 0; i < samples.size(); ++i) {
        if (outlier[i]) continue;
        graph::MotionSample m = samples[i];
        m.sensor.value = m.sensor.value * SE2::exp(delta * tilt_jacobians[i].col(c));
        moved.push_back(m);
      }
      const graph::CalibrationResult g = graph::calibrate(moved, o);
      if (!g.summary.converged()) return std::nullopt;
      value[static_cast<size_t>(s)] = Eigen::Vector4d(g.value[0], g.value[1], g.value[2], g.value[3]);
    }
    Eigen::Vector4d d = (value[0] - value[1]) / (2.0 * step);
    d(3) = std::remainder(value[0](3) - value[1](3), 2.0 * M_PI) / (2.0 * step);
    for (int p = 0; p < 4; ++p)
      if (!result.estimated[static_cast<size_t>(p)]) d(p) = 0.0;
    J.col(c) = d;
  }
  return J;
}

}  // namespace planarvo::calib
