#include "graph/posegraph/optimize.h"

#include <cmath>

#include "core/error.h"
#include "graph/posegraph/g2o.h"
#include "graph/posegraph/initialisation.h"

namespace planarvo::graph {
namespace {

// Every number in the file is finite (the reader checks), but an edge's error at the file's poses,
// or its information, can still be too large for double arithmetic: eᵀΩe overflows, and nothing
// measured from such a graph means anything. Bad input, naming the edge.
void check_finite_errors(const std::string& path, const G2oFile& file, const FactorGraph& graph, double chi2) {
  if (std::isfinite(chi2)) return;
  const int k = graph.first_nonfinite_factor();
  std::string where = "the sum of the edges' errors";
  if (k >= 0) {
    const G2oEdge& e = file.edges.at(static_cast<size_t>(k));
    where = "the error of EDGE_SE2 " + std::to_string(e.from) + " " + std::to_string(e.to);
  }
  throw_invalid_input(path + ": " + where +
                      " at the file's poses overflows double arithmetic (eᵀΩe is not finite): a pose, "
                      "measurement or information value is far too large");
}

}  // namespace

PosegraphResult optimize_g2o(const std::string& in_path, const std::string& out_path, const PosegraphOptions& options) {
  if (options.max_iterations <= 0) throw_invalid_argument("pose graph: max_iterations must be positive");
  G2oFile file = read_g2o(in_path);
  if (file.vertices.empty()) throw_invalid_input(in_path + ": no VERTEX_SE2 lines");
  FactorGraph graph = make_pose_graph(file);
  PosegraphResult result;
  result.initial_chi2 = graph.chi2();
  check_finite_errors(in_path, file, graph, result.initial_chi2);
  if (options.rotation_first) initialise_rotation_first(graph);
  SolverOptions so;
  so.max_iterations = options.max_iterations;
  Solver solver(so);
  result.summary = solver.solve(graph);
  if (options.log) options.log(result.summary.full_report());
  result.final_chi2 = graph.chi2();
  if (!out_path.empty()) {
    update_poses(file, graph);
    write_g2o(out_path, file);
  }
  return result;
}

}  // namespace planarvo::graph
