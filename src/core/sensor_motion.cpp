#include "core/sensor_motion.h"

#include <string>

#include "core/error.h"

namespace planarvo {

Motion sensor_motion(const Extrinsics& e, const Motion& robot_motion) {
  if (!(e.z > 0) || !e.finite())
    throw_invalid_argument("sensor_motion: the extrinsics' height must be positive and every value finite (z = " +
                           std::to_string(e.z) + ")");
  const SE2 T = sensor_pose(e);
  const SE2 m = T.inverse() * robot_motion.value * T;
  Motion out;
  out.value = SE2(m.x / e.z, m.y / e.z, m.theta);
  const Eigen::Matrix3d S = Eigen::Vector3d(1.0 / e.z, 1.0 / e.z, 1.0).asDiagonal();
  const Eigen::Matrix3d A = S * T.inverse().adjoint();
  out.covariance = A * robot_motion.covariance * A.transpose();
  return out;
}

}  // namespace planarvo
