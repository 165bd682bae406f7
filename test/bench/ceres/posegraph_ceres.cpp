// The peer of `planarvo posegraph` as a whole process: a standalone Ceres Solver 2.1 program that
// reads a g2o 2-D pose graph, solves it and writes the result, linked against Ceres alone (not
// planarvo), so that its start-up is Ceres's own. Used by test/bench/posegraph_vs_ceres.py.
//
// The problem is the one `planarvo posegraph` solves: g2o's error e = t2v(Z^-1 (X_i^-1 X_j)),
// whitened by the upper Cholesky factor of the information matrix, the poses (x, y, theta) as
// plain 3-vectors (additive updates, as planarvo's solver), the first vertex and FIX vertices held.
// Solver settings as bench_posegraph_ceres: Levenberg-Marquardt, SPARSE_NORMAL_CHOLESKY on
// SuiteSparse, one thread, function tolerance 1e-6, gradient 1e-10, parameter 1e-8, initial
// trust-region radius 1e4, at most 100 iterations. Jacobians by automatic differentiation, as
// Ceres's own pose_graph_2d example computes them.
//
//   posegraph_ceres IN.g2o [-o OUT.g2o] [--max-iterations N]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <ceres/ceres.h>

namespace {

struct Vertex {
  int id = 0;
  double pose[3] = {0, 0, 0};
};

struct Edge {
  int i = 0, j = 0;
  double z[3] = {0, 0, 0};
  Eigen::Matrix3d sqrt_information;
};

struct Graph {
  std::vector<Vertex> vertices;
  std::map<int, size_t> index;
  std::vector<Edge> edges;
  std::vector<int> fixed;
  std::vector<std::string> other_lines;  // EDGE and FIX lines, written back as read
};

template <typename T>
T wrap(const T& a) {
  const T two_pi = T(2.0 * M_PI);
  return a - two_pi * ceres::floor((a + T(M_PI)) / two_pi);
}

// r = L t2v(Z^-1 (X_i^-1 X_j)).
class EdgeError {
 public:
  explicit EdgeError(const Edge& e) : e_(e) {}
  template <typename T>
  bool operator()(const T* xi, const T* xj, T* r) const {
    const T ci = ceres::cos(xi[2]), si = ceres::sin(xi[2]);
    const T dx = xj[0] - xi[0], dy = xj[1] - xi[1];
    const T lx = ci * dx + si * dy, ly = -si * dx + ci * dy;  // X_i^-1 X_j, translation
    const double cz = std::cos(e_.z[2]), sz = std::sin(e_.z[2]);
    const T ex = cz * (lx - e_.z[0]) + sz * (ly - e_.z[1]);
    const T ey = -sz * (lx - e_.z[0]) + cz * (ly - e_.z[1]);
    const T et = wrap(xj[2] - xi[2] - T(e_.z[2]));
    const Eigen::Matrix3d& L = e_.sqrt_information;
    r[0] = L(0, 0) * ex + L(0, 1) * ey + L(0, 2) * et;
    r[1] = L(1, 1) * ey + L(1, 2) * et;
    r[2] = L(2, 2) * et;
    return true;
  }

 private:
  Edge e_;
};

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "posegraph_ceres: %s\n", message.c_str());
  std::exit(2);
}

Graph read_g2o(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path + ": cannot open");
  Graph g;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::istringstream s(line);
    std::string tag;
    if (!(s >> tag) || tag[0] == '#') continue;
    if (tag == "VERTEX_SE2") {
      Vertex v;
      if (!(s >> v.id >> v.pose[0] >> v.pose[1] >> v.pose[2])) fail(path + ":" + std::to_string(n) + ": bad vertex");
      g.index[v.id] = g.vertices.size();
      g.vertices.push_back(v);
    } else if (tag == "EDGE_SE2") {
      Edge e;
      double u[6];
      if (!(s >> e.i >> e.j >> e.z[0] >> e.z[1] >> e.z[2] >> u[0] >> u[1] >> u[2] >> u[3] >> u[4] >> u[5]))
        fail(path + ":" + std::to_string(n) + ": bad edge");
      Eigen::Matrix3d omega;
      omega << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
      // Upper L with L' L = Omega: the transposed lower Cholesky factor.
      e.sqrt_information = Eigen::LLT<Eigen::Matrix3d>(omega).matrixU();
      g.edges.push_back(e);
      g.other_lines.push_back(line);
    } else if (tag == "FIX") {
      int id = 0;
      s >> id;
      g.fixed.push_back(id);
      g.other_lines.push_back(line);
    }
  }
  if (g.vertices.empty()) fail(path + ": no VERTEX_SE2 lines");
  return g;
}

double chi2(const Graph& g) {
  double sum = 0;
  for (const Edge& e : g.edges) {
    double r[3];
    const EdgeError error(e);
    error(g.vertices[g.index.at(e.i)].pose, g.vertices[g.index.at(e.j)].pose, r);
    sum += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  }
  return sum;
}

void write_g2o(const std::string& path, const Graph& g) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) fail(path + ": cannot write");
  for (const Vertex& v : g.vertices)
    std::fprintf(f, "VERTEX_SE2 %d %.17g %.17g %.17g\n", v.id, v.pose[0], v.pose[1], wrap(v.pose[2]));
  for (const std::string& l : g.other_lines) std::fprintf(f, "%s\n", l.c_str());
  if (std::fclose(f) != 0) fail(path + ": write failed");
}

}  // namespace

int main(int argc, char** argv) {
  std::string in, out;
  int max_iterations = 100;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if ((arg == "-o" || arg == "--output") && a + 1 < argc) out = argv[++a];
    else if (arg == "--max-iterations" && a + 1 < argc) max_iterations = std::atoi(argv[++a]);
    else if (in.empty() && arg[0] != '-') in = arg;
    else fail("usage: posegraph_ceres IN.g2o [-o OUT.g2o] [--max-iterations N]");
  }
  if (in.empty()) fail("usage: posegraph_ceres IN.g2o [-o OUT.g2o] [--max-iterations N]");
  Graph g = read_g2o(in);
  const double chi2_0 = chi2(g);

  ceres::Problem problem;
  for (const Edge& e : g.edges) {
    auto* cost = new ceres::AutoDiffCostFunction<EdgeError, 3, 3, 3>(new EdgeError(e));
    problem.AddResidualBlock(cost, nullptr, g.vertices[g.index.at(e.i)].pose, g.vertices[g.index.at(e.j)].pose);
  }
  std::vector<int> held = g.fixed;
  held.push_back(g.vertices.front().id);
  for (int id : held) {
    double* block = g.vertices[g.index.at(id)].pose;
    if (problem.HasParameterBlock(block)) problem.SetParameterBlockConstant(block);
  }
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  o.num_threads = 1;
  o.max_num_iterations = max_iterations;
  o.function_tolerance = 1e-6;
  o.gradient_tolerance = 1e-10;
  o.parameter_tolerance = 1e-8;
  o.initial_trust_region_radius = 1e4;
  ceres::Solver::Summary s;
  ceres::Solve(o, &problem, &s);
  std::printf("%s: chi2 %.6f -> %.6f in %d iterations, %.3f s\n", in.c_str(), chi2_0, chi2(g),
              static_cast<int>(s.iterations.size()) - 1, s.total_time_in_seconds);
  std::printf("termination: %s\n", ceres::TerminationTypeToString(s.termination_type));
  if (!out.empty()) write_g2o(out, g);
  return s.termination_type == ceres::CONVERGENCE ? 0 : 1;
}
