// The aligner's joint solve (track/aligner.h: each pair's block eliminated onto the shared tilt,
// then back-substitution) against a dense solve of the whole assembled system, and the tilt's
// information against the inverse of the dense covariance's tilt block.
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "track/aligner.h"

namespace planarvo::track {
namespace {

// A random positive definite pair block in the pass's order (motion 3, tilt 2, brightness 2).
ReduceSums random_pair(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Eigen::MatrixXd J(40, 7);
  for (int i = 0; i < J.rows(); ++i)
    for (int j = 0; j < 7; ++j) J(i, j) = n(rng) * (j < 3 ? 100.0 : j < 5 ? 30.0 : 1.0);
  Eigen::VectorXd r(40);
  for (int i = 0; i < 40; ++i) r(i) = n(rng);
  ReduceSums s;
  s.JtWJ = J.transpose() * J;
  s.JtWr = J.transpose() * r;
  return s;
}

TEST(AlignerJointSolve, EqualsTheDenseSolveOfTheWholeSystem) {
  std::mt19937 rng(9);
  for (const double lambda : {0.0, 1e-3, 0.5}) {
    const int P = 4;
    std::vector<ReduceSums> sums;
    for (int p = 0; p < P; ++p) sums.push_back(random_pair(rng));
    // Unknowns: pair p's (motion, a, b) at 5p..5p+4, the tilt at 5P, 5P+1.
    const int N = 5 * P + 2;
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(N, N);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(N);
    const int local[5] = {0, 1, 2, 5, 6};  // motion, brightness in the pass's order
    for (int p = 0; p < P; ++p) {
      int at[7];
      for (int k = 0; k < 5; ++k) at[local[k]] = 5 * p + k;
      at[3] = 5 * P;
      at[4] = 5 * P + 1;
      for (int i = 0; i < 7; ++i) {
        g(at[i]) += sums[static_cast<size_t>(p)].JtWr(i);
        for (int j = 0; j < 7; ++j) H(at[i], at[j]) += sums[static_cast<size_t>(p)].JtWJ(i, j);
      }
    }
    Eigen::MatrixXd Hd = H;
    for (int i = 0; i < N; ++i) Hd(i, i) *= 1.0 + lambda;
    const Eigen::VectorXd dense = -Hd.ldlt().solve(g);

    JointStep step;
    ASSERT_TRUE(solve_joint(sums, true, true, lambda, &step));
    for (int p = 0; p < P; ++p)
      for (int k = 0; k < 5; ++k)
        EXPECT_NEAR(step.local[static_cast<size_t>(p)](k), dense(5 * p + k), 1e-8 * (1 + std::abs(dense(5 * p + k))))
            << "lambda " << lambda << " pair " << p << " parameter " << k;
    EXPECT_NEAR(step.orientation(0), dense(5 * P), 1e-8 * (1 + std::abs(dense(5 * P))));
    EXPECT_NEAR(step.orientation(1), dense(5 * P + 1), 1e-8 * (1 + std::abs(dense(5 * P + 1))));

    if (lambda == 0.0) {
      // The tilt's information is the inverse of its block of the dense covariance.
      const Eigen::MatrixXd cov = H.inverse();
      const Eigen::Matrix2d expected = cov.bottomRightCorner(2, 2).inverse();
      const Eigen::Matrix2d S = joint_orientation_information(sums, true);
      EXPECT_LT((S - expected).norm(), 1e-8 * expected.norm());
    }
  }
}

TEST(AlignerJointSolve, WithoutTheTiltEachPairIsItsOwnSystem) {
  std::mt19937 rng(10);
  const ReduceSums full = random_pair(rng);
  // The tracker's layout: motion 3, brightness 2 (NPARAM 3).
  ReduceSums s;
  const int keep[5] = {0, 1, 2, 5, 6};
  s.JtWJ.resize(5, 5);
  s.JtWr.resize(5);
  for (int i = 0; i < 5; ++i) {
    s.JtWr(i) = full.JtWr(keep[i]);
    for (int j = 0; j < 5; ++j) s.JtWJ(i, j) = full.JtWJ(keep[i], keep[j]);
  }
  JointStep step;
  ASSERT_TRUE(solve_joint({s}, true, false, 0.0, &step));
  // The solve adds a ridge of 1e-12 of the largest diagonal entry (a parameter the images do not
  // constrain at all still gets a finite step); so does the reference.
  Eigen::MatrixXd A = s.JtWJ;
  A.diagonal().array() += 1e-12 * A.diagonal().maxCoeff();
  const Eigen::VectorXd dense = -A.ldlt().solve(Eigen::VectorXd(s.JtWr));
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(step.local[0](k), dense(k), 1e-9 * (1 + std::abs(dense(k))));
  // Without brightness only the motion block is solved.
  ASSERT_TRUE(solve_joint({s}, false, false, 0.0, &step));
  Eigen::Matrix3d A3 = s.JtWJ.topLeftCorner(3, 3);
  A3.diagonal().array() += 1e-12 * A3.diagonal().maxCoeff();
  const Eigen::Vector3d motion = -A3.ldlt().solve(s.JtWr.head(3));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(step.local[0](k), motion(k), 1e-9 * (1 + std::abs(motion(k))));
  EXPECT_EQ(step.local[0](3), 0.0);
}

}  // namespace
}  // namespace planarvo::track
