// The whole pose-graph workflow behind `planarvo posegraph` and planarvo_posegraph_optimize: a
// g2o file read (g2o.h), checked, initialised (initialisation.h), optimised by the sparse
// Levenberg–Marquardt solver (solver/solver.h) and written back.
#pragma once
#include <functional>
#include <string>

#include "graph/solver/solver.h"

namespace planarvo::graph {

struct PosegraphOptions {
  int max_iterations = 100;     // > 0
  bool rotation_first = false;  // initialise_rotation_first before solving
  // Receives the solver's report (SolverSummary::full_report) once it has solved; none: not made.
  std::function<void(const std::string& report)> log;
};

struct PosegraphResult {
  SolverSummary summary;
  double initial_chi2 = 0.0;  // at the file's poses
  double final_chi2 = 0.0;
};

// Optimises the graph of `in_path` (the first vertex held fixed, g2o's error convention) and writes
// it to `out_path` (empty: not written; written also when the solver did not converge, so that the
// graph it reached can be looked at). Throws InvalidInput naming the file for a file without
// vertices or with an edge whose error overflows double arithmetic at the file's poses (naming the
// edge), InvalidArgument for options out of range.
PosegraphResult optimize_g2o(const std::string& in_path, const std::string& out_path, const PosegraphOptions& options);

}  // namespace planarvo::graph
