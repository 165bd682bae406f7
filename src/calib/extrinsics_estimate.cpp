#include "calib/extrinsics_estimate.h"

#include "graph/calibration/calibration_extrinsics.h"

namespace planarvo::calib {

ExtrinsicsEstimate compose_extrinsics(double roll, double pitch, const Eigen::Matrix2d& rp_cov, bool rp_estimated,
                                      const graph::CalibrationResult& g, const Eigen::Matrix<double, 4, 2>* J) {
  ExtrinsicsEstimate out = graph::as_extrinsics(g, false);
  out.value.roll = roll;
  out.value.pitch = pitch;
  if (rp_estimated) {
    out.covariance.block<2, 2>(3, 3) = rp_cov;
    out.estimated[3] = out.estimated[4] = true;
    out.observable[3] = out.observable[4] = true;
    if (J && J->allFinite()) {
      // The graph's parameters x, y, scale, yaw sit at x, y, z, yaw.
      constexpr std::array<int, 4> at = {0, 1, 2, 5};
      const Eigen::Matrix4d added = *J * rp_cov * J->transpose();
      const Eigen::Matrix<double, 4, 2> cross = *J * rp_cov;
      for (size_t i = 0; i < 4; ++i) {
        if (!g.estimated[i]) continue;
        for (size_t j = 0; j < 4; ++j)
          if (g.estimated[j]) out.covariance(at[i], at[j]) += added(static_cast<int>(i), static_cast<int>(j));
        for (int k = 0; k < 2; ++k) {
          out.covariance(at[i], 3 + k) = cross(static_cast<int>(i), k);
          out.covariance(3 + k, at[i]) = cross(static_cast<int>(i), k);
        }
      }
    }
  }
  return out;
}

std::string describe_camera_calibration(graph::CalibrationMethod method, bool labels_from_odometry) {
  if (method == graph::CalibrationMethod::Odometry)
    return "roll and pitch from images (sec. 5.1); x, y, z, yaw against wheel odometry (5.2.1)";
  return labels_from_odometry ? "roll and pitch from images (sec. 5.1); x, yaw nonholonomic, y from direction labels "
                                "taken from the sign of the wheel odometry (5.2.2), z given"
                              : "roll and pitch from images (sec. 5.1); x, yaw nonholonomic, y from direction labels "
                                "(5.2.2), z given";
}

}  // namespace planarvo::calib
