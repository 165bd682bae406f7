// The camera's 6-DoF extrinsics from the two stages of the paper's calibration: roll and pitch
// from images (section 5.1, track/roll_pitch.h) and x, y, height and yaw from the graph
// (section 5.2, graph/calibration/calibration.h), with a 6x6 covariance and, per parameter, whether it was
// estimated and whether the data determine it.
//
// Why they compose: the tracker run at x = y = 0, z = 1, yaw = 0 with the estimated tilt measures
// the planar motion of the camera's ground frame s (on the ground below the camera, yaw of the
// camera) in units of the height. With T_vs = (x, y, yaw) on the ground and T_sc = (Ry(pitch)
// Rx(roll) R0 | (0, 0, z)), T_vs T_sc = (Rz(yaw) Ry(pitch) Rx(roll) R0 | (x, y, z)) is exactly
// docs/conventions.md's T_vc, and the graph's m_r = T_vs S_z(m_s) T_vs^-1 estimates (x, y, z, yaw).
// The graph's motions were tracked with stage 1's tilt, so its error moves them all alike: given
// J = d(x, y, scale, yaw) / d(roll, pitch) (calib/tilt_propagation.h), the graph's block gets
// J C_rp J^T more and the cross-covariance with roll and pitch is J C_rp; without it the stages
// are taken as independent.
#pragma once
#include <string>

#include <Eigen/Core>

#include "core/extrinsics.h"
#include "core/extrinsics_estimate.h"
#include "graph/calibration/calibration.h"
#include "track/roll_pitch.h"

namespace planarvo::calib {

// The tracker's extrinsics in stage 2 (eq. 14): the camera's tilt, at the robot's origin, one
// unit above the ground, no yaw; its motions are the camera's ground frame's in units of height.
inline Extrinsics stage2_extrinsics(double roll, double pitch) { return Extrinsics{0.0, 0.0, 1.0, roll, pitch, 0.0}; }

// The graph's (x, y, scale, yaw) as x, y, z, yaw (graph::as_extrinsics); its fixed scale (a height given by hand) as z,
// not estimated. Roll and pitch as given, estimated when `roll_pitch_estimated`.
ExtrinsicsEstimate compose_extrinsics(double roll, double pitch, const Eigen::Matrix2d& roll_pitch_covariance,
                                      bool roll_pitch_estimated, const graph::CalibrationResult& graph,
                                      const Eigen::Matrix<double, 4, 2>* tilt_jacobian = nullptr);

// How the whole calibration (calib/pipeline.h) finds the extrinsics with the graph's method, one
// sentence (extrinsics.yaml's method). labels_from_odometry: the nonholonomic method's direction
// labels came from the odometry's forward motion (graph::CalibrationOptions::still_speed), the
// drive having no labels of its own.
std::string describe_camera_calibration(graph::CalibrationMethod method, bool labels_from_odometry = false);

}  // namespace planarvo::calib
