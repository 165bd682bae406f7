// A motion pair's residual at a calibration's estimate, as the odometry method weighs it: the
// robot's motion between the two poses is free in the graph and tied to the odometry's motion W
// (factor eq. 25) and to the sensor's motion mapped into the robot frame, M = T S_h(m) T^-1
// (factor eq. 26, weighted as G e with the sensor's information). Both errors are linear in the
// free motion's coordinates, so it is eliminated exactly: the pair's χ² is dᵀ S⁻¹ d with
// d = coords(W) − coords(M) (angle wrapped) and S = S_o + K S_s Kᵀ, S_s the sensor's covariance
// carried into the robot frame (K = R G⁻¹ Rᵀ, R the rotation of M's angle). Summed over the pairs
// this is the solver's χ² at its optimum for that z.
#pragma once
#include <Eigen/Core>

#include "core/se2.h"

namespace planarvo::graph {

struct PairResidual {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();  // m, m, rad: robot frame at the interval's start
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double chi2 = 0.0;
};

// z = (x, y, scale, yaw); odometry_cov and sensor_cov: the covariances of the motions' own (x, y,
// θ) as the calibration took them (component covariances, calibration.h).
PairResidual pair_residual(const SE2& odometry, const SE2& sensor, const Eigen::Matrix3d& odometry_cov,
                           const Eigen::Matrix3d& sensor_cov, const Eigen::Vector4d& z);

}  // namespace planarvo::graph
