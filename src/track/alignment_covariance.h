// The covariance of a tracked alignment (src/track/README.md, "The tracker"; its measured NEES: test/bench/results/track.md): the M-estimator's
// sandwich from the fused pass's sums, with the scores clustered over neighbouring pixels, plus
// the part of the last, unchecked Gauss-Newton step the estimate is still off by.
#pragma once
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "track/warp_reduce.h"

namespace planarvo::track {

// The motion's 3x3 covariance from the finest level's sums: s is the last pass at the estimate, st
// the STATS pass that opened the level (the same pass when the level took one). n = 3 or 5
// parameters, brightness marginalised by taking the motion block; A = s's J^T W J (n x n) and
// ldlt its factorisation; step_fraction TrackerOptions::covariance_step_fraction.
Eigen::Matrix3d alignment_covariance(const ReduceSums& s, const ReduceSums& st, int n, double floor_s2,
                                     const MatrixJ& A, const Eigen::LDLT<MatrixJ>& ldlt, double step_fraction);
// The same over all n parameters (n x n; the motion's is its top-left 3 x 3): the local plane's
// attitudes (AlignerModel::LocalPlane) take their covariance from it.
MatrixJ alignment_covariance_all(const ReduceSums& s, const ReduceSums& st, int n, double floor_s2, const MatrixJ& A,
                                 const Eigen::LDLT<MatrixJ>& ldlt, double step_fraction);

}  // namespace planarvo::track
