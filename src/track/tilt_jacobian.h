// How an alignment's motion moves with the camera's tilt (FrameResult::motion_tilt_jacobian, for
// the calibration's calib/tilt_propagation.h): d pose / d (roll, pitch) of a converged alignment.
//
// At the alignment's optimum the gradient in its local parameters (motion, brightness) is zero
// for every tilt, so by the implicit function theorem d local / d y = -A_ll^-1 A_ly, A the J^T W J
// of one pass with the tilt y as two more parameters (the roll/pitch estimator's NPARAM 5 pass,
// warp_model.h's rotation about the camera centre), at the estimate, at half resolution. A change
// of roll or pitch turns the camera about an axis with a vertical part too (roll turns about the
// pitched x axis): its horizontal part is y; its vertical part turns the camera's ground frame,
// which the pose is expressed in. Checked against the tracker run with the tilt off
// (test/e2e/tilt_propagation_test.cpp).
#pragma once
#include <Eigen/Core>

#include "core/extrinsics.h"
#include "core/se2.h"
#include "image/pyramid.h"
#include "track/warp_reduce.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::track {

class TiltJacobian {
 public:
  // kernel: the tracker's pass options (the STATS, debug and selection variants are not used).
  TiltJacobian(ocl::Runtime& runtime, const WarpReduceOptions& kernel);

  // d motion / d (roll, pitch) in motion's right perturbation, per radian: `motion` (the live
  // pose in the reference's robot frame) aligned from `reference` to `live` with extrinsics e,
  // brightness (log_gain, bias; with_brightness: estimated) and Huber threshold huber_k; K the
  // camera matrix of level 0. Zero when the system is singular.
  Eigen::Matrix<double, 3, 2> operator()(const Pyramid& reference, const Pyramid& live, const Eigen::Matrix3d& K,
                                         const Extrinsics& e, const SE2& motion, double log_gain, double bias,
                                         double huber_k, bool with_brightness);

 private:
  WarpReduce pass_;
};

}  // namespace planarvo::track
