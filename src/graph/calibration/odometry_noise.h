// The wheel odometry's noise estimated from a calibration's own residuals. The default noise model
// of graph/calibration.h is isotropic in translation, but a differential drive's odometry errs
// along its travel (wheel travel) and in heading, and hardly sideways: with the isotropic model
// the calibration's yaw and position uncertainties come out several times too large (measured:
// yaw 60x on the simulator's 2 %-per-wheel odometry, src/calib/README.md). When the sensor is far
// more precise than the odometry (a camera tracked at micrometres), the residual of each interval
// is the odometry's error, so its variance model can be fitted from them:
//     sigma_c^2 = constant_c + per_translation_c |t|^2 + per_rotation_c theta^2,   c = x, y, theta
// in the frame at the interval's end (the right perturbation of the odometry motion), by least
// squares on the squared residuals with non-negative coefficients.
#pragma once
#include <vector>

#include <Eigen/Core>

#include "core/se2.h"

namespace planarvo::graph {

struct OdometryNoiseModel {
  Eigen::Vector3d constant = Eigen::Vector3d::Zero();         // variances: m^2, m^2, rad^2
  Eigen::Vector3d per_translation = Eigen::Vector3d::Zero();  // per m^2 of travel
  Eigen::Vector3d per_rotation = Eigen::Vector3d::Zero();     // per rad^2 of turn
  // Floors so that an interval standing still is not taken as exact.
  double floor_translation = 1e-6, floor_rotation = 1e-6;     // m, rad

  // Covariance of the right perturbation of motion m (diagonal).
  Eigen::Matrix3d covariance(const SE2& m) const;
};

// odometry[i]: the odometry's motion over interval i; residual[i]: the right perturbation that
// takes it to the sensor's motion mapped into the robot frame (t2v(odometry^-1 * mapped)), for the
// inlier intervals only. Needs at least 10 intervals (else the zero model, floors only).
OdometryNoiseModel fit_odometry_noise(const std::vector<SE2>& odometry, const std::vector<Eigen::Vector3d>& residual);

}  // namespace planarvo::graph
