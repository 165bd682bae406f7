// The Levenberg–Marquardt solver and its normal equations: known optima of synthetic graphs, a
// dense Eigen reference of the same normal equations, fixed variables and parameters, robust
// kernels against an outlier, non-positive-definite systems, the reference g2o files, g2o I/O.
#include <cmath>
#include <fstream>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "common/test_util.h"
#include "core/error.h"
#include "core/se2.h"
#include "graph/posegraph/factors.h"
#include "graph/posegraph/g2o.h"
#include "graph/posegraph/initialisation.h"
#include "graph/solver/normal_equations.h"
#include "graph/solver/solver.h"

namespace planarvo::graph {
namespace {

// A test-only factor tying a pose pair to a 2-vector: e = (t_j − t_i) − v. It couples a vector
// variable to poses, so the pattern code sees mixed blocks in both column orders.
class DisplacementFactor final : public Factor {
 public:
  DisplacementFactor(VariableId i, VariableId j, VariableId v, const Eigen::Matrix2d& info)
      : Factor({i, j, v}, {VariableType::pose2(), VariableType::pose2(), VariableType::vector(2)},
               info) {}
  void evaluate(const double* const* x, double* e, double* const* J) const override {
    e[0] = x[1][0] - x[0][0] - x[2][0];
    e[1] = x[1][1] - x[0][1] - x[2][1];
    if (!J) return;
    if (J[0]) Eigen::Map<Eigen::Matrix<double, 2, 3>>(J[0]) << -1, 0, 0, 0, -1, 0;
    if (J[1]) Eigen::Map<Eigen::Matrix<double, 2, 3>>(J[1]) << 1, 0, 0, 0, 1, 0;
    if (J[2]) Eigen::Map<Eigen::Matrix2d>(J[2]) << -1, 0, 0, -1;
  }
};

Eigen::Matrix3d edge_information() {
  Eigen::Matrix3d I;
  I << 100, 10, 5, 10, 80, -4, 5, -4, 400;
  return I;
}

double angle_diff(double a, double b) { return std::abs(wrap_angle(a - b)); }

// Two laps around a circle (radius 5, then 6) with odometry edges and loop closures between
// the laps; measurements from the truth, optionally noisy; initial values perturbed.
struct Synthetic {
  FactorGraph graph;
  std::vector<SE2> truth;
  std::vector<VariableId> poses;
};

Synthetic make_circle(int per_lap, double meas_noise, double init_noise, unsigned seed) {
  Synthetic s;
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int lap = 0; lap < 2; ++lap)
    for (int k = 0; k < per_lap; ++k) {
      const double phi = 2 * M_PI * k / per_lap, r = 5.0 + lap;
      s.truth.emplace_back(r * std::cos(phi), r * std::sin(phi), wrap_angle(phi + M_PI / 2));
    }
  for (size_t i = 0; i < s.truth.size(); ++i) {
    SE2 init = s.truth[i];
    if (i > 0) init = SE2(init.x + init_noise * n(rng), init.y + init_noise * n(rng),
                          init.theta + 0.5 * init_noise * n(rng));
    s.poses.push_back(s.graph.add_pose(init));
  }
  s.graph.set_fixed(s.poses[0]);
  auto add_edge = [&](size_t i, size_t j) {
    SE2 z = s.truth[i].inverse() * s.truth[j];
    z = SE2(z.x + meas_noise * n(rng), z.y + meas_noise * n(rng), z.theta + meas_noise * n(rng));
    s.graph.emplace_factor<RelativePoseFactor>(s.poses[i], s.poses[j], z, edge_information());
  };
  const size_t N = s.truth.size();
  for (size_t i = 0; i + 1 < N; ++i) add_edge(i, i + 1);
  for (int k = 0; k < per_lap; k += 3) add_edge(static_cast<size_t>(k), static_cast<size_t>(k + per_lap));
  return s;
}

double max_pose_error(const FactorGraph& g, const Synthetic& s) {
  double err = 0.0;
  for (size_t i = 0; i < s.poses.size(); ++i) {
    const SE2 p = g.pose(s.poses[i]);
    err = std::max({err, std::abs(p.x - s.truth[i].x), std::abs(p.y - s.truth[i].y),
                    angle_diff(p.theta, s.truth[i].theta)});
  }
  return err;
}

TEST(GraphSolver, NoiseFreeGraphConvergesToTruth) {
  for (PoseRetraction retraction : {PoseRetraction::Additive, PoseRetraction::RightExp}) {
    Synthetic s = make_circle(40, 0.0, 0.3, 1);
    SolverOptions o;
    o.linear.retraction = retraction;
    // The default step tolerance (1e-8 relative, as Ceres) stops at ~1e-8·|x| ≈ 5e-7 here.
    o.parameter_tolerance = 1e-14;
    const SolverSummary sum = solve(s.graph, o);
    EXPECT_TRUE(sum.converged()) << sum.full_report();
    EXPECT_LT(max_pose_error(s.graph, s), 1e-9) << sum.full_report();
    EXPECT_LT(s.graph.chi2(), 1e-18);
    EXPECT_GT(sum.initial_cost, 1.0);
  }
}

// The mixed graph of the dense-reference test: poses, a 2-vector tied to pose pairs, priors, a
// robust kernel, a fixed pose and single fixed parameters of a pose and of the vector.
FactorGraph make_mixed_graph(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  FactorGraph g;
  const VariableId v0 = g.add_vector(Eigen::Vector2d(0.3, -0.2), "offset");
  std::vector<VariableId> p;
  for (int i = 0; i < 8; ++i) p.push_back(g.add_pose(SE2(i + 0.2 * u(rng), 0.3 * u(rng), 0.4 * u(rng))));
  const VariableId v1 = g.add_vector(Eigen::Vector3d(1, 2, 3), "tail");
  g.set_fixed(p[0]);
  g.set_parameter_fixed(p[3], 2);  // θ of pose 3
  g.set_parameter_fixed(v1, 1);
  for (int i = 0; i + 1 < 8; ++i)
    g.emplace_factor<RelativePoseFactor>(p[i], p[i + 1], SE2(1, 0.1 * u(rng), 0.1 * u(rng)),
                                         edge_information());
  g.add_factor(std::make_unique<RelativePoseFactor>(p[1], p[6], SE2(5, 0.3, 0.2), edge_information()),
               std::make_shared<CauchyKernel>(1.0));
  for (int i = 0; i + 2 < 8; i += 2)
    g.add_factor(std::make_unique<DisplacementFactor>(p[i + 2], p[i], v0, 4.0 * Eigen::Matrix2d::Identity()),
                 i == 2 ? std::make_shared<HuberKernel>(0.5) : nullptr);
  g.emplace_factor<VectorPriorFactor>(v1, Eigen::Vector3d(1.5, 2, 2.5), Eigen::Matrix3d::Identity());
  g.emplace_factor<PosePriorFactor>(p[5], SE2(5, 0, 0), edge_information());
  return g;
}

TEST(GraphSolver, SparseNormalEquationsMatchDenseReference) {
  for (PoseRetraction retraction : {PoseRetraction::Additive, PoseRetraction::RightExp}) {
    for (Factorization fact : {Factorization::Simplicial, Factorization::Supernodal}) {
      FactorGraph g = make_mixed_graph(5);
      LinearSolverOptions lo;
      lo.retraction = retraction;
      lo.factorization = fact;
      NormalEquations ne(g, lo);
      const int n = ne.num_columns();
      // Dense reference: per-factor Jacobians, assembled by column.
      Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
      Eigen::VectorXd grad = Eigen::VectorXd::Zero(n);
      double cost = 0.0;
      for (int f = 0; f < g.num_factors(); ++f) {
        Eigen::VectorXd r;
        std::vector<Eigen::MatrixXd> J;
        cost += linearize_factor(g, f, r, J);
        const auto& vars = g.factor(f).variables();
        Eigen::MatrixXd Jf = Eigen::MatrixXd::Zero(r.size(), n);
        for (size_t k = 0; k < vars.size(); ++k) {
          Eigen::MatrixXd Jk = J[k];
          // RightExp: poses step in their own frame, except pose 3 (variable 4) whose θ is
          // fixed and which steps additively.
          if (retraction == PoseRetraction::RightExp && g.type(vars[k]).kind == VariableKind::Pose2 &&
              g.fixed_mask(vars[k]) == 0) {
            Eigen::Matrix3d B = Eigen::Matrix3d::Identity();
            B.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(g.pose(vars[k]).theta).toRotationMatrix();
            Jk = Jk * B;
          }
          for (int p = 0; p < Jk.cols(); ++p) {
            const int c = ne.column(vars[k], p);
            if (c >= 0) Jf.col(c) += Jk.col(p);
          }
        }
        H += Jf.transpose() * Jf;
        grad += Jf.transpose() * r;
      }
      const double sparse_cost = ne.linearize(g.values().data());
      EXPECT_NEAR(sparse_cost, cost, 1e-12 * cost);
      EXPECT_LT((ne.dense_hessian() - H).cwiseAbs().maxCoeff(), 1e-10 * H.cwiseAbs().maxCoeff());
      EXPECT_LT((ne.gradient() - grad).cwiseAbs().maxCoeff(), 1e-10 * grad.cwiseAbs().maxCoeff());
      // The damped step, both damping types.
      for (Damping damping : {Damping::Marquardt, Damping::Levenberg}) {
        const double lambda = 1e-3;
        Eigen::VectorXd D = damping == Damping::Marquardt
                                ? Eigen::VectorXd(H.diagonal().cwiseMax(lo.min_diagonal))
                                : Eigen::VectorXd::Ones(n);
        const Eigen::MatrixXd A = H + lambda * Eigen::MatrixXd(D.asDiagonal());
        const Eigen::VectorXd ref = A.llt().solve(-grad);
        ASSERT_TRUE(ne.factorize(lambda, damping));
        Eigen::VectorXd delta;
        ASSERT_TRUE(ne.solve_step(delta));
        EXPECT_LT((delta - ref).norm(), 1e-9 * ref.norm());
        // The predicted decrease is the model's: |r|² − |r + Jδ|² = −2gᵀδ − δᵀHδ.
        const double pred = -2 * grad.dot(ref) - ref.dot(H * ref);
        EXPECT_NEAR(ne.predicted_decrease(delta), pred, 1e-9 * std::abs(pred));
      }
    }
  }
}

TEST(GraphSolver, ReusedFactorPreconditionsTheNewSystem) {
  // Factorise at one state, move, linearise again: CG on the old factor must solve the new
  // damped system (checked against a dense solve of it), for a different λ too.
  Synthetic s = make_circle(30, 0.02, 0.05, 12);
  NormalEquations ne(s.graph, {});
  ne.linearize(s.graph.values().data());
  ASSERT_TRUE(ne.factorize(1e-3, Damping::Marquardt));
  std::vector<double> moved = s.graph.values();
  for (size_t i = 3; i < moved.size(); ++i) moved[i] += 0.01 * std::sin(static_cast<double>(i));
  ne.linearize(moved.data());
  const Eigen::MatrixXd H = ne.dense_hessian();
  const Eigen::VectorXd g = ne.gradient();
  const double lambda = 1e-2;
  const Eigen::MatrixXd A = H + lambda * Eigen::MatrixXd(H.diagonal().asDiagonal());
  const Eigen::VectorXd ref = A.llt().solve(-g);
  Eigen::VectorXd delta;
  const int iterations = ne.solve_step_reusing_factor(lambda, Damping::Marquardt, delta, 100, 1e-12);
  ASSERT_GT(iterations, 0);
  EXPECT_LT((delta - ref).norm(), 1e-8 * ref.norm()) << iterations << " CG iterations";
  // The model decrease of an inexact step is computed with H itself.
  EXPECT_NEAR(ne.predicted_decrease(delta), -2 * g.dot(delta) - delta.dot(H * delta),
              1e-9 * std::abs(g.dot(delta)));
  // Too few iterations allowed: reported as failure, not as a step.
  EXPECT_EQ(ne.solve_step_reusing_factor(lambda, Damping::Marquardt, delta, 1, 1e-14), -1);
}

TEST(GraphSolver, FactorReuseReachesTheSameOptimum) {
  const G2oFile file = read_g2o(test::shared_dir() / "data" / "posegraphs" / "intel.g2o");
  SolverOptions with, without;
  with.reuse_cg_budget = 100.0;  // reuse whenever CG converges within the iteration cap
  with.reuse_max_cg_iterations = 20;
  without.reuse_factorization = false;
  FactorGraph a = make_pose_graph(file), b = make_pose_graph(file);
  // Start away from the files' values so that there are several iterations to reuse across.
  initialise_spanning_tree(a);
  initialise_spanning_tree(b);
  const SolverSummary sa = solve(a, with), sb = solve(b, without);
  EXPECT_TRUE(sa.converged()) << sa.full_report();
  EXPECT_TRUE(sb.converged()) << sb.full_report();
  EXPECT_LT(sa.num_factorizations, sa.num_iterations) << sa.full_report();
  EXPECT_EQ(sb.num_factorizations, sb.num_iterations);
  EXPECT_NEAR(a.chi2(), b.chi2(), 1e-5 * b.chi2());
  EXPECT_NEAR(a.chi2(), 546.461, 1e-3 * 546.461);
}

TEST(GraphSolver, FixedVariablesAndParametersKeepTheirValues) {
  FactorGraph g = make_mixed_graph(9);
  const std::vector<double> before = g.values();
  SolverOptions tight;  // converge fully, so that two retractions can be compared below
  tight.function_tolerance = 1e-14;
  tight.parameter_tolerance = 1e-14;
  const SolverSummary s = solve(g, tight);
  EXPECT_TRUE(s.converged()) << s.full_report();
  const std::vector<double>& after = g.values();
  // pose 0 (variable 1) fixed; θ of pose 3 (variable 4); parameter 1 of "tail" (variable 9).
  for (int p = 0; p < 3; ++p) EXPECT_EQ(after[static_cast<size_t>(g.offset(1) + p)], before[static_cast<size_t>(g.offset(1) + p)]);
  EXPECT_EQ(after[static_cast<size_t>(g.offset(4) + 2)], before[static_cast<size_t>(g.offset(4) + 2)]);
  EXPECT_EQ(after[static_cast<size_t>(g.offset(9) + 1)], before[static_cast<size_t>(g.offset(9) + 1)]);
  // ... while the free parameters next to them moved.
  EXPECT_NE(after[static_cast<size_t>(g.offset(4))], before[static_cast<size_t>(g.offset(4))]);
  EXPECT_NE(after[static_cast<size_t>(g.offset(9))], before[static_cast<size_t>(g.offset(9))]);
  EXPECT_NE(after[static_cast<size_t>(g.offset(9) + 2)], before[static_cast<size_t>(g.offset(9) + 2)]);
  EXPECT_LT(s.final_cost, s.initial_cost);
  // The same with the additive retraction everywhere.
  FactorGraph h = make_mixed_graph(9);
  SolverOptions o = tight;
  o.linear.retraction = PoseRetraction::Additive;
  ASSERT_TRUE(solve(h, o).converged());
  EXPECT_EQ(h.values()[static_cast<size_t>(h.offset(4) + 2)], before[static_cast<size_t>(h.offset(4) + 2)]);
  EXPECT_NEAR(h.robust_cost(), g.robust_cost(), 1e-9 * g.robust_cost());
}

TEST(GraphSolver, EveryVariableFixedIsNothingToOptimize) {
  Synthetic s = make_circle(10, 0.0, 0.1, 2);
  for (VariableId v : s.poses) s.graph.set_fixed(v);
  const SolverSummary sum = solve(s.graph);
  EXPECT_EQ(sum.termination, TerminationType::NothingToOptimize);
  EXPECT_DOUBLE_EQ(sum.final_cost, s.graph.chi2());
}

// One gross outlier among loop closures: plain least squares is pulled away from the
// outlier-free optimum, Cauchy and Tukey are not.
TEST(GraphSolver, RobustKernelsDownWeightAnOutlier) {
  const int per_lap = 30;
  auto build = [&](bool with_outlier, RobustKernelPtr kernel) {
    Synthetic s = make_circle(per_lap, 0.01, 0.0, 3);
    // Start every solve from odometry chaining, not from the truth.
    initialise_spanning_tree(s.graph);
    if (with_outlier)
      s.graph.add_factor(std::make_unique<RelativePoseFactor>(s.poses[5], s.poses[50],
                                                              SE2(3.0, -4.0, 2.0), edge_information()),
                         kernel);
    for (int f = 0; f < s.graph.num_factors(); ++f)
      if (f >= 2 * per_lap - 1) s.graph.set_robust_kernel(f, kernel);  // loop closures
    return s;
  };
  Synthetic clean = build(false, nullptr);
  ASSERT_TRUE(solve(clean.graph).converged());
  auto distance_to_clean = [&](const FactorGraph& g) {
    double d = 0.0;
    for (VariableId v : clean.poses) {
      const SE2 a = g.pose(v), b = clean.graph.pose(v);
      d = std::max({d, std::hypot(a.x - b.x, a.y - b.y), angle_diff(a.theta, b.theta)});
    }
    return d;
  };
  Synthetic plain = build(true, nullptr);
  solve(plain.graph);
  const double plain_error = distance_to_clean(plain.graph);
  EXPECT_GT(plain_error, 0.1);
  for (RobustKernelPtr k : {RobustKernelPtr(std::make_shared<CauchyKernel>(1.0)),
                            RobustKernelPtr(std::make_shared<TukeyKernel>(3.0))}) {
    Synthetic robust = build(true, k);
    const SolverSummary sum = solve(robust.graph);
    EXPECT_TRUE(sum.converged()) << k->name() << "\n" << sum.full_report();
    EXPECT_LT(distance_to_clean(robust.graph), 0.02 * plain_error) << k->name();
  }
}

TEST(GraphSolver, FailedFactorisationRejectsTheStepAndRecovers) {
  // Pure Gauss–Newton at the start (λ = 0) and a free variable no factor touches: H is
  // singular, the factorisation must fail, be reported, and damping must take over.
  Synthetic s = make_circle(10, 0.0, 0.2, 4);
  s.graph.add_vector(Eigen::Vector2d(1, 2), "untouched");
  SolverOptions o;
  o.damping = Damping::Levenberg;
  o.initial_lambda = 0.0;
  o.min_lambda = 0.0;
  const SolverSummary sum = solve(s.graph, o);
  ASSERT_GE(sum.iterations.size(), 2u);
  EXPECT_FALSE(sum.iterations[1].factorization_ok) << sum.full_report();
  EXPECT_FALSE(sum.iterations[1].step_accepted);
  EXPECT_GE(sum.num_failed_factorizations, 1);
  EXPECT_TRUE(sum.converged()) << sum.full_report();
  EXPECT_LT(max_pose_error(s.graph, s), 1e-8);
  EXPECT_EQ(s.graph.vector(s.graph.num_variables() - 1), Eigen::Vector2d(1, 2));
}

TEST(GraphSolver, FreeGaugeDoesNotBreakTheSolver) {
  // No fixed pose: H has a 3-dimensional null space; Marquardt damping keeps H + λD definite.
  Synthetic s = make_circle(20, 0.0, 0.2, 5);
  s.graph.set_fixed(s.poses[0], false);
  const SolverSummary sum = solve(s.graph);
  EXPECT_TRUE(sum.converged()) << sum.full_report();
  EXPECT_LT(s.graph.chi2(), 1e-12);
}

TEST(GraphSolver, NonFiniteCostIsReported) {
  Synthetic s = make_circle(10, 0.0, 0.2, 6);
  std::vector<double> v = s.graph.values();
  v[3] = std::nan("");
  s.graph.set_values(v);
  const SolverSummary sum = solve(s.graph);
  EXPECT_EQ(sum.termination, TerminationType::NumericalFailure);
  EXPECT_FALSE(sum.converged());
}

TEST(GraphSolver, SummaryHasOneTableRowPerIteration) {
  Synthetic s = make_circle(20, 0.01, 0.2, 7);
  SolverOptions o;
  int calls = 0;
  o.callback = [&](const IterationSummary&) { return ++calls < 3; };
  const SolverSummary sum = solve(s.graph, o);
  EXPECT_EQ(sum.termination, TerminationType::UserStop);
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(sum.iterations.size(), static_cast<size_t>(sum.num_iterations + 1));
  const std::string report = sum.full_report();
  size_t rows = 0;
  for (size_t p = report.find("\n"); p != std::string::npos; p = report.find("\n", p + 1)) ++rows;
  EXPECT_GE(rows, sum.iterations.size() + 4);
  EXPECT_NE(report.find("UserStop"), std::string::npos);
  EXPECT_NE(sum.brief_report().find("UserStop"), std::string::npos);
  EXPECT_EQ(sum.num_accepted + sum.num_rejected + sum.num_failed_factorizations, sum.num_iterations);
}

TEST(GraphSolver, ReusesTheAnalysisAndNoticesStructureChanges) {
  Synthetic s = make_circle(20, 0.01, 0.2, 8);
  Solver solver;
  const SolverSummary first = solver.solve(s.graph);
  EXPECT_GT(first.times.analyze, 0.0);
  s.graph.set_values(make_circle(20, 0.01, 0.2, 8).graph.values());
  const SolverSummary second = solver.solve(s.graph);
  EXPECT_EQ(second.times.analyze, 0.0);
  EXPECT_NEAR(second.final_cost, first.final_cost, 1e-6 * first.final_cost);
  // A new factor changes the pattern: the solver must rebuild, and the result must see it.
  s.graph.emplace_factor<PosePriorFactor>(s.poses[7], SE2(0, 0, 0), Eigen::Matrix3d::Identity());
  const SolverSummary third = solver.solve(s.graph);
  EXPECT_GT(third.times.analyze, 0.0);
  EXPECT_GT(third.final_cost, first.final_cost);
  EXPECT_NEAR(third.final_cost, s.graph.chi2(), 1e-9 * third.final_cost);
}

TEST(GraphSolver, NeverMistakesOneGraphForAnother) {
  // Graphs built the same way, one after another at the same address: each must get its own
  // analysis (sizes differ, so a stale one would break).
  Solver solver;
  for (int round = 0; round < 3; ++round) {
    Synthetic s = make_circle(10 + 5 * round, 0.0, 0.1, 20);
    const SolverSummary sum = solver.solve(s.graph);
    EXPECT_TRUE(sum.converged()) << sum.full_report();
    EXPECT_EQ(sum.num_parameters, 3 * (2 * (10 + 5 * round) - 1));
    EXPECT_LT(max_pose_error(s.graph, s), 1e-6);
  }
  // A moved graph keeps its factors and may keep the analysis; a kernel change may not.
  Synthetic s = make_circle(20, 0.0, 0.1, 21);
  solver.solve(s.graph);
  FactorGraph moved = std::move(s.graph);
  moved.set_values(make_circle(20, 0.0, 0.1, 21).graph.values());
  EXPECT_TRUE(solver.solve(moved).converged());
  EXPECT_LT(max_pose_error(moved, s), 1e-6);
  // The moved-from graph is empty and no longer matches.
  EXPECT_EQ(s.graph.num_variables(), 0);
  EXPECT_NE(s.graph.structure_version(), moved.structure_version());
  const std::uint64_t before = moved.structure_version();
  moved.set_robust_kernel(0, std::make_shared<HuberKernel>(1.0));
  EXPECT_NE(moved.structure_version(), before);
  EXPECT_GT(solver.solve(moved).times.analyze, 0.0);
}

// ---- the reference files ---------------------------------------------------------------------

double solve_file(const std::string& name, SolverSummary* summary = nullptr) {
  const G2oFile file = read_g2o(test::shared_dir() / "data" / "posegraphs" / name);
  FactorGraph g = make_pose_graph(file);
  const SolverSummary s = solve(g);
  EXPECT_TRUE(s.converged()) << s.full_report();
  if (summary) *summary = s;
  return g.chi2();
}

TEST(GraphReferenceFiles, RingReachesTheReferenceOptimum) {
  EXPECT_NEAR(solve_file("ring.g2o"), 11.1631, 1e-3 * 11.1631);
}

TEST(GraphReferenceFiles, IntelReachesTheReferenceOptimum) {
  EXPECT_NEAR(solve_file("intel.g2o"), 546.461, 1e-3 * 546.461);
}

TEST(GraphReferenceFiles, ManhattanReachesTheReferenceOptimum) {
  EXPECT_NEAR(solve_file("manhattanOlson3500.g2o"), 146.0767, 1e-3 * 146.0767);
}

TEST(GraphReferenceFiles, RotationFirstInitialisationReachesTheSameOptimum) {
  const G2oFile file = read_g2o(test::shared_dir() / "data" / "posegraphs" / "manhattanOlson3500.g2o");
  FactorGraph g = make_pose_graph(file);
  const double before = g.chi2();
  initialise_rotation_first(g);
  EXPECT_LT(g.chi2(), 1e-3 * before);
  EXPECT_TRUE(solve(g).converged());
  EXPECT_NEAR(g.chi2(), 146.0767, 1e-3 * 146.0767);
}

// ---- g2o files --------------------------------------------------------------------------------

TEST(GraphG2o, WriteThenReadRoundTrips) {
  test::ScratchDir dir;
  const G2oFile ring = read_g2o(test::shared_dir() / "data" / "posegraphs" / "ring.g2o");
  EXPECT_EQ(ring.vertices.size(), 434u);
  EXPECT_EQ(ring.edges.size(), 459u);
  FactorGraph g = make_pose_graph(ring);
  solve(g);
  G2oFile out = ring;
  update_poses(out, g);
  write_g2o(dir / "ring_opt.g2o", out);
  const G2oFile back = read_g2o(dir / "ring_opt.g2o");
  ASSERT_EQ(back.vertices.size(), out.vertices.size());
  ASSERT_EQ(back.edges.size(), out.edges.size());
  for (size_t i = 0; i < back.vertices.size(); ++i) {
    EXPECT_EQ(back.vertices[i].id, out.vertices[i].id);
    EXPECT_EQ(back.vertices[i].pose.x, out.vertices[i].pose.x);
    EXPECT_EQ(back.vertices[i].pose.theta, out.vertices[i].pose.theta);
  }
  for (size_t i = 0; i < back.edges.size(); ++i) {
    EXPECT_EQ(back.edges[i].information, out.edges[i].information);
    EXPECT_EQ(back.edges[i].measurement.y, out.edges[i].measurement.y);
  }
  // The written optimum is still the optimum.
  EXPECT_NEAR(make_pose_graph(back).chi2(), g.chi2(), 1e-9 * g.chi2());
}

TEST(GraphG2o, ErrorsNameFileAndLine) {
  test::ScratchDir dir;
  auto expect_error = [&](const std::string& text, const std::string& where, const std::string& what) {
    const auto path = dir / "bad.g2o";
    std::ofstream(path) << text;
    try {
      read_g2o(path);
      ADD_FAILURE() << "no error for:\n" << text;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidInput);
      const std::string msg = e.what();
      EXPECT_NE(msg.find("bad.g2o:" + where), std::string::npos) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
    }
  };
  const std::string v = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n";
  expect_error(v + "EDGE_SE2 0 1 1 0 0 1 0 0 1 0\n", "3", "I33");
  expect_error(v + "EDGE_SE2 0 7 1 0 0 1 0 0 1 0 1\n", "3", "no vertex 7");
  expect_error(v + "EDGE_SE2 0 1 1 0 0 1 0 0 -1 0 1\n", "3", "positive definite");
  expect_error(v + "EDGE_SE2 0 1 nan 0 0 1 0 0 1 0 1\n", "3", "not finite");
  expect_error(v + "EDGE_SE2 0 1 1 0 inf 1 0 0 1 0 1\n", "3", "not finite");
  expect_error(v + "EDGE_SE2 0 1 1 0 0 1 0 0 nan 0 1\n", "3", "positive definite");
  expect_error(v + "# comment\nVERTEX_XY 2 1 1\n", "4", "VERTEX_XY");
  expect_error("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n", "2", "twice");
  expect_error("VERTEX_SE2 0 0 zero 0\n", "1", "y");
  EXPECT_THROW(read_g2o(dir / "missing.g2o"), Error);
}

}  // namespace
}  // namespace planarvo::graph
