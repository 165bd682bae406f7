#include "calib/extrinsics_estimate.h"

namespace planarvo::calib {

ExtrinsicsEstimate compose_extrinsics(double roll, double pitch, const Eigen::Matrix2d& rp_cov, bool rp_estimated,
                                      const graph::CalibrationResult& g, const Eigen::Matrix<double, 4, 2>* J) {
  ExtrinsicsEstimate out;
  out.value = Extrinsics{g.value[0], g.value[1], g.value[2], roll, pitch, g.value[3]};
  // The graph's parameters x, y, scale, yaw sit at x, y, z, yaw.
  constexpr std::array<int, 4> at = {0, 1, 2, 5};
  for (size_t i = 0; i < 4; ++i) {
    out.estimated[static_cast<size_t>(at[i])] = g.estimated[i];
    out.observable[static_cast<size_t>(at[i])] = g.observable[i];
    for (size_t j = 0; j < 4; ++j)
      if (g.estimated[i] && g.estimated[j])
        out.covariance(at[i], at[j]) = g.covariance(static_cast<int>(i), static_cast<int>(j));
  }
  if (rp_estimated) {
    out.covariance.block<2, 2>(3, 3) = rp_cov;
    out.estimated[3] = out.estimated[4] = true;
    out.observable[3] = out.observable[4] = true;
    if (J && J->allFinite()) {
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

}  // namespace planarvo::calib
