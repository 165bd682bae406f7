// planarvo's solver next to Ceres Solver 2.1 on the same graphs, from the same initial values,
// with the same tolerances and iteration cap. Ceres: SPARSE_NORMAL_CHOLESKY on SuiteSparse, one
// thread, its default Levenberg–Marquardt. Both evaluate the very same planarvo factors (Ceres
// through a CostFunction that calls Factor::evaluate and whitens), so the residuals, Jacobians
// and parameterisation (additive x, y, θ) are identical; only the solvers differ. χ² is
// recomputed by planarvo from each solver's result. Times are each solver's own total (Ceres:
// Summary::total_time_in_seconds, planarvo: SolverSummary::total_time_s), best of --repeat.
//
//   bench_posegraph_ceres [--file NAME] [--calibration N] [--repeat N] [--iterations N]
//                         [--ceres-radius R]   (Ceres' initial trust-region radius, default 1e4)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <ceres/ceres.h>

#include "../bench_posegraph_synthetic.h"
#include "core/error.h"
#include "graph/posegraph/g2o.h"
#include "graph/solver/solver.h"

using namespace planarvo;
using namespace planarvo::graph;

namespace {

// A planarvo factor as a Ceres cost: r = L·e, dr/dx = L·de/dx (row-major for Ceres).
class FactorCost final : public ceres::CostFunction {
 public:
  explicit FactorCost(const Factor& f) : f_(f) {
    set_num_residuals(f.residual_dim());
    for (const VariableType& t : f.types()) mutable_parameter_block_sizes()->push_back(t.dim);
    e_.resize(f.residual_dim());
    L_ = f.sqrt_information();
    for (const VariableType& t : f.types()) J_.emplace_back(f.residual_dim(), t.dim);
    for (auto& J : J_) Jptr_.push_back(J.data());
  }
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const int m = f_.residual_dim();
    std::vector<double*> jp(Jptr_.size(), nullptr);
    if (jacobians)
      for (size_t k = 0; k < jp.size(); ++k) jp[k] = jacobians[k] ? Jptr_[k] : nullptr;
    f_.evaluate(p, e_.data(), jacobians ? jp.data() : nullptr);
    if (f_.information_depends_on_state()) f_.sqrt_information_at(p, L_.data());
    Eigen::Map<Eigen::VectorXd> r(residuals, m);
    r = L_.triangularView<Eigen::Upper>() * e_;
    if (!jacobians) return true;
    for (size_t k = 0; k < J_.size(); ++k) {
      if (!jacobians[k]) continue;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> out(
          jacobians[k], m, J_[k].cols());
      out = L_.triangularView<Eigen::Upper>() * J_[k];
    }
    return true;
  }

 private:
  const Factor& f_;
  mutable Eigen::VectorXd e_;
  mutable Eigen::MatrixXd L_;
  mutable std::vector<Eigen::MatrixXd> J_;
  std::vector<double*> Jptr_;
};

struct Result {
  double chi2 = 0, ms = 1e300;
  int iterations = 0;
  std::string termination;
};

Result run_ceres(FactorGraph& graph, int max_iterations, double radius) {
  std::vector<double> x = graph.values();
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  for (int f = 0; f < graph.num_factors(); ++f) {
    if (graph.robust_kernel(f)) throw Error(ErrorCode::Internal, "robust kernels not mapped");
    std::vector<double*> blocks;
    for (VariableId v : graph.factor(f).variables()) blocks.push_back(x.data() + graph.offset(v));
    problem.AddResidualBlock(new FactorCost(graph.factor(f)), nullptr, blocks);
  }
  for (VariableId v = 0; v < graph.num_variables(); ++v) {
    double* block = x.data() + graph.offset(v);
    if (!problem.HasParameterBlock(block)) continue;
    if (graph.is_fixed(v)) {
      problem.SetParameterBlockConstant(block);
      continue;
    }
    std::vector<int> fixed;
    for (int p = 0; p < graph.type(v).dim; ++p)
      if (graph.is_parameter_fixed(v, p)) fixed.push_back(p);
    if (!fixed.empty())
      problem.SetManifold(block, new ceres::SubsetManifold(graph.type(v).dim, fixed));
  }
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  o.num_threads = 1;
  o.max_num_iterations = max_iterations;
  o.function_tolerance = 1e-6;
  o.gradient_tolerance = 1e-10;
  o.parameter_tolerance = 1e-8;
  o.initial_trust_region_radius = radius;
  ceres::Solver::Summary s;
  ceres::Solve(o, &problem, &s);
  graph.set_values(x);
  Result r;
  r.chi2 = graph.chi2();
  r.ms = s.total_time_in_seconds * 1e3;
  r.iterations = static_cast<int>(s.iterations.size()) - 1;
  r.termination = ceres::TerminationTypeToString(s.termination_type);
  return r;
}

Result run_planarvo(FactorGraph& graph, int max_iterations) {
  SolverOptions o;
  o.max_iterations = max_iterations;
  const SolverSummary s = graph::solve(graph, o);
  Result r;
  r.chi2 = graph.chi2();
  r.ms = s.total_time_s * 1e3;
  r.iterations = s.num_iterations;
  r.termination = to_string(s.termination);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files = {"ring.g2o",     "intel.g2o",     "manhattanOlson3500.g2o",
                                    "ringCity.g2o", "city10000.g2o", "ais2klinik.g2o"};
  std::vector<int> calibration_sizes = {1000, 10000, 100000};
  int max_iterations = 100, repeat = 3;
  double radius = 1e4;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--file") {
      files = {v};
      calibration_sizes.clear();
    } else if (a == "--calibration") {
      calibration_sizes = {std::atoi(v.c_str())};
      files.clear();
    } else if (a == "--iterations") {
      max_iterations = std::atoi(v.c_str());
    } else if (a == "--repeat") {
      repeat = std::max(1, std::atoi(v.c_str()));
    } else if (a == "--ceres-radius") {
      radius = std::atof(v.c_str());
    }
  }
  std::printf("%-24s | %14s %5s %9s %-18s | %14s %5s %9s %-14s | %7s\n", "graph", "planarvo chi2",
              "iters", "ms", "termination", "ceres chi2", "iters", "ms", "termination", "speedup");
  auto compare = [&](const std::string& name, auto make) {
    Result p, c;
    for (int r = 0; r < repeat; ++r) {  // interleaved, so both see the same machine load
      FactorGraph g1 = make();
      const Result pr = run_planarvo(g1, max_iterations);
      if (pr.ms < p.ms) p = pr;
      FactorGraph g2 = make();
      const Result cr = run_ceres(g2, max_iterations, radius);
      if (cr.ms < c.ms) c = cr;
    }
    std::printf("%-24s | %14.6f %5d %9.1f %-18s | %14.6f %5d %9.1f %-14s | %6.2fx\n", name.c_str(),
                p.chi2, p.iterations, p.ms, p.termination.c_str(), c.chi2, c.iterations, c.ms,
                c.termination.c_str(), c.ms / p.ms);
    std::fflush(stdout);
  };
  const std::string dir = std::string(PLANARVO_SHARED_DIR) + "/data/posegraphs/";
  for (const std::string& name : files) {
    const G2oFile file = read_g2o(dir + name);
    compare(name, [&] { return make_pose_graph(file); });
  }
  for (int n : calibration_sizes)
    compare("calibration " + std::to_string(n),
            [&] { return std::move(bench::make_calibration_graph(n, 7).graph); });
  return 0;
}
