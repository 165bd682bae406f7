#include "graph/posegraph/initialisation.h"

#include <cmath>
#include <deque>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include "core/error.h"
#include "graph/posegraph/factors.h"

namespace planarvo::graph {
namespace {

struct Edge {
  int i, j;  // pose variables
  SE2 z;
  Eigen::Matrix3d information;
};

struct Tree {
  std::vector<int> anchors;
  std::vector<int> order;         // variables in BFS order (anchors first)
  std::vector<int> parent_edge;   // edge that reached the variable, −1 for anchors / unreached
  std::vector<char> reached;
};

std::vector<Edge> relative_pose_edges(const FactorGraph& graph) {
  std::vector<Edge> edges;
  for (int f = 0; f < graph.num_factors(); ++f)
    if (const auto* r = dynamic_cast<const RelativePoseFactor*>(&graph.factor(f)))
      edges.push_back({r->variables()[0], r->variables()[1], r->measurement(),
                       r->information()});
  return edges;
}

Tree spanning_tree(const FactorGraph& graph, const std::vector<Edge>& edges) {
  const int n = graph.num_variables();
  std::vector<std::vector<int>> adj(static_cast<size_t>(n));
  for (size_t e = 0; e < edges.size(); ++e) {
    adj[static_cast<size_t>(edges[e].i)].push_back(static_cast<int>(e));
    adj[static_cast<size_t>(edges[e].j)].push_back(static_cast<int>(e));
  }
  Tree t;
  t.parent_edge.assign(static_cast<size_t>(n), -1);
  t.reached.assign(static_cast<size_t>(n), 0);
  std::deque<int> queue;
  auto seed = [&](int v) {
    t.reached[static_cast<size_t>(v)] = 1;
    t.anchors.push_back(v);
    queue.push_back(v);
  };
  auto search = [&]() {
    while (!queue.empty()) {
      const int v = queue.front();
      queue.pop_front();
      t.order.push_back(v);
      for (int e : adj[static_cast<size_t>(v)]) {
        const Edge& edge = edges[static_cast<size_t>(e)];
        const int u = edge.i == v ? edge.j : edge.i;
        if (t.reached[static_cast<size_t>(u)] || graph.is_fixed(u)) continue;
        t.reached[static_cast<size_t>(u)] = 1;
        t.parent_edge[static_cast<size_t>(u)] = e;
        queue.push_back(u);
      }
    }
  };
  // One search seeded with all fixed poses, then one from the first pose of each part left.
  for (int v = 0; v < n; ++v)
    if (graph.type(v).kind == VariableKind::Pose2 && graph.is_fixed(v)) seed(v);
  search();
  for (int v = 0; v < n; ++v)
    if (graph.type(v).kind == VariableKind::Pose2 && !t.reached[static_cast<size_t>(v)] &&
        !adj[static_cast<size_t>(v)].empty()) {
      seed(v);
      search();
    }
  return t;
}

// The pose of `child` from its parent's through edge e.
SE2 chain(const Edge& e, int child, const SE2& parent) {
  return child == e.j ? parent * e.z : parent * e.z.inverse();
}

}  // namespace

void initialise_spanning_tree(FactorGraph& graph) {
  const std::vector<Edge> edges = relative_pose_edges(graph);
  const Tree t = spanning_tree(graph, edges);
  for (int v : t.order) {
    const int e = t.parent_edge[static_cast<size_t>(v)];
    if (e < 0) continue;
    const Edge& edge = edges[static_cast<size_t>(e)];
    const int parent = edge.i == v ? edge.j : edge.i;
    graph.set_pose(v, chain(edge, v, graph.pose(parent)));
  }
}

namespace {

// What the two linear least-squares problems of the rotation-first initialisation share: the
// relative-pose edges, the spanning tree, the index of each unknown pose (reached, not an
// anchor; -1 otherwise), and the edges' orientation weights.
struct RotationFirst {
  std::vector<Edge> edges;
  Tree t;
  std::vector<int> unknown;
  int m = 0, n = 0;
  std::vector<double> w_theta;
};

// The orientations' least squares θ_j − θ_i = z + 2πk over the edges, the wraps k from the
// angles `wraps_from` (known poses keep theirs).
std::vector<double> solve_orientations(const RotationFirst& r, const std::vector<double>& wraps_from) {
  const std::vector<Edge>& edges = r.edges;
  const Tree& t = r.t;
  const std::vector<int>& unknown = r.unknown;
  const std::vector<double>& w_theta = r.w_theta;
  const int m = r.m, n = r.n;
    // θ_j − θ_i = z + 2πk, with k from wraps_from.
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m);
  for (size_t e = 0; e < edges.size(); ++e) {
    const Edge& ed = edges[e];
    const int ui = unknown[static_cast<size_t>(ed.i)], uj = unknown[static_cast<size_t>(ed.j)];
    if (!t.reached[static_cast<size_t>(ed.i)] || !t.reached[static_cast<size_t>(ed.j)]) continue;
    const double k = std::round((wraps_from[static_cast<size_t>(ed.j)] -
                                 wraps_from[static_cast<size_t>(ed.i)] - ed.z.theta) /
                                (2.0 * M_PI));
    const double d = ed.z.theta + 2.0 * M_PI * k;
    const double w = w_theta[e];
    // residual θ_j − θ_i − d
    if (uj >= 0) {
      trip.emplace_back(uj, uj, w);
      rhs[uj] += w * (d + (ui < 0 ? wraps_from[static_cast<size_t>(ed.i)] : 0.0));
    }
    if (ui >= 0) {
      trip.emplace_back(ui, ui, w);
      rhs[ui] -= w * (d - (uj < 0 ? wraps_from[static_cast<size_t>(ed.j)] : 0.0));
    }
    if (ui >= 0 && uj >= 0) {
      trip.emplace_back(ui, uj, -w);
      trip.emplace_back(uj, ui, -w);
    }
  }
  Eigen::SparseMatrix<double> A(m, m);
  A.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
  if (ldlt.info() != Eigen::Success)
    throw Error(ErrorCode::Failed, "initialise_rotation_first: the orientation system is singular");
  const Eigen::VectorXd x = ldlt.solve(rhs);
  std::vector<double> out = wraps_from;
  for (int v = 0; v < n; ++v)
    if (unknown[static_cast<size_t>(v)] >= 0) out[static_cast<size_t>(v)] = x[unknown[static_cast<size_t>(v)]];
  return out;
  }

// The positions' least squares given the orientations `solved`: t_j − t_i = R(θ_i) z_t.
void solve_positions(const RotationFirst& problem, const std::vector<double>& solved, FactorGraph& graph) {
  const std::vector<Edge>& edges = problem.edges;
  const Tree& t = problem.t;
  const std::vector<int>& unknown = problem.unknown;
  const int m = problem.m, n = problem.n;
  // Positions: t_j − t_i = R(θ_i) z_t, weight (R(θ_i + z_θ)) Ω_tt (…)ᵀ.
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * m);
  for (const Edge& ed : edges) {
    if (!t.reached[static_cast<size_t>(ed.i)] || !t.reached[static_cast<size_t>(ed.j)]) continue;
    const int ui = unknown[static_cast<size_t>(ed.i)], uj = unknown[static_cast<size_t>(ed.j)];
    const double ti = solved[static_cast<size_t>(ed.i)];
    const Eigen::Matrix2d Ri = Eigen::Rotation2Dd(ti).toRotationMatrix();
    const Eigen::Matrix2d M = Eigen::Rotation2Dd(ti + ed.z.theta).toRotationMatrix();
    const Eigen::Matrix2d W = M * ed.information.topLeftCorner<2, 2>() * M.transpose();
    Eigen::Vector2d d = Ri * Eigen::Vector2d(ed.z.x, ed.z.y);
    // residual t_j − t_i − d
    if (ui < 0) d += Eigen::Vector2d(graph.pose(ed.i).x, graph.pose(ed.i).y);
    if (uj < 0) d -= Eigen::Vector2d(graph.pose(ed.j).x, graph.pose(ed.j).y);
    const Eigen::Vector2d wd = W * d;
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c) {
        if (uj >= 0) trip.emplace_back(2 * uj + r, 2 * uj + c, W(r, c));
        if (ui >= 0) trip.emplace_back(2 * ui + r, 2 * ui + c, W(r, c));
        if (ui >= 0 && uj >= 0) {
          trip.emplace_back(2 * ui + r, 2 * uj + c, -W(r, c));
          trip.emplace_back(2 * uj + r, 2 * ui + c, -W(r, c));
        }
      }
    if (uj >= 0) rhs.segment<2>(2 * uj) += wd;
    if (ui >= 0) rhs.segment<2>(2 * ui) -= wd;
  }
  Eigen::SparseMatrix<double> A(2 * m, 2 * m);
  A.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
  if (ldlt.info() != Eigen::Success)
    throw Error(ErrorCode::Failed, "initialise_rotation_first: the position system is singular");
  const Eigen::VectorXd p = ldlt.solve(rhs);
  for (int v = 0; v < n; ++v) {
    const int u = unknown[static_cast<size_t>(v)];
    if (u >= 0) graph.set_pose(v, SE2(p[2 * u], p[2 * u + 1], solved[static_cast<size_t>(v)]));
  }
}

}  // namespace

int initialise_rotation_first(FactorGraph& graph) {
  RotationFirst r;
  r.edges = relative_pose_edges(graph);
  r.t = spanning_tree(graph, r.edges);
  r.n = graph.num_variables();
  const std::vector<Edge>& edges = r.edges;
  const Tree& t = r.t;
  const int n = r.n;

  // Unknowns: reached, non-anchor poses.
  r.unknown.assign(static_cast<size_t>(n), -1);
  std::vector<char> is_anchor(static_cast<size_t>(n), 0);
  for (int a : t.anchors) is_anchor[static_cast<size_t>(a)] = 1;
  for (int v : t.order)
    if (!is_anchor[static_cast<size_t>(v)]) r.unknown[static_cast<size_t>(v)] = r.m++;
  if (r.m == 0) return 0;

  // Spanning-tree orientations, not wrapped (the wraps k_ij are what they decide).
  std::vector<double> theta(static_cast<size_t>(n), 0.0);
  for (int v = 0; v < n; ++v)
    if (graph.type(v).kind == VariableKind::Pose2) theta[static_cast<size_t>(v)] = graph.pose(v).theta;
  for (int v : t.order) {
    const int e = t.parent_edge[static_cast<size_t>(v)];
    if (e < 0) continue;
    const Edge& edge = edges[static_cast<size_t>(e)];
    theta[static_cast<size_t>(v)] = edge.j == v ? theta[static_cast<size_t>(edge.i)] + edge.z.theta
                                                : theta[static_cast<size_t>(edge.j)] - edge.z.theta;
  }

  // Orientation weights: the inverse marginal variance of the measured angle.
  r.w_theta.resize(edges.size());
  for (size_t e = 0; e < edges.size(); ++e)
    r.w_theta[e] = 1.0 / edges[e].information.inverse()(2, 2);

  std::vector<double> solved = solve_orientations(r, theta);
  // Re-estimate the wraps from the least-squares orientations (the tree's chained angles drift
  // along long branches; the solution spreads loop errors) and solve again.
  int changed = 0;
  for (const Edge& ed : edges) {
    if (!t.reached[static_cast<size_t>(ed.i)] || !t.reached[static_cast<size_t>(ed.j)]) continue;
    const double k0 = std::round((theta[static_cast<size_t>(ed.j)] - theta[static_cast<size_t>(ed.i)] - ed.z.theta) / (2.0 * M_PI));
    const double k1 = std::round((solved[static_cast<size_t>(ed.j)] - solved[static_cast<size_t>(ed.i)] - ed.z.theta) / (2.0 * M_PI));
    changed += k0 != k1;
  }
  if (changed > 0) solved = solve_orientations(r, solved);

  solve_positions(r, solved, graph);
  return changed;
}

}  // namespace planarvo::graph
