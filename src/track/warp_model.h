// The tracker's motion model: the ground-plane homography between a reference (keyframe) and a
// live frame as a function of the robot's planar motion, and its derivatives (the paper's
// eqs. 8, 9 and 13, re-derived in shared/spec/conventions.md's frames).
//
// Parameterisation. The estimate is T̂, the live robot pose in the reference robot frame (the
// relative motion T_r^-1 T_l of conventions.md), updated by a right-multiplied se(2) increment:
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
// are what the fused kernel takes (warp_reduce.h). Any other parameter of the homography (the
// camera's roll and pitch, section 5.1) enters the kernel the same way, as Ĥ^-1 ∂H/∂y_i.
#pragma once
#include <array>

#include <Eigen/Core>

#include "core/extrinsics.h"
#include "core/se2.h"

namespace planarvo::track {

struct MotionHomography {
  Eigen::Matrix3d H;                 // reference -> live pixels, H(2,2) = 1
  std::array<Eigen::Matrix3d, 3> dH;  // ∂H/∂x_i at x = 0
  std::array<Eigen::Matrix3d, 3> G;   // Ĥ^-1 dH_i: reference-side generators
};

// H, dH and G for the motion estimate T̂ (live pose in the reference robot frame), for the
// camera matrix K of the pyramid level in use. In double, analytic.
MotionHomography motion_homography(const Eigen::Matrix3d& K, const Extrinsics& extrinsics,
                                   const SE2& motion);

// The largest displacement, in pixels of the image the camera matrix K belongs to, of the
// corners and the centre of a width x height image between the homographies of motion a and
// motion b (both live poses in the reference robot frame) : the tracker's step size measure.
double max_pixel_displacement(const Eigen::Matrix3d& K, const Extrinsics& extrinsics,
                              const SE2& a, const SE2& b, int width, int height);

}  // namespace planarvo::track
