// The camera's pose on the robot, T_vc = (R_vc | t_vc), in the conventions of
// docs/conventions.md: R_vc = Rz(yaw) Ry(pitch) Rx(roll) R0, with R0 the camera looking
// straight down, image top towards the robot's front.
#pragma once
#include <cmath>
#include <string>

#include <Eigen/Core>

namespace planarvo {

struct Extrinsics {
  double x = 0.0, y = 0.0, z = 0.0;           // camera centre in the robot frame, metres
  double roll = 0.0, pitch = 0.0, yaw = 0.0;  // radians

  // All six values are finite numbers.
  bool finite() const { return std::isfinite(x + y + z + roll + pitch + yaw); }

  Eigen::Matrix3d R_vc() const;
  Eigen::Vector3d t_vc() const { return {x, y, z}; }
  Eigen::Matrix4d T_vc() const;
  // Ground-plane normal in camera coordinates, n_c = R_vc^T (0,0,1): ground points X satisfy
  // n_c^T X = -z.
  Eigen::Vector3d plane_normal_camera() const;

  // Recovers the six values from a rigid transform; throws InvalidArgument when the rotation
  // is not orthonormal.
  static Extrinsics from_matrix(const Eigen::Matrix4d& T_vc);
  // R0: camera axes in robot coordinates for roll = pitch = yaw = 0.
  static Eigen::Matrix3d R0();
};

// What a camera on a vehicle can be (docs/conventions.md, "Plausible extrinsics"): its centre at
// most kMaxOffset from the robot's origin in x and y, its height 0 < z <= kMaxHeight, each angle
// at most a turn (2 pi) in size. Values outside are most likely in the wrong unit (millimetres,
// degrees); a caller lets an unusual rig through with its option (accept_unusual_extrinsics in the
// C API, --force in the tool).
inline constexpr double kMaxOffset = 20.0;  // metres
inline constexpr double kMaxHeight = 5.0;   // metres
// "" when e is plausible, else which value is not and the unit mistake that likely made it, e.g.
// "z = 178.7 m is over 5 m: millimetres by mistake? (178.7 mm = 0.1787 m)". With height_given
// false a z of 0 is "not given" and passes.
std::string implausible_extrinsics(const Extrinsics& e, bool height_given = true);
// Throws InvalidArgument "<what>: <why> (angles are radians, lengths metres; for an unusual rig set
// accept_unusual_extrinsics, --force in the planarvo tool)" when e is not plausible.
void check_plausible_extrinsics(const Extrinsics& e, const std::string& what, bool height_given = true);
// The same for a camera height alone (a height given by hand).
void check_plausible_height(double z, const std::string& what);

// The homography mapping undistorted reference pixels to undistorted live pixels on the ground
// plane, for the robot's relative motion T_k^-1 T_{k+1} = motion (docs/conventions.md, "The
// homography between two frames"; the paper's eq. 3). K is the 3x3 camera matrix.
Eigen::Matrix3d ground_homography(const Eigen::Matrix3d& K, const Extrinsics& e,
                                  const Eigen::Matrix4d& robot_motion);
// The same between two cameras with their own poses relative to the ground plane (a body that
// leans: core/body_attitude.h): the reference camera at e_ref in the reference robot's ground
// frame, the live camera at e_live in the live robot's, the live robot at robot_motion in the
// reference's. The plane's normal and distance are the reference camera's. Equals the one above
// when e_ref and e_live are the same.
Eigen::Matrix3d ground_homography(const Eigen::Matrix3d& K, const Extrinsics& e_ref, const Extrinsics& e_live,
                                  const Eigen::Matrix4d& robot_motion);

}  // namespace planarvo
