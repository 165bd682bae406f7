// Benchmark: planarvo's Levenberg–Marquardt on the standard 2-D pose graphs
// (shared/data/posegraphs) and on synthetic calibration graphs (paper fig. 2). Prints:
//   1. the six files from the initial values in the file: vertices, edges, initial and final
//      χ², iterations, time, termination;
//   2. the same after rotation-first initialisation (its time listed apart);
//   3. calibration graphs of 1k/10k/100k poses: χ², iterations, time, error of z.
// Times are the best of --repeat runs (default 3), solver only (files are read beforehand).
//
//   bench_posegraph [--file NAME] [--calibration N] [--repeat N] [--verbose]
//                   [--ordering block-amd|auto|amd|metis] [--simplicial|--supernodal]
//                   [--damping marquardt|levenberg] [--lambda L] [--decrease F]
//                   [--retraction additive|rightexp] [--no-reuse] [--cg-budget F]
//                   [--cg-tolerance T] [--iterations N]
//                   [--only files|rotation|calibration]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_posegraph_synthetic.h"
#include "graph/posegraph/g2o.h"
#include "graph/posegraph/initialisation.h"
#include "graph/solver/solver.h"

using namespace planarvo;
using namespace planarvo::graph;

namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void print_header(const char* what) {
  std::printf("\n%s\n%-24s %8s %8s %16s %14s %6s %6s %9s %9s  %s\n", what, "graph", "vertices",
              "factors", "initial chi2", "final chi2", "iters", "chol", "init ms", "solve ms",
              "termination");
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files = {"ring.g2o",     "intel.g2o",     "manhattanOlson3500.g2o",
                                    "ringCity.g2o", "city10000.g2o", "ais2klinik.g2o"};
  std::vector<int> calibration_sizes = {1000, 10000, 100000};
  SolverOptions options;
  std::string only;
  bool verbose = false;
  int repeat = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--file") {
      files = {next()};
    } else if (a == "--calibration") {
      calibration_sizes = {std::atoi(next().c_str())};
    } else if (a == "--only") {
      only = next();
    } else if (a == "--ordering") {
      const std::string v = next();
      options.linear.ordering = v == "auto"    ? Ordering::Automatic
                                : v == "amd"   ? Ordering::AMD
                                : v == "metis" ? Ordering::METIS
                                               : Ordering::BlockAMD;
    } else if (a == "--supernodal") {
      options.linear.factorization = Factorization::Supernodal;
    } else if (a == "--simplicial") {
      options.linear.factorization = Factorization::Simplicial;
    } else if (a == "--damping") {
      options.damping = next() == "levenberg" ? Damping::Levenberg : Damping::Marquardt;
    } else if (a == "--lambda") {
      options.initial_lambda = std::atof(next().c_str());
    } else if (a == "--decrease") {
      options.lambda_max_decrease = std::atof(next().c_str());
    } else if (a == "--retraction") {
      options.linear.retraction =
          next() == "rightexp" ? PoseRetraction::RightExp : PoseRetraction::Additive;
    } else if (a == "--cg-budget") {
      options.reuse_cg_budget = std::atof(next().c_str());
    } else if (a == "--cg-tolerance") {
      options.reuse_cg_tolerance = std::atof(next().c_str());
    } else if (a == "--no-reuse") {
      options.reuse_factorization = false;
    } else if (a == "--iterations") {
      options.max_iterations = std::atoi(next().c_str());
    } else if (a == "--repeat") {
      repeat = std::max(1, std::atoi(next().c_str()));
    } else if (a == "--verbose") {
      verbose = true;
    } else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }

  // Runs `make` + optional initialisation + solve `repeat` times; prints the fastest run.
  auto run = [&](const std::string& name, auto make, bool rotation_first, auto extra) {
    double best_solve = 1e300, best_init = 0.0, chi0 = 0.0, chi1 = 0.0;
    SolverSummary summary;
    size_t vertices = 0, factors = 0;
    for (int r = 0; r < repeat; ++r) {
      auto problem = make();
      FactorGraph& graph = problem.graph;
      vertices = static_cast<size_t>(graph.num_variables());
      factors = static_cast<size_t>(graph.num_factors());
      const double t0 = now_s();
      if (rotation_first) initialise_rotation_first(graph);
      const double t1 = now_s();
      const double c0 = graph.chi2();
      Solver solver(options);
      const SolverSummary s = solver.solve(graph);
      if (s.total_time_s * 1e3 < best_solve) {
        best_solve = s.total_time_s * 1e3;
        best_init = (t1 - t0) * 1e3;
        summary = s;
        chi0 = c0;
        chi1 = graph.chi2();
        extra(problem);
      }
    }
    std::printf("%-24s %8zu %8zu %16.6f %14.6f %6d %6d %9.1f %9.1f  %s\n", name.c_str(), vertices,
                factors, chi0, chi1, summary.num_iterations, summary.num_factorizations,
                best_init, best_solve, to_string(summary.termination).c_str());
    if (verbose) std::printf("%s\n", summary.full_report().c_str());
    std::fflush(stdout);
  };

  const std::string dir = std::string(PLANARVO_SHARED_DIR) + "/data/posegraphs/";
  std::vector<G2oFile> loaded;
  for (const std::string& name : files) loaded.push_back(read_g2o(dir + name));
  struct FileProblem {
    FactorGraph graph;
  };
  auto nothing = [](const auto&) {};
  for (int pass = 0; pass < 2; ++pass) {
    const bool rotation = pass == 1;
    if (!only.empty() && only != (rotation ? "rotation" : "files")) continue;
    print_header(rotation ? "Pose graphs, rotation-first initialisation (init ms), then LM"
                          : "Pose graphs from the initial values in the files");
    for (size_t i = 0; i < files.size(); ++i)
      run(files[i], [&] { return FileProblem{make_pose_graph(loaded[i])}; }, rotation, nothing);
  }

  if (only.empty() || only == "calibration") {
    print_header("Calibration graphs (odometry + sensor factors, z from (0, 0, 1, 0))");
    for (int n : calibration_sizes) {
      Eigen::Vector4d error = Eigen::Vector4d::Zero();
      run("calibration " + std::to_string(n), [&] { return bench::make_calibration_graph(n, 7); },
          false, [&](const bench::SyntheticCalibration& c) {
            error = c.graph.vector(c.z) - c.truth;
          });
      std::printf("%24s z - truth: x %.2e m, y %.2e m, height %.2e m, yaw %.2e rad\n", "",
                  error[0], error[1], error[2], error[3]);
    }
  }
  return 0;
}
