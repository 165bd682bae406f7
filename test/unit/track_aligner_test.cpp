// The aligner's joint solve (track/aligner.h: each pair's block eliminated onto the shared tilt,
// then back-substitution) against a dense solve of the whole assembled system, and the tilt's
// information against the inverse of the dense covariance's tilt block; the levels it aligns
// (AlignerOptions::finest_level's automatic rule) against the rule worked by hand.
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "ocl/runtime.h"
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

// Pyramid shapes only: Aligner::levels reads the levels' sizes, not their pixels.
Pyramid shape(int width, int height, int levels) {
  Pyramid p;
  for (int l = 0; l < levels; ++l) {
    PyramidLevel L;
    L.width = width >> l;
    L.height = height >> l;
    p.levels.push_back(L);
  }
  return p;
}

// finest_level -1: A = the coarsest level at least 320 px wide, then level A - 1 on one pixel per
// 3x3 block (auto_finer_block), and A itself then on one pixel per 2x2 block (auto_coarse_block);
// explicit levels and blocks are taken as given.
TEST(AlignerLevels, TheAutomaticFinestLevelIsTheOneBelowTheCoarsestAtLeast320Wide) {
  ocl::Runtime rt;
  const Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  struct Case {
    int w, h, finest_level, auto_block, coarse_block, select0, select1;
    int want_finest, want_block_at_finest, want_block_above;
  };
  const Case cases[] = {
      {640, 480, -1, 3, 2, 0, 0, 0, 3, 2},    // A = 1 at 1/4, then level 0 at 1/9
      {640, 480, -1, 3, 0, 0, 0, 0, 3, 0},    // auto_coarse_block 0: A on every pixel
      {640, 480, -1, 3, 2, 0, 3, 0, 3, 3},    // an explicit block at A wins
      {320, 240, -1, 3, 2, 0, 0, 0, 0, 0},    // A = 0: level 0 on every pixel
      {1280, 960, -1, 3, 2, 0, 0, 1, 3, 2},   // A = 2 at 1/4, level 1 at 1/9
      {640, 480, -1, 0, 2, 0, 0, 1, 0, 0},    // auto_finer_block 0: stop at A, on every pixel
      {640, 480, -1, 1, 2, 0, 0, 0, 0, 0},    // 1: level A - 1 on every pixel, and A
      {640, 480, -1, 3, 2, 4, 0, 0, 4, 2},    // an explicit block at that level wins
      {640, 480, 0, 3, 2, 0, 0, 0, 0, 0},     // an explicit finest level: every pixel
      {640, 480, 0, 3, 2, 2, 0, 0, 2, 0},
      {640, 480, 2, 3, 2, 0, 0, 2, 0, 0},
  };
  for (const Case& c : cases) {
    AlignerOptions o;
    o.finest_level = c.finest_level;
    o.auto_finer_block = c.auto_block;
    o.auto_coarse_block = c.coarse_block;
    o.select_blocks[0] = c.select0;
    o.select_blocks[1] = c.select1;
    Aligner aligner(rt, K, o, false);
    const Pyramid p = shape(c.w, c.h, 4);
    const AlignmentLevels L = aligner.levels(p, p);
    const std::string what = std::to_string(c.w) + "x" + std::to_string(c.h) + " finest_level " +
                             std::to_string(c.finest_level) + " blocks " + std::to_string(c.auto_block) + ", " +
                             std::to_string(c.coarse_block);
    EXPECT_EQ(L.coarsest, 3) << c.w;
    EXPECT_EQ(L.finest, c.want_finest) << what;
    EXPECT_EQ(L.select_block[static_cast<size_t>(L.finest)], c.want_block_at_finest) << what;
    const int above = L.finest + 1;
    EXPECT_EQ(L.select_block[static_cast<size_t>(above)], c.want_block_above) << what;
    for (int l = above + 1; l <= L.coarsest; ++l) EXPECT_EQ(L.select_block[static_cast<size_t>(l)], 0) << what << " " << l;
  }
}

// The subsampled level's prior test (prior_consistency_scale) against the same algebra done with
// dense inverses: 1 when the data's own estimate lies within chi2 of the prior, else the factor
// on H at which the inflated prior's d^2 equals chi2.
TEST(AlignerPrior, ConsistencyScaleInflatesThePriorUntilItExplainsTheDifference) {
  std::mt19937 rng(4);
  std::normal_distribution<double> n;
  int consistent = 0, scaled = 0;
  for (int nl : {3, 5}) {
    Eigen::MatrixXd J(60, nl), Jp(60, nl);
    for (int i = 0; i < 60; ++i)
      for (int j = 0; j < nl; ++j) {
        J(i, j) = n(rng) * (j < 3 ? 50.0 : 5.0);
        Jp(i, j) = n(rng) * (j < 3 ? 80.0 : 5.0);
      }
    const Eigen::MatrixXd A = J.transpose() * J, H = Jp.transpose() * Jp;
    const double sigma = 1.7, chi2 = 3.0;
    // The dense reference: d^2(scale) of the data's one-step estimate against the prior.
    auto d2 = [&](const Eigen::VectorXd& g, const Eigen::Vector3d& e, double scale) {
      const Eigen::VectorXd step = -A.inverse() * g;
      const Eigen::Vector3d dm = e + step.head<3>();
      const Eigen::Matrix3d C = sigma * sigma * (A.inverse().topLeftCorner<3, 3>() + H.inverse().topLeftCorner<3, 3>() / scale);
      return dm.dot(C.inverse() * dm);
    };
    for (double size : {0.1, 1.0, 10.0, 100.0}) {
      Eigen::VectorXd g(nl);
      for (int i = 0; i < nl; ++i) g(i) = n(rng) * size * sigma * 50.0;
      const Eigen::Vector3d e(n(rng) * size * 0.01, n(rng) * size * 0.01, n(rng) * size * 0.01);
      const double s = prior_consistency_scale(PriorMatrix(A), PriorVector(g), PriorMatrix(H), e, sigma, chi2);
      const double at1 = d2(g, e, 1.0);
      if (at1 <= chi2) {
        EXPECT_EQ(s, 1.0) << "nl " << nl << " size " << size << " d2 " << at1;
        ++consistent;
      } else if (s > 0.0) {
        ++scaled;
        EXPECT_LT(s, 1.0);
        EXPECT_NEAR(d2(g, e, s), chi2, 1e-5 * chi2) << "nl " << nl << " size " << size;
      } else {
        EXPECT_GT(d2(g, e, 1e-6), chi2);
      }
      EXPECT_EQ(prior_consistency_scale(PriorMatrix(A), PriorVector(g), PriorMatrix(H), e, sigma, 0.0), 1.0);
    }
  }
  EXPECT_GT(consistent, 0);
  EXPECT_GT(scaled, 0);
}

}  // namespace
}  // namespace planarvo::track
