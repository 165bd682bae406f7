// The tracker's motion model: the ground-plane homography between a reference (keyframe) and a
// live frame as a function of the robot's planar motion, and its derivatives (the paper's
// eqs. 8, 9 and 13, re-derived in docs/conventions.md's frames).
//
// Parameterisation. The estimate is T̂, the live robot pose in the reference robot frame (the
// relative motion T_r^-1 T_l of docs/conventions.md), updated by a right-multiplied se(2)
// increment:
//     H(x) = ground_homography(K, e, T̂ · exp(x)),     T̂ <- T̂ · exp(x̂)      (eqs. 8, 9)
// x = (vx, vy, omega) in SE2::exp's coordinates: metres and radians in the live robot frame.
// The camera motion of T̂ exp(x) is T_cv (T̂ exp(x))^-1 T_vc, so with P = [I; -n_c^T / z] (4x3,
// which maps a ground point X to (X, 1)) and gen_i the 4x4 generators of se(2) raised to the
// plane z = 0:
//     H(x)      ~ K top3(T_cv exp(-x) T̂^-1 T_vc) P K^-1
//     dH/dx_i   ~ K top3(T_cv (-gen_i) T̂^-1 T_vc) P K^-1                                 (eq. 13)
// both divided by H(0)(2,2) (with the quotient rule), so that H(0) equals ground_homography
// exactly and dH_i is the derivative of that normalised matrix.
//
// Planar motions compose (the ground plane is the same plane in every robot frame), so
// H(T̂ exp(x)) = H(T̂) · H(T̂ exp(x) T̂^-1) = Ĥ · Gen(x), Gen(x) = H(exp(Ad_T̂ x)): the increment
// acts on the reference side as well, in exponential coordinates linear in x. That is what ESM
// needs (its Jacobian uses the reference image's gradient at the reference pixel), and the
// reference-side generators
//     G_i = Ĥ^-1 dH_i       (∂π(G(x) p)/∂x_i = ∂π/∂h|_p G_i p, the motion field in reference pixels)
// are what the fused kernel takes (warp_reduce.h). Any other parameter of the homography enters
// the kernel the same way, as Ĥ^-1 ∂H/∂y_i: the camera's orientation to the ground (section 5.1,
// below).
//
// Orientation (section 5.1, eqs. 19-24, in docs/conventions.md's frames). The camera's tilt is
// updated by a rotation about the camera centre through the robot's x and y axes,
//     R_vc <- exp([y1, y2, 0]_x) R_vc,          t_vc unchanged                         (eq. 20)
// (the paper's R̂_cv <- R̂_cv R(ŷ) is the same update written for R_cv = R_vc^T, with R(y) acting
// on the other side). A rotation about the robot's z axis would be yaw, which planar motions
// absorb, so two generators G_x = [e_x]_x, G_y = [e_y]_x span exactly the tilts of the camera
// (the tangent space of the ground normal n_c). With A_i = [[G_i, -G_i t_vc], [0, 0]] the
// derivative of T_vc(y) = exp(y_i A_i) T_vc, the camera motion M = T_cv T̂^-1 T_vc has
//     dM/dy_i = T_cv (T̂^-1 A_i - A_i T̂^-1) T_vc                                  (eqs. 22-24)
// (eq. 24's G M T N - M T N G, with the paper's M and N absorbed into the 4x4 transforms), and
// the plane normal n_c = R_vc^T e_z moves by dn_c/dy_i = -R_vc^T G_i e_z, so
//     dH/dy_i ~ K (top3(dM_i) P + top3(M) [0; -dn_c^T / z]) K^-1.
#pragma once
#include <array>

#include <Eigen/Core>

#include "core/body_attitude.h"
#include "core/extrinsics.h"
#include "core/se2.h"
#include "core/camera.h"

namespace planarvo::track {

inline constexpr int kMotionParams = 3;       // x, y, theta of the planar motion
inline constexpr int kOrientationParams = 2;  // the camera's tilt (section 5.1)
inline constexpr int kAttitudeParams = 4;     // the local plane (section 6.4): the reference's and
                                              // the live body's roll and pitch

struct MotionHomography {
  Eigen::Matrix3d H;  // reference -> live pixels, H(2,2) = 1
  int nparam = kMotionParams;  // 3, 5 with the orientation, 7 with the attitudes (motion first)
  std::array<Eigen::Matrix3d, kMotionParams + kAttitudeParams> dH;  // ∂H/∂x_i, then ∂H/∂y_i at 0
  std::array<Eigen::Matrix3d, kMotionParams + kAttitudeParams> G;   // Ĥ^-1 dH_i: reference side
};

// H, dH and G for the motion estimate T̂ (live pose in the reference robot frame), for the
// camera matrix K of the pyramid level in use; with_orientation adds the two tilt parameters
// (eqs. 21-24). In double, analytic.
MotionHomography motion_homography(const Eigen::Matrix3d& K, const Extrinsics& extrinsics,
                                   const SE2& motion, bool with_orientation = false);

// The local plane (section 6.4; core/body_attitude.h). The camera is fixed to a body that
// rotates relative to the local ground plane about the robot's origin: the reference camera is at
// E_r = B(a_r) T_vc, the live one at E_l = B(a_l) T_vc (B = [Rx(roll) Ry(pitch) 0; 0 1]) in
// their robots' ground frames, so the camera motion is M = E_l^-1 T̂^-1 E_r and the plane's normal
// and distance are the reference camera's, n_r = R_r^T e_z and z_r = e_z^T B(a_r) t_vc:
//     H ~ K (M_R - M_t n_r^T / z_r) K^-1
// (ground_homography(K, E_r, E_l, T̂)). Its parameters: the motion x (as above), then the
// reference's and the live attitude's roll and pitch, each updated additively (a <- a + y), with
// dB/droll = [e_x]_x B and dB/dpitch = B [e_y]_x. The live attitude moves the live camera only
// (dM = T_vc^-1 dB_l^T T̂^-1 E_r); the reference's moves the reference camera and the plane
// (dM = E_l^-1 T̂^-1 dB_r T_vc, dn_r = R_vc^T dB_r^T e_z, dz_r = e_z^T dB_r t_vc). nparam 7.
MotionHomography local_plane_homography(const Eigen::Matrix3d& K, const Extrinsics& mounting, const SE2& motion,
                                        const BodyAttitude& reference, const BodyAttitude& live);

// The orientation update of eq. 20: R_vc <- exp([y1, y2, 0]_x) R_vc about the camera centre,
// returned as extrinsics (roll, pitch and yaw re-read from the rotation; yaw moves only at second
// order). Translation unchanged.
Extrinsics rotate_orientation(const Extrinsics& extrinsics, const Eigen::Vector2d& y);

// The largest displacement, in pixels of the image the camera matrix K belongs to, of the
// corners and the centre of a width x height image between the homographies of motion a and
// motion b (both live poses in the reference robot frame) : the tracker's step size measure.
double max_pixel_displacement(const Eigen::Matrix3d& K, const Extrinsics& extrinsics,
                              const SE2& a, const SE2& b, int width, int height);
// The same between the homographies of (extrinsics a, motion a) and (extrinsics b, motion b).
double max_pixel_displacement(const Eigen::Matrix3d& K, const Extrinsics& ea, const SE2& a,
                              const Extrinsics& eb, const SE2& b, int width, int height);

// The same between two homographies (reference -> live pixels).
double max_pixel_displacement(const Eigen::Matrix3d& Ha, const Eigen::Matrix3d& Hb, int width, int height);

// How much the ground's scale in the image changes under `motion` (the live pose in the
// reference's robot frame): the largest |log| of the warp's linear scale (the square root of its
// Jacobian's determinant) at the centre and the corners of `region`; HUGE_VAL where the warp
// folds or leaves the plane in front. Moving along a perspective camera's viewing direction keeps
// the overlap high while the fine texture's appearance changes (the tracker's keyframe rule).
double log_scale_change(const Eigen::Matrix3d& K, const Extrinsics& extrinsics, const SE2& motion,
                        const PixelRegion& region);

}  // namespace planarvo::track
