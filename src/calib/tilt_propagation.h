// The tilt's uncertainty carried into x, y, height and yaw (the two stages' cross-covariance).
//
// Stage 2 tracks with the tilt stage 1 estimated, so a tilt error is the same in every tracked
// motion: the tracker fits the image's motion with a plane tilted by that error, and every motion
// moves with it. That does not average out over the drive, and the graph's covariance (which sees
// only the motions' own noise) leaves it out. A tilt error turns the tracked motions' directions
// and changes their rotations (configuration 2, a pitch error of 1 mrad: directions turned by 0.1
// mrad, each motion's rotation changed by 0.03 mrad), so the yaw moves with it, and so do x and
// y, which the nonholonomic method takes from the motions' directions. This is the two-step estimator's correction (Murphy and Topel,
// 1985): with J = d(x, y, scale, yaw) / d(roll, pitch) through stages 2 and 3, the graph's
// parameters get J C_rp J^T more, and J C_rp is their cross-covariance with the tilt.
//
// Each motion's own derivative comes from the tracker (TrackerOptions::tilt_jacobian: the implicit
// function theorem on its alignment's normal equations, with the tilt as two more parameters), so
// it weighs the image as the alignment does (texture, valid region, robust weights); a geometric
// fit of the tilted plane's homography over the image mispredicted the turn of the directions
// (the wrong sign for roll on configuration 2), and the change of the measured tracks fitted as
// linear in the motion could not be determined from stage 1's frames (one direction of motion). J then
// comes from calibrating the graph again with every motion moved along its derivative.
#pragma once
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "graph/calibration/calibration.h"

namespace planarvo::calib {

// J = d(x, y, scale, yaw) / d(roll, pitch) of the graph calibration at `result` (calibrated from
// `samples` with `options`), by central differences of step radians with every sample's motion m
// moved to m exp(G delta), G its tilt Jacobian (`tilt_jacobians`, one per sample); the samples the
// calibration gated out are left out, and the solves start from `result`. nullopt when a moved
// calibration does not converge or the sizes differ. Rows of parameters the graph did not
// estimate are zero.
std::optional<Eigen::Matrix<double, 4, 2>> graph_tilt_jacobian(
    const std::vector<graph::MotionSample>& samples, const std::vector<Eigen::Matrix<double, 3, 2>>& tilt_jacobians,
    const graph::CalibrationOptions& options, const graph::CalibrationResult& result, double step = 1e-3);

}  // namespace planarvo::calib
