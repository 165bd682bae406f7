#include "graph/solver/covariance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "core/error.h"

namespace planarvo::graph {
namespace {

// Covariances are in stored coordinates: the additive retraction's columns are exactly those.
LinearSolverOptions stored_coordinates(LinearSolverOptions o) {
  o.retraction = PoseRetraction::Additive;
  return o;
}

std::string join_names(const FactorGraph& g, const std::vector<VariableId>& vars) {
  std::string s;
  for (VariableId v : vars) s += (s.empty() ? "'" : ", '") + g.name(v) + "'";
  return s;
}

}  // namespace

MarginalCovariance::MarginalCovariance(const FactorGraph& graph, std::vector<VariableId> variables,
                                       const LinearSolverOptions& options)
    : variables_(std::move(variables)) {
  for (size_t i = 0; i < variables_.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (variables_[i] == variables_[j])
        throw_invalid_argument("MarginalCovariance: '" + graph.name(variables_[i]) + "' twice");
  NormalEquations ne(graph, stored_coordinates(options));
  ne.linearize(graph.values().data());
  if (ne.num_columns() > 0 && !ne.factorize(0.0, Damping::Marquardt))
    throw Error(ErrorCode::Failed,
                "marginal covariance: the information matrix is not positive definite at the "
                "current values, some direction is unobservable (analyse_observability names it)");
  int total = 0;
  for (VariableId v : variables_) {
    start_.push_back(total);
    dims_.push_back(graph.type(v).dim);
    total += dims_.back();
  }
  // The chosen variables' free columns: solve H X = E for exactly those.
  std::vector<int> rows, cols;  // joint_ row ↔ H column
  for (size_t k = 0; k < variables_.size(); ++k)
    for (int p = 0; p < graph.type(variables_[k]).dim; ++p) {
      const int c = ne.column(variables_[k], p);
      if (c >= 0) {
        rows.push_back(start_[k] + p);
        cols.push_back(c);
      }
    }
  joint_ = Eigen::MatrixXd::Zero(total, total);
  if (cols.empty()) return;
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(ne.num_columns(), static_cast<int>(cols.size()));
  for (size_t k = 0; k < cols.size(); ++k) E(cols[k], static_cast<int>(k)) = 1.0;
  const Eigen::MatrixXd X = ne.solve(E);
  for (size_t a = 0; a < cols.size(); ++a)
    for (size_t b = 0; b < cols.size(); ++b)
      joint_(rows[a], rows[b]) = X(cols[a], static_cast<int>(b));
  joint_ = 0.5 * (joint_ + joint_.transpose()).eval();
}

int MarginalCovariance::index_of(VariableId v) const {
  for (size_t k = 0; k < variables_.size(); ++k)
    if (variables_[k] == v) return static_cast<int>(k);
  throw_invalid_argument("MarginalCovariance: variable " + std::to_string(v) + " was not chosen");
}

Eigen::MatrixXd MarginalCovariance::block(VariableId a, VariableId b) const {
  const auto i = static_cast<size_t>(index_of(a)), j = static_cast<size_t>(index_of(b));
  return joint_.block(start_[i], start_[j], dims_[i], dims_[j]);
}

Eigen::MatrixXd MarginalCovariance::joint() const { return joint_; }

Eigen::MatrixXd marginal_covariance(const FactorGraph& graph, VariableId v,
                                    const LinearSolverOptions& options) {
  return MarginalCovariance(graph, {v}, options).covariance(v);
}

namespace {

// The observability block's free parameters: each variable's first column and each parameter's
// column in the block (-1: fixed, or not in the block), and their names.
struct BlockColumns {
  std::vector<int> start;
  std::vector<std::vector<int>> column;
  int count = 0;
};

BlockColumns block_columns(const FactorGraph& graph, const std::vector<VariableId>& block,
                           std::vector<std::string>* names) {
  BlockColumns c;
  c.start.assign(static_cast<size_t>(graph.num_variables()), -1);
  c.column.resize(static_cast<size_t>(graph.num_variables()));
  int k = 0;
  for (VariableId v : block) {
    if (c.start[static_cast<size_t>(v)] >= 0)
      throw_invalid_argument("analyse_observability: '" + graph.name(v) + "' twice");
    c.start[static_cast<size_t>(v)] = k;
    auto& lc = c.column[static_cast<size_t>(v)];
    lc.assign(static_cast<size_t>(graph.type(v).dim), -1);
    for (int p = 0; p < graph.type(v).dim; ++p)
      if (!graph.is_parameter_fixed(v, p)) {
        lc[static_cast<size_t>(p)] = k++;
        names->push_back(graph.name(v) + "." + graph.parameter_name(v, p));
      }
  }
  c.count = k;
  return c;
}

// H's block rows: H_bb (block × block) and H_ob (the other variables' columns of `others` × block),
// from the factors that touch the block.
void block_information(const FactorGraph& graph, const BlockColumns& c, const NormalEquations& others,
                       Eigen::MatrixXd& Hbb, Eigen::MatrixXd& Hob) {
  Eigen::VectorXd r;
  std::vector<Eigen::MatrixXd> J;
  for (int f = 0; f < graph.num_factors(); ++f) {
    const auto& vars = graph.factor(f).variables();
    if (std::none_of(vars.begin(), vars.end(), [&](VariableId v) { return c.start[static_cast<size_t>(v)] >= 0; }))
      continue;
    linearize_factor(graph, f, r, J);
    for (size_t a = 0; a < vars.size(); ++a) {
      const auto& la = c.column[static_cast<size_t>(vars[a])];
      if (la.empty()) continue;
      for (int pa = 0; pa < J[a].cols(); ++pa) {
        const int ca = la[static_cast<size_t>(pa)];
        if (ca < 0) continue;
        for (size_t b = 0; b < vars.size(); ++b) {
          const auto& lb = c.column[static_cast<size_t>(vars[b])];
          for (int pb = 0; pb < J[b].cols(); ++pb) {
            const double h = J[a].col(pa).dot(J[b].col(pb));
            if (!lb.empty()) {
              const int cb = lb[static_cast<size_t>(pb)];
              if (cb >= 0) Hbb(ca, cb) += h;
            } else {
              const int co = others.column(vars[b], pb);
              if (co >= 0) Hob(co, ca) += h;
            }
          }
        }
      }
    }
  }
}

// The spectrum of the block's marginal information S scaled to correlations: rank, null space
// (in the parameters' own units), condition number and the parameters the null space names.
void analyse_spectrum(const Eigen::MatrixXd& S, const Eigen::MatrixXd& Hbb, double relative_tolerance,
                      ObservabilityReport& rep) {
  const int nb = static_cast<int>(S.rows());
  // Scale to correlations. A parameter left with roundoff-sized information is unobservable
  // outright, as scaling its S_ii up to 1 would hide that: when the elimination cancelled its
  // information (S_ii at most relative_tolerance of H_bb,ii: the other variables explain all of
  // it, as for a gauge), or when it has almost none to begin with (S_ii at most
  // relative_tolerance of the largest diagonal, in SI units: a Jacobian column that is zero
  // up to rounding).
  const double max_diag = S.diagonal().maxCoeff();
  Eigen::VectorXd scale(nb);
  std::vector<char> empty(static_cast<size_t>(nb), 0);
  for (int i = 0; i < nb; ++i) {
    empty[static_cast<size_t>(i)] =
        !(S(i, i) > relative_tolerance * Hbb(i, i)) || !(S(i, i) > relative_tolerance * max_diag);
    scale[i] = empty[static_cast<size_t>(i)] ? 1.0 : 1.0 / std::sqrt(S(i, i));
  }
  Eigen::MatrixXd Sn = scale.asDiagonal() * S * scale.asDiagonal();
  for (int i = 0; i < nb; ++i)
    if (empty[static_cast<size_t>(i)]) {
      Sn.row(i).setZero();
      Sn.col(i).setZero();
    }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Sn);
  rep.eigenvalues = es.eigenvalues();
  rep.eigenvectors = es.eigenvectors();
  const double top = std::max(rep.eigenvalues.maxCoeff(), 0.0);
  std::vector<char> named(static_cast<size_t>(nb), 0);
  rep.rank = 0;
  for (int i = 0; i < nb; ++i) {
    if (top > 0.0 && rep.eigenvalues[i] > relative_tolerance * top) {
      ++rep.rank;
      continue;
    }
    const Eigen::VectorXd u = rep.eigenvectors.col(i);
    Eigen::VectorXd d = scale.asDiagonal() * u;
    rep.null_space.push_back(d.normalized());
    for (int p = 0; p < nb; ++p)
      if (std::abs(u[p]) >= 0.1) named[static_cast<size_t>(p)] = 1;
  }
  const double low = rep.eigenvalues.minCoeff();
  rep.condition_number = rep.rank == nb && low > 0.0 ? top / low : std::numeric_limits<double>::infinity();
  for (int p = 0; p < nb; ++p)
    if (named[static_cast<size_t>(p)]) rep.unobservable.push_back(rep.parameter_names[static_cast<size_t>(p)]);
}

}  // namespace

ObservabilityReport analyse_observability(const FactorGraph& graph,
                                          const std::vector<VariableId>& block,
                                          double relative_tolerance,
                                          const LinearSolverOptions& options) {
  ObservabilityReport rep;
  rep.relative_tolerance = relative_tolerance;
  const BlockColumns cols = block_columns(graph, block, &rep.parameter_names);
  const int nb = cols.count;
  if (nb == 0) throw_invalid_argument("analyse_observability: the block has no free parameter");

  NormalEquations others(graph, stored_coordinates(options), block);
  const int no = others.num_columns();
  Eigen::MatrixXd Hbb = Eigen::MatrixXd::Zero(nb, nb);
  Eigen::MatrixXd Hob = Eigen::MatrixXd::Zero(no, nb);
  block_information(graph, cols, others, Hbb, Hob);
  // The block's marginal information: the Schur complement of the other variables.
  Eigen::MatrixXd S = Hbb;
  if (no > 0) {
    others.linearize(graph.values().data());
    if (!others.factorize(0.0, Damping::Marquardt))
      throw Error(ErrorCode::Failed,
                  "analyse_observability: the other variables are not determined even with " +
                      join_names(graph, block) +
                      " known (is a gauge free? fix a pose), so the marginal information of the "
                      "block is not defined");
    S -= Hob.transpose() * others.solve(Hob);
  }
  S = 0.5 * (S + S.transpose()).eval();
  rep.information = S;
  analyse_spectrum(S, Hbb, relative_tolerance, rep);
  return rep;
}

std::string ObservabilityReport::describe() const {
  std::ostringstream s;
  s.precision(3);
  s << "rank " << rank << " of " << parameter_names.size() << ", condition " << condition_number;
  if (unobservable.empty()) return s.str();
  s << "; unobservable:";
  for (const auto& n : unobservable) s << " " << n;
  for (const Eigen::VectorXd& d : null_space) {
    s << "\n  null-space direction:";
    for (int i = 0; i < d.size(); ++i)
      if (std::abs(d[i]) >= 1e-3) s << " " << parameter_names[static_cast<size_t>(i)] << " " << d[i];
  }
  return s.str();
}

}  // namespace planarvo::graph
