// The camera's own planar motion, the sensor motion of the graph calibration (docs/conventions.md,
// "Sensor motions and the calibration model"; the paper's eq. 7 in this project's form
// m_r = T_vs S_h(m_s) T_vs^-1): the motion of the ground point straight below the camera, turned by
// the camera's yaw, with lengths in units of the camera's height. From a robot motion tracked with
// extrinsics e: m_s = S_{1/z}(T_vs^-1 m_r T_vs), T_vs = (e.x, e.y, e.yaw), h = e.z. So a drive
// tracked with any extrinsics gives the motions that tracking at x = y = 0, z = 1, yaw = 0 (and the
// same roll and pitch) gives, which is what calibrate --motions needs.
#pragma once
#include "core/extrinsics.h"
#include "core/motion.h"
#include "core/se2.h"

namespace planarvo {

// T_vs: the camera's ground point and yaw on the robot.
inline SE2 sensor_pose(const Extrinsics& e) { return SE2(e.x, e.y, e.yaw); }

// The sensor motion of robot_motion (tracked with e), its covariance carried along (right
// perturbations: xi_s = S_{1/z} Ad(T_vs^-1) xi). Throws InvalidArgument unless e.z > 0.
Motion sensor_motion(const Extrinsics& e, const Motion& robot_motion);

}  // namespace planarvo
