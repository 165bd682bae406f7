// The body's rotation relative to the local ground plane (the paper's section 6.4): a car's body
// rolls in turns and pitches over bumps on its suspension, and the camera fixed to it turns with
// it. R_plane_body = Rx(roll) Ry(pitch) (body x forward, y left, z up), the body rotating about
// the robot frame's origin on the ground (docs/conventions.md, "The body's attitude"). A rigid
// robot's body stays at 0, 0: the camera's extrinsics are then its pose relative to the ground.
#pragma once
#include <Eigen/Core>

#include "core/extrinsics.h"

namespace planarvo {

struct BodyAttitude {
  double roll = 0.0, pitch = 0.0;  // radians

  bool zero() const { return roll == 0.0 && pitch == 0.0; }
  Eigen::Matrix3d R_plane_body() const;
};

// The camera relative to the local ground plane when the body carrying it is at attitude a:
// T = [R_plane_body 0; 0 1] T_vc of the mounting. The mounting exactly when a is zero.
Extrinsics on_plane(const Extrinsics& mounting, const BodyAttitude& a);

// The roll and pitch of R = Rz(yaw) Rx(roll) Ry(pitch): the attitude that puts the plane's normal
// where R does (a yaw about the normal changes no view of the plane).
BodyAttitude attitude_of(const Eigen::Matrix3d& R);

// A mounting knocked: the camera turned about its own centre by the rotation `step` expressed in
// the body's axes, so that a body at attitude `step` with the old mounting sees the ground as a
// body at rest does with the new one (the same orientation; the camera's centre, its height
// included, kept), and by `yaw` about the body's vertical. T = [Rz(yaw) R(step) R_vc | t_vc].
Extrinsics turned_mounting(const Extrinsics& mounting, const BodyAttitude& step, double yaw = 0.0);

// An attitude measured against a mounting, re-expressed against that mounting turned by `step`
// and `yaw` (turned_mounting): R(a') = R(a) R(step)^T Rz(yaw)^T, its roll and pitch.
BodyAttitude relative_to_turned(const BodyAttitude& a, const BodyAttitude& step, double yaw = 0.0);

}  // namespace planarvo
