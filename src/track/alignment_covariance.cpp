#include "track/alignment_covariance.h"

#include <algorithm>

namespace planarvo::track {

Eigen::Matrix3d alignment_covariance(const ReduceSums& s, const ReduceSums& st, int n, double floor_s2,
                                     const MatrixJ& A, const Eigen::LDLT<MatrixJ>& ldlt, double step_fraction) {
  return alignment_covariance_all(s, st, n, floor_s2, A, ldlt, step_fraction).topLeftCorner(3, 3);
}

MatrixJ alignment_covariance_all(const ReduceSums& s, const ReduceSums& st, int n, double floor_s2, const MatrixJ& A,
                                 const Eigen::LDLT<MatrixJ>& ldlt, double step_fraction) {
  // Bread: the Huber cost's Hessian, J^T J over the inliers (J^T W J also counts the pixels
  // beyond the threshold, with weight k / |r|, and would understate the spread).
  const ReduceSums& hs = s.has_stats ? s : st;
  MatrixJ B = hs.JtJ_inlier.rows() >= n ? MatrixJ(hs.JtJ_inlier.topLeftCorner(n, n)) : A;
  Eigen::LDLT<MatrixJ> bread(B);
  if (bread.info() != Eigen::Success || !(bread.vectorD().minCoeff() > 0.0)) bread.compute(A);
  const MatrixJ Binv = bread.solve(MatrixJ::Identity(n, n));
  // Meat: the scores' outer product over G clusters of neighbouring pixels, scaled by
  // G / (G - 1): the scores are taken at the fitted solution, which removes one cluster's worth
  // of their spread along any direction (E = (1 - 1/G) of the true one for alike clusters).
  // With too few clusters, the independent-pixel sigma^2 J^T W J. At least the floor's worth
  // of independent noise.
  const double dof = std::max(1.0, s.valid - n);
  MatrixJ M = s.clusters > 2.0 * n ? MatrixJ(s.score_outer.topLeftCorner(n, n) * (s.clusters / (s.clusters - 1.0)))
                                   : MatrixJ(std::max(s.wrr / dof, floor_s2) * A);
  M += std::max(0.0, floor_s2 - s.wrr / dof) * A;
  MatrixJ C = Binv * M * Binv.transpose();
  C = 0.5 * (C + C.transpose()).eval();
  // The last step, applied unchecked (or left over): the estimate is off by a fraction of it.
  const VectorJ step = -ldlt.solve(VectorJ(s.JtWr.head(n)));
  const VectorJ d = step_fraction * step;
  if (d.allFinite()) C += d * d.transpose();
  return C;
}

}  // namespace planarvo::track
