// Marginal covariances and observability against a dense reference: the inverse of the dense
// Gauss–Newton matrix and its Schur complement, built from per-factor Jacobians.
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/error.h"
#include "graph/solver/covariance.h"
#include "graph/posegraph/factors.h"
#include "graph/solver/normal_equations.h"
#include "graph/solver/solver.h"

namespace planarvo::graph {
namespace {

// e = wᵀx over a vector variable: information along one direction only.
class DirectionFactor final : public Factor {
 public:
  DirectionFactor(VariableId v, Eigen::VectorXd w, double target, double info)
      : Factor({v}, {VariableType::vector(static_cast<int>(w.size()))}, Eigen::Matrix<double, 1, 1>(info)),
        w_(std::move(w)), target_(target) {}
  void evaluate(const double* const* x, double* e, double* const* J) const override {
    e[0] = w_.dot(Eigen::Map<const Eigen::VectorXd>(x[0], w_.size())) - target_;
    if (J && J[0]) Eigen::Map<Eigen::RowVectorXd>(J[0], w_.size()) = w_.transpose();
  }

 private:
  Eigen::VectorXd w_;
  double target_;
};

// e = (t_j − t_i) − v: ties a 2-vector to a pose pair.
class DisplacementFactor final : public Factor {
 public:
  DisplacementFactor(VariableId i, VariableId j, VariableId v)
      : Factor({i, j, v}, {VariableType::pose2(), VariableType::pose2(), VariableType::vector(2)},
               Eigen::Matrix2d::Identity() * 25.0) {}
  void evaluate(const double* const* x, double* e, double* const* J) const override {
    e[0] = x[1][0] - x[0][0] - x[2][0];
    e[1] = x[1][1] - x[0][1] - x[2][1];
    if (!J) return;
    if (J[0]) Eigen::Map<Eigen::Matrix<double, 2, 3>>(J[0]) << -1, 0, 0, 0, -1, 0;
    if (J[1]) Eigen::Map<Eigen::Matrix<double, 2, 3>>(J[1]) << 1, 0, 0, 0, 1, 0;
    if (J[2]) Eigen::Map<Eigen::Matrix2d>(J[2]) << -1, 0, 0, -1;
  }
};

struct Problem {
  FactorGraph graph;
  std::vector<VariableId> poses;
  VariableId offset = -1;
};

// A noisy loop of poses with a 2-vector tied to some pose pairs, θ of one pose held, solved.
Problem make_problem(unsigned seed) {
  Problem p;
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 0.05);
  const int N = 16;
  for (int i = 0; i < N; ++i) {
    const double phi = 2 * M_PI * i / N;
    p.poses.push_back(p.graph.add_pose(SE2(4 * std::cos(phi) + n(rng), 4 * std::sin(phi) + n(rng), phi + M_PI / 2)));
  }
  p.offset = p.graph.add_vector(Eigen::Vector2d(0.5, 0.5), "offset", {"dx", "dy"});
  p.graph.set_fixed(p.poses[0]);
  p.graph.set_parameter_fixed(p.poses[3], 2);
  Eigen::Matrix3d info;
  info << 50, 5, 2, 5, 40, -1, 2, -1, 300;
  for (int i = 0; i < N; ++i) {
    const int j = (i + 1) % N;
    const double step = 2 * M_PI / N;
    const double chord = 2 * 4 * std::sin(step / 2);
    p.graph.emplace_factor<RelativePoseFactor>(p.poses[i], p.poses[j],
                                               SE2(chord * std::cos(step / 2) + n(rng),
                                                   chord * std::sin(step / 2) + n(rng), step + n(rng)),
                                               info);
  }
  for (int i = 2; i + 4 < N; i += 3)
    p.graph.emplace_factor<DisplacementFactor>(p.poses[i], p.poses[i + 4], p.offset);
  EXPECT_TRUE(solve(p.graph).converged());
  return p;
}

// Dense H in the columns of a NormalEquations of the same graph (stored coordinates).
Eigen::MatrixXd dense_information(const FactorGraph& g, const NormalEquations& ne) {
  const int n = ne.num_columns();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  for (int f = 0; f < g.num_factors(); ++f) {
    Eigen::VectorXd r;
    std::vector<Eigen::MatrixXd> J;
    linearize_factor(g, f, r, J);
    Eigen::MatrixXd Jf = Eigen::MatrixXd::Zero(r.size(), n);
    const auto& vars = g.factor(f).variables();
    for (size_t k = 0; k < vars.size(); ++k)
      for (int p = 0; p < J[k].cols(); ++p)
        if (ne.column(vars[k], p) >= 0) Jf.col(ne.column(vars[k], p)) += J[k].col(p);
    H += Jf.transpose() * Jf;
  }
  return H;
}

TEST(GraphCovariance, MarginalCovarianceMatchesDenseInverse) {
  Problem p = make_problem(1);
  NormalEquations ne(p.graph, {});
  const Eigen::MatrixXd Hinv = dense_information(p.graph, ne).inverse();
  const std::vector<VariableId> chosen = {p.poses[5], p.offset, p.poses[3], p.poses[0]};
  MarginalCovariance cov(p.graph, chosen);
  for (VariableId a : chosen)
    for (VariableId b : chosen) {
      const Eigen::MatrixXd C = cov.block(a, b);
      for (int i = 0; i < C.rows(); ++i)
        for (int j = 0; j < C.cols(); ++j) {
          const int ci = ne.column(a, i), cj = ne.column(b, j);
          const double ref = ci >= 0 && cj >= 0 ? Hinv(ci, cj) : 0.0;
          EXPECT_NEAR(C(i, j), ref, 1e-9 * Hinv.cwiseAbs().maxCoeff()) << a << "," << b << " (" << i << "," << j << ")";
        }
    }
  // Fixed: the whole of pose 0 and θ of pose 3 have exactly zero (co)variance.
  EXPECT_EQ(cov.covariance(p.poses[0]).norm(), 0.0);
  EXPECT_EQ(cov.covariance(p.poses[3]).row(2).norm(), 0.0);
  EXPECT_GT(cov.covariance(p.poses[3])(0, 0), 0.0);
  EXPECT_LT((marginal_covariance(p.graph, p.offset) - cov.covariance(p.offset)).norm(), 1e-12);
  EXPECT_THROW(cov.block(p.poses[7], p.offset), Error);  // not chosen
}

TEST(GraphCovariance, MarginalInformationIsTheDenseSchurComplement) {
  Problem p = make_problem(2);
  NormalEquations ne(p.graph, {});
  const Eigen::MatrixXd H = dense_information(p.graph, ne);
  // Block: the offset vector and pose 9.
  std::vector<int> b, o;
  for (int c = 0; c < ne.num_columns(); ++c) {
    bool in_block = false;
    for (VariableId v : {p.offset, p.poses[9]})
      for (int q = 0; q < p.graph.type(v).dim; ++q) in_block |= ne.column(v, q) == c;
    (in_block ? b : o).push_back(c);
  }
  auto sub = [&](const std::vector<int>& r, const std::vector<int>& c) {
    Eigen::MatrixXd M(r.size(), c.size());
    for (size_t i = 0; i < r.size(); ++i)
      for (size_t j = 0; j < c.size(); ++j) M(static_cast<int>(i), static_cast<int>(j)) = H(r[i], c[j]);
    return M;
  };
  const Eigen::MatrixXd S_ref = sub(b, b) - sub(b, o) * sub(o, o).inverse() * sub(o, b);
  // analyse_observability orders the block as given, pose 9 (x, y, θ) then offset (dx, dy):
  // the column order of b too, since the offset was added after the poses.
  const ObservabilityReport rep = analyse_observability(p.graph, {p.poses[9], p.offset});
  ASSERT_EQ(rep.parameter_names.size(), 5u);
  EXPECT_EQ(rep.parameter_names[0], p.graph.name(p.poses[9]) + ".x");
  EXPECT_EQ(rep.parameter_names[4], "offset.dy");
  EXPECT_LT((rep.information - S_ref).cwiseAbs().maxCoeff(), 1e-8 * S_ref.cwiseAbs().maxCoeff());
  EXPECT_TRUE(rep.observable());
  EXPECT_EQ(rep.rank, 5);
  EXPECT_TRUE(std::isfinite(rep.condition_number));
  EXPECT_TRUE(rep.unobservable.empty());
  // The marginal information is the inverse of the marginal covariance.
  MarginalCovariance cov(p.graph, {p.poses[9], p.offset});
  EXPECT_LT((rep.information.inverse() - cov.joint()).cwiseAbs().maxCoeff(),
            1e-8 * cov.joint().cwiseAbs().maxCoeff());
}

TEST(GraphCovariance, UnobservableParametersAreNamed) {
  Problem p = make_problem(3);
  // w = (a, b, c, d): information on a + b and on c; a − b and d are unobservable.
  const VariableId w = p.graph.add_vector(Eigen::Vector4d(1, 2, 3, 4), "w", {"a", "b", "c", "d"});
  p.graph.emplace_factor<DirectionFactor>(w, Eigen::Vector4d(1, 1, 0, 0), 2.0, 4.0);
  p.graph.emplace_factor<DirectionFactor>(w, Eigen::Vector4d(0, 0, 1, 0), 3.0, 1e4);
  const ObservabilityReport rep = analyse_observability(p.graph, {w});
  EXPECT_FALSE(rep.observable());
  EXPECT_EQ(rep.rank, 2);
  EXPECT_FALSE(std::isfinite(rep.condition_number));
  EXPECT_EQ(rep.unobservable, (std::vector<std::string>{"w.a", "w.b", "w.d"})) << rep.describe();
  ASSERT_EQ(rep.null_space.size(), 2u);
  for (const Eigen::VectorXd& d : rep.null_space) {
    EXPECT_NEAR(d[0] + d[1], 0.0, 1e-9);  // along a − b ...
    EXPECT_NEAR(d[2], 0.0, 1e-9);         // ... or d, never c
  }
  EXPECT_NE(rep.describe().find("unobservable: w.a w.b w.d"), std::string::npos) << rep.describe();
  // H is singular, so the covariance is refused rather than garbage.
  EXPECT_THROW(MarginalCovariance(p.graph, {w}), Error);
  // Holding d and b fixed leaves a and c, both observable.
  p.graph.set_parameter_fixed(w, 3);
  p.graph.set_parameter_fixed(w, 1);
  const ObservabilityReport fixed = analyse_observability(p.graph, {w});
  EXPECT_TRUE(fixed.observable()) << fixed.describe();
  EXPECT_EQ(fixed.parameter_names, (std::vector<std::string>{"w.a", "w.c"}));
  // Conditioning is unit-free: a and c differ by 2500× in information, not in scaled terms.
  EXPECT_NEAR(fixed.condition_number, 1.0, 1e-9);
}

TEST(GraphCovariance, FreeGaugeIsReportedNotAnswered) {
  Problem p = make_problem(4);
  p.graph.set_fixed(p.poses[0], false);
  EXPECT_THROW(analyse_observability(p.graph, {p.offset}), Error);
  EXPECT_THROW(MarginalCovariance(p.graph, {p.offset}), Error);
  // With a pose in the block the rest is determined again and the block carries the gauge: its
  // position is free, its heading is not (θ of pose 3 is held).
  const ObservabilityReport rep = analyse_observability(p.graph, {p.poses[0]});
  EXPECT_EQ(rep.rank, 1) << rep.describe();
  const std::string name = p.graph.name(p.poses[0]);
  EXPECT_EQ(rep.unobservable, (std::vector<std::string>{name + ".x", name + ".y"})) << rep.describe();
}

}  // namespace
}  // namespace planarvo::graph
