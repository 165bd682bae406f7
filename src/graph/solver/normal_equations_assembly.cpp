// NormalEquations (normal_equations.h), assembly: each factor's whitened, robust-weighted error
// and Jacobians (linearize_factor for one factor, linearize() for all), the cost at trial
// points, and J̃ᵀJ̃ and J̃ᵀr̃ added block by block into H's fixed pattern and g.
#include "graph/solver/normal_equations.h"

#include <cmath>
#include <cstring>

#include <cholmod.h>

#include "graph/solver/normal_equations_internal.h"

namespace planarvo::graph {

using normal_equations_detail::Clock;
using normal_equations_detail::seconds_since;

namespace {

// In-place X ← L·X for an upper-triangular m × m L (column-major) and an m × n X: row i of the
// product needs rows i..m-1 of X, so ascending rows never read an overwritten one.
void upper_times_in_place(const double* L, int m, double* X, int n) {
  for (int c = 0; c < n; ++c) {
    double* x = X + c * m;
    for (int i = 0; i < m; ++i) {
      double s = 0.0;
      for (int j = i; j < m; ++j) s += L[i + j * m] * x[j];
      x[i] = s;
    }
  }
}

// J ← J · diag(R(θ), 1) for the RightExp retraction: d(X·exp(δ))/dδ at 0 is diag(R(θ), 1).
void right_exp_jacobian(double c, double s, double* J, int m) {
  double* j0 = J;
  double* j1 = J + m;
  for (int i = 0; i < m; ++i) {
    const double a = j0[i], b = j1[i];
    j0[i] = c * a + s * b;
    j1[i] = -s * a + c * b;
  }
}

// Σ_t a[t]·b[t] over M rows (M = 0: m rows, known at run time only).
template <int M>
inline double dot_rows(const double* a, const double* b, int m) {
  double s = 0.0;
  if constexpr (M > 0) {
    for (int t = 0; t < M; ++t) s += a[t] * b[t];
  } else {
    for (int t = 0; t < m; ++t) s += a[t] * b[t];
  }
  return s;
}

}  // namespace

double linearize_factor(const FactorGraph& graph, int f, Eigen::VectorXd& residual,
                        std::vector<Eigen::MatrixXd>& jacobians) {
  const Factor& fac = graph.factor(f);
  const auto& vars = fac.variables();
  const int m = fac.residual_dim();
  std::vector<const double*> ptrs;
  std::vector<double*> jptrs;
  jacobians.resize(vars.size());
  for (size_t k = 0; k < vars.size(); ++k) {
    ptrs.push_back(&graph.values()[static_cast<size_t>(graph.offset(vars[k]))]);
    jacobians[k].resize(m, fac.types()[k].dim);
    jptrs.push_back(jacobians[k].data());
  }
  Eigen::VectorXd e(m);
  Eigen::MatrixXd L(m, m);
  fac.evaluate(ptrs.data(), e.data(), jptrs.data());
  fac.sqrt_information_at(ptrs.data(), L.data());
  const Eigen::MatrixXd Lu = L.triangularView<Eigen::Upper>();
  residual = Lu * e;
  for (auto& J : jacobians) J = Lu * J;
  const double s = residual.squaredNorm();
  const RobustKernel* kernel = graph.robust_kernel(f);
  if (!kernel) return s;
  double rho[3];
  kernel->evaluate(s, rho);
  const double w = std::sqrt(rho[1]);
  residual *= w;
  for (auto& J : jacobians) J *= w;
  return rho[0];
}

double NormalEquations::evaluate_cost(const double* values, PhaseTimes* times) {
  const auto t0 = Clock::now();
  double cost = 0.0;
  for (const FactorInfo& info : factors_) {
    const int m = info.residual_dim;
    for (int k = 0; k < info.num_slots; ++k)
      ptr_scratch_[static_cast<size_t>(k)] =
          values + slot_value_offset_[static_cast<size_t>(info.slot_begin + k)];
    double* e = e_scratch_.data();
    info.factor->evaluate(ptr_scratch_.data(), e, nullptr);
    const double* L = info.sqrt_info;
    if (!L) {
      info.factor->sqrt_information_at(ptr_scratch_.data(), sqrt_info_scratch_.data());
      L = sqrt_info_scratch_.data();
    }
    double s = 0.0;
    for (int i = 0; i < m; ++i) {
      double ri = 0.0;
      for (int j = i; j < m; ++j) ri += L[i + j * m] * e[j];
      s += ri * ri;
    }
    if (info.kernel) {
      double rho[3];
      info.kernel->evaluate(s, rho);
      s = rho[0];
    }
    cost += s;
  }
  if (times) times->evaluate += seconds_since(t0);
  return cost;
}

bool NormalEquations::linearize_factor_into(int f, const double* values, double& cost) {
  const FactorInfo& info = factors_[static_cast<size_t>(f)];
  const int m = info.residual_dim;
  bool any_free = false;
  for (int k = 0; k < info.num_slots; ++k) {
    const auto s = static_cast<size_t>(info.slot_begin + k);
    ptr_scratch_[static_cast<size_t>(k)] = values + slot_value_offset_[s];
    const int jo = slot_jac_offset_[s];
    jac_ptr_scratch_[static_cast<size_t>(k)] = jo >= 0 ? jac_.data() + jo : nullptr;
    any_free |= jo >= 0;
  }
  double* e = e_scratch_.data();
  info.factor->evaluate(ptr_scratch_.data(), e, any_free ? jac_ptr_scratch_.data() : nullptr);
  const double* L = info.sqrt_info;
  if (!L) {
    info.factor->sqrt_information_at(ptr_scratch_.data(), sqrt_info_scratch_.data());
    L = sqrt_info_scratch_.data();
  }
  upper_times_in_place(L, m, e, 1);
  double s = 0.0;
  for (int i = 0; i < m; ++i) s += e[i] * e[i];
  double w = 1.0;
  if (info.kernel) {
    double rho[3];
    info.kernel->evaluate(s, rho);
    cost += rho[0];
    w = std::sqrt(rho[1]);
    for (int i = 0; i < m; ++i) e[i] *= w;
  } else {
    cost += s;
  }
  if (!any_free) return false;
  const auto& types = info.factor->types();
  for (int k = 0; k < info.num_slots; ++k) {
    double* J = jac_ptr_scratch_[static_cast<size_t>(k)];
    if (!J) continue;
    const int d = types[static_cast<size_t>(k)].dim;
    upper_times_in_place(L, m, J, d);
    if (w != 1.0)
      for (int i = 0; i < m * d; ++i) J[i] *= w;
    const auto sk = static_cast<size_t>(info.slot_begin + k);
    if (slot_body_frame_[sk]) {
      const double* cs = &rotation_[2 * static_cast<size_t>(slot_var_[sk])];
      right_exp_jacobian(cs[0], cs[1], J, m);
    }
  }
  return true;
}

template <int M>
void NormalEquations::accumulate_factor(const FactorInfo& info) {
  double* Hx = static_cast<double*>(H_->x);
  const int* Hp = static_cast<const int*>(H_->p);
  double* g = g_.data();
  const int m = info.residual_dim;
  const double* r = e_scratch_.data();
  int pair = info.pair_begin;
  for (int k = 0; k < info.num_slots; ++k) {
    const auto sk = static_cast<size_t>(info.slot_begin + k);
    const int jk = slot_jac_offset_[sk];
    if (jk < 0) {
      pair += info.num_slots - k;
      continue;
    }
    const auto a = static_cast<size_t>(slot_var_[sk]);
    const double* Ja = jac_.data() + jk;
    const int fa = num_free_[a];
    const int ca = col_start_[a];
    const int* pa = free_params_.data() + free_begin_[a];
    for (int i = 0; i < fa; ++i) g[ca + i] += dot_rows<M>(Ja + pa[i] * m, r, m);
    // Diagonal block: the upper triangle of J_aᵀJ_a.
    {
      const int off = pair_offset_[static_cast<size_t>(pair++)];
      for (int j = 0; j < fa; ++j) {
        double* out = Hx + Hp[ca + j] + off;
        const double* cj = Ja + pa[j] * m;
        for (int i = 0; i <= j; ++i) out[i] += dot_rows<M>(Ja + pa[i] * m, cj, m);
      }
    }
    for (int l = k + 1; l < info.num_slots; ++l) {
      const int off = pair_offset_[static_cast<size_t>(pair++)];
      if (off < 0) continue;
      const auto sl = static_cast<size_t>(info.slot_begin + l);
      const auto b = static_cast<size_t>(slot_var_[sl]);
      const double* Jb = jac_.data() + slot_jac_offset_[sl];
      // Rows of the variable with the earlier columns, columns of the other.
      const bool a_is_row = ca < col_start_[b];
      const auto row_var = a_is_row ? a : b;
      const auto col_var = a_is_row ? b : a;
      const double* Jr = a_is_row ? Ja : Jb;
      const double* Jc = a_is_row ? Jb : Ja;
      const int fr = num_free_[row_var], fc = num_free_[col_var];
      const int* pr = free_params_.data() + free_begin_[row_var];
      const int* pc = free_params_.data() + free_begin_[col_var];
      const int cc = col_start_[col_var];
      for (int j = 0; j < fc; ++j) {
        double* out = Hx + Hp[cc + j] + off;
        const double* cj = Jc + pc[j] * m;
        for (int i = 0; i < fr; ++i) out[i] += dot_rows<M>(Jr + pr[i] * m, cj, m);
      }
    }
  }
}

double NormalEquations::linearize(const double* values, PhaseTimes* times) {
  const auto t0 = Clock::now();
  // cos, sin of each body-frame pose's heading, once per pose rather than once per factor.
  for (size_t v = 0; v < body_frame_.size(); ++v)
    if (body_frame_[v]) {
      const double theta = values[var_offset_[v] + 2];
      rotation_[2 * v] = std::cos(theta);
      rotation_[2 * v + 1] = std::sin(theta);
    }
  double* Hx = static_cast<double*>(H_ ? H_->x : nullptr);
  if (H_) std::memset(Hx, 0, static_cast<size_t>(static_cast<const int*>(H_->p)[n_]) * sizeof(double));
  g_.setZero();
  // Factor by factor: its error and Jacobians, then at once its blocks into H and g, while they
  // are in cache (no whole-graph Jacobian is stored).
  double cost = 0.0;
  const int nf = static_cast<int>(factors_.size());
  for (int f = 0; f < nf; ++f) {
    if (!linearize_factor_into(f, values, cost)) continue;
    const FactorInfo& info = factors_[static_cast<size_t>(f)];
    switch (info.residual_dim) {  // fixed-size dot products for the common residual sizes
      case 1: accumulate_factor<1>(info); break;
      case 2: accumulate_factor<2>(info); break;
      case 3: accumulate_factor<3>(info); break;
      default: accumulate_factor<0>(info); break;
    }
  }
  for (int c = 0; c < n_; ++c) h_diag_[c] = Hx[diag_pos_[static_cast<size_t>(c)]];
  if (times) times->linearize += seconds_since(t0);
  return cost;
}

Eigen::MatrixXd NormalEquations::dense_hessian() const {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n_, n_);
  if (n_ == 0) return H;
  const int* Hp = static_cast<const int*>(H_->p);
  const int* Hi = static_cast<const int*>(H_->i);
  const double* Hx = static_cast<const double*>(H_->x);
  for (int c = 0; c < n_; ++c)
    for (int p = Hp[c]; p < Hp[c + 1]; ++p) {
      H(Hi[p], c) = Hx[p];
      H(c, Hi[p]) = Hx[p];
    }
  H.diagonal() = h_diag_;
  return H;
}

}  // namespace planarvo::graph
