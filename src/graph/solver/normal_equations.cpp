// NormalEquations (normal_equations.h), the system's layout: construction, the free parameters'
// columns, H's CSC pattern with the factors' block offsets, and steps on the values (retract).
// Filling H and g is in normal_equations_assembly.cpp; the ordering, the factorisation and the
// solves in normal_equations_cholesky.cpp.
#include "graph/solver/normal_equations.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <cholmod.h>

#include "core/error.h"
#include "graph/solver/normal_equations_internal.h"

namespace planarvo::graph {

using normal_equations_detail::Clock;
using normal_equations_detail::seconds_since;

NormalEquations::NormalEquations(const FactorGraph& graph, const LinearSolverOptions& options,
                                 const std::vector<VariableId>& also_fixed)
    : options_(options), version_(graph.structure_version()) {
  const auto t0 = Clock::now();
  cc_ = new cholmod_common;
  cholmod_start(cc_);
  cc_->print = 0;
  cc_->error_handler = nullptr;
  cc_->quick_return_if_not_posdef = 1;
  cc_->supernodal = options_.factorization == Factorization::Supernodal   ? CHOLMOD_SUPERNODAL
                    : options_.factorization == Factorization::Simplicial ? CHOLMOD_SIMPLICIAL
                                                                          : CHOLMOD_AUTO;
  cc_->supernodal_switch = options_.supernodal_switch;
  try {
    build_pattern(graph, also_fixed);
    analyze();
  } catch (...) {
    release();
    throw;
  }
  analyze_seconds_ = seconds_since(t0);
}

NormalEquations::~NormalEquations() { release(); }

void NormalEquations::release() {
  if (!cc_) return;
  if (L_) cholmod_free_factor(&L_, cc_);
  if (H_) cholmod_free_sparse(&H_, cc_);
  if (B_) cholmod_free_dense(&B_, cc_);
  if (X_) cholmod_free_dense(&X_, cc_);
  if (Y_) cholmod_free_dense(&Y_, cc_);
  if (E_) cholmod_free_dense(&E_, cc_);
  cholmod_finish(cc_);
  delete cc_;
  cc_ = nullptr;
}

bool NormalEquations::matches(const FactorGraph& graph) const {
  return graph.structure_version() == version_;
}

int NormalEquations::column(VariableId v, int parameter) const {
  if (v < 0 || v >= static_cast<int>(col_start_.size())) return -1;
  const int* fp = free_params_.data() + free_begin_[static_cast<size_t>(v)];
  for (int i = 0; i < num_free_[static_cast<size_t>(v)]; ++i)
    if (fp[i] == parameter) return col_start_[static_cast<size_t>(v)] + i;
  return -1;
}

void NormalEquations::build_pattern(const FactorGraph& graph,
                                    const std::vector<VariableId>& also_fixed) {
  const int nv = graph.num_variables();
  std::vector<char> forced(static_cast<size_t>(nv), 0);
  for (VariableId v : also_fixed) {
    if (v < 0 || v >= nv) throw_invalid_argument("NormalEquations: no variable " + std::to_string(v));
    forced[static_cast<size_t>(v)] = 1;
  }
  var_type_.resize(static_cast<size_t>(nv));
  var_offset_.resize(static_cast<size_t>(nv));
  for (VariableId v = 0; v < nv; ++v) {
    var_type_[static_cast<size_t>(v)] = graph.type(v);
    var_offset_[static_cast<size_t>(v)] = graph.offset(v);
  }
  body_frame_.assign(static_cast<size_t>(nv), 0);
  rotation_.assign(2 * static_cast<size_t>(nv), 0.0);
  num_free_.assign(static_cast<size_t>(nv), 0);
  free_begin_.assign(static_cast<size_t>(nv), 0);
  free_params_.clear();
  n_ = 0;
  for (VariableId v = 0; v < nv; ++v) {
    const auto sv = static_cast<size_t>(v);
    const VariableType type = graph.type(v);
    const std::uint64_t mask = forced[sv] ? ~std::uint64_t{0} : graph.fixed_mask(v);
    free_begin_[sv] = static_cast<int>(free_params_.size());
    body_frame_[sv] = options_.retraction == PoseRetraction::RightExp &&
                      type.kind == VariableKind::Pose2 && mask == 0;
    for (int p = 0; p < type.dim; ++p)
      if (!((mask >> p) & 1u)) free_params_.push_back(p);
    num_free_[sv] = static_cast<int>(free_params_.size()) - free_begin_[sv];
    n_ += num_free_[sv];
  }

  // Factors as slots, and the variable graph: free variables sharing a factor.
  adjacency_.assign(static_cast<size_t>(nv), {});
  const int nf = graph.num_factors();
  factors_.clear();
  factors_.reserve(static_cast<size_t>(nf));
  slot_var_.clear();
  slot_value_offset_.clear();
  slot_jac_offset_.clear();
  slot_body_frame_.clear();
  int max_jac = 0, max_m = 0, max_slots = 0;
  for (int f = 0; f < nf; ++f) {
    const Factor& fac = graph.factor(f);
    const auto& vars = fac.variables();
    FactorInfo info{};
    info.factor = &fac;
    info.kernel = graph.robust_kernel(f);
    info.sqrt_info = fac.information_depends_on_state() ? nullptr : fac.sqrt_information().data();
    info.residual_dim = fac.residual_dim();
    info.slot_begin = static_cast<int>(slot_var_.size());
    info.num_slots = static_cast<int>(vars.size());
    int jac_total = 0;
    for (size_t k = 0; k < vars.size(); ++k) {
      const auto v = static_cast<size_t>(vars[k]);
      slot_var_.push_back(vars[k]);
      slot_value_offset_.push_back(graph.offset(vars[k]));
      slot_body_frame_.push_back(body_frame_[v]);
      if (num_free_[v] > 0) {
        slot_jac_offset_.push_back(jac_total);
        jac_total += info.residual_dim * fac.types()[k].dim;
      } else {
        slot_jac_offset_.push_back(-1);
      }
      for (size_t l = 0; l < k; ++l) {
        const auto u = static_cast<size_t>(vars[l]);
        if (num_free_[u] == 0 || num_free_[v] == 0) continue;
        adjacency_[u].push_back(vars[k]);
        adjacency_[v].push_back(vars[l]);
      }
    }
    max_jac = std::max(max_jac, jac_total);
    max_m = std::max(max_m, info.residual_dim);
    max_slots = std::max(max_slots, info.num_slots);
    factors_.push_back(info);
  }
  for (auto& a : adjacency_) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }

  // Buffers.
  jac_.assign(static_cast<size_t>(max_jac), 0.0);
  ptr_scratch_.assign(static_cast<size_t>(max_slots), nullptr);
  jac_ptr_scratch_.assign(static_cast<size_t>(max_slots), nullptr);
  e_scratch_.assign(static_cast<size_t>(max_m), 0.0);
  sqrt_info_scratch_.assign(static_cast<size_t>(max_m * max_m), 0.0);
  g_ = Eigen::VectorXd::Zero(n_);
  h_diag_ = Eigen::VectorXd::Zero(n_);
  d_ = Eigen::VectorXd::Zero(n_);
  // Columns: analyze() numbers them in the elimination order.
}

void NormalEquations::number_columns(const std::vector<VariableId>& order) {
  const size_t nv = num_free_.size();
  col_start_.assign(nv, -1);
  block_of_column_.clear();
  int c = 0;
  for (VariableId v : order) {
    col_start_[static_cast<size_t>(v)] = c;
    c += num_free_[static_cast<size_t>(v)];
    block_of_column_.insert(block_of_column_.end(),
                            static_cast<size_t>(num_free_[static_cast<size_t>(v)]), v);
  }

  // Rows above each variable's diagonal block: its neighbours with earlier columns, in column
  // order, each contributing all its free parameters.
  auto by_column = [&](int a, int b) {
    return col_start_[static_cast<size_t>(a)] < col_start_[static_cast<size_t>(b)];
  };
  std::vector<std::vector<int>> lower(nv), lower_offset(nv);
  diag_offset_.assign(nv, 0);
  size_t nnz = 0;
  for (VariableId v : order) {
    const auto sv = static_cast<size_t>(v);
    auto& lv = lower[sv];
    for (int u : adjacency_[sv])
      if (by_column(u, v)) lv.push_back(u);
    std::sort(lv.begin(), lv.end(), by_column);
    auto& off = lower_offset[sv];
    off.resize(lv.size());
    int above = 0;
    for (size_t i = 0; i < lv.size(); ++i) {
      off[i] = above;
      above += num_free_[static_cast<size_t>(lv[i])];
    }
    diag_offset_[sv] = above;
    const int fv = num_free_[sv];
    nnz += static_cast<size_t>(fv) * static_cast<size_t>(above) +
           static_cast<size_t>(fv * (fv + 1) / 2);
  }

  // Block offsets of every pair of a factor's slots (k ≤ l), −1 when either has no column.
  pair_offset_.clear();
  for (auto& info : factors_) {
    info.pair_begin = static_cast<int>(pair_offset_.size());
    for (int k = 0; k < info.num_slots; ++k) {
      const int a = slot_var_[static_cast<size_t>(info.slot_begin + k)];
      for (int l = k; l < info.num_slots; ++l) {
        const int b = slot_var_[static_cast<size_t>(info.slot_begin + l)];
        if (num_free_[static_cast<size_t>(a)] == 0 || num_free_[static_cast<size_t>(b)] == 0) {
          pair_offset_.push_back(-1);
        } else if (k == l) {
          pair_offset_.push_back(diag_offset_[static_cast<size_t>(a)]);
        } else {
          const int row = by_column(a, b) ? a : b;
          const int col = row == a ? b : a;
          const auto& lv = lower[static_cast<size_t>(col)];
          const auto it = std::lower_bound(lv.begin(), lv.end(), row, by_column);
          pair_offset_.push_back(lower_offset[static_cast<size_t>(col)][static_cast<size_t>(it - lv.begin())]);
        }
      }
    }
  }

  // The CSC pattern of the upper triangle.
  if (H_) cholmod_free_sparse(&H_, cc_);
  H_ = cholmod_allocate_sparse(static_cast<size_t>(n_), static_cast<size_t>(n_), nnz, 1, 1, 1,
                               CHOLMOD_REAL, cc_);
  if (!H_) throw Error(ErrorCode::Failed, "NormalEquations: out of memory for H");
  int* Hp = static_cast<int*>(H_->p);
  int* Hi = static_cast<int*>(H_->i);
  diag_pos_.resize(static_cast<size_t>(n_));
  int pos = 0;
  for (VariableId v : order) {
    const auto sv = static_cast<size_t>(v);
    for (int j = 0; j < num_free_[sv]; ++j) {
      const int col = col_start_[sv] + j;
      Hp[col] = pos;
      for (int u : lower[sv])
        for (int i = 0; i < num_free_[static_cast<size_t>(u)]; ++i)
          Hi[pos++] = col_start_[static_cast<size_t>(u)] + i;
      for (int i = 0; i <= j; ++i) Hi[pos++] = col_start_[sv] + i;
      diag_pos_[static_cast<size_t>(col)] = pos - 1;
    }
  }
  Hp[n_] = pos;
  std::memset(H_->x, 0, nnz * sizeof(double));
}

void NormalEquations::retract(const double* values, const Eigen::VectorXd& delta,
                              double* out) const {
  const int nv = static_cast<int>(col_start_.size());
  for (int v = 0; v < nv; ++v) {
    const auto sv = static_cast<size_t>(v);
    const int fv = num_free_[sv];
    if (fv == 0) continue;
    const VariableType type = var_type_[sv];
    const int o = var_offset_[sv];
    const double* x = values + o;
    double* y = out + o;
    const double* dv = delta.data() + col_start_[sv];
    if (body_frame_[sv]) {
      const SE2 moved = SE2(x[0], x[1], x[2]) * SE2::exp(Eigen::Vector3d(dv[0], dv[1], dv[2]));
      y[0] = moved.x;
      y[1] = moved.y;
      y[2] = moved.theta;
      continue;
    }
    for (int p = 0; p < type.dim; ++p) y[p] = x[p];
    const int* fp = free_params_.data() + free_begin_[sv];
    for (int i = 0; i < fv; ++i) y[fp[i]] += dv[i];
    if (type.kind == VariableKind::Pose2) y[2] = wrap_angle(y[2]);
  }
}

double NormalEquations::free_values_norm(const double* values) const {
  double s = 0.0;
  const int nv = static_cast<int>(col_start_.size());
  for (int v = 0; v < nv; ++v) {
    const auto sv = static_cast<size_t>(v);
    const double* x = values + var_offset_[sv];
    const int* fp = free_params_.data() + free_begin_[sv];
    for (int i = 0; i < num_free_[sv]; ++i) s += x[fp[i]] * x[fp[i]];
  }
  return std::sqrt(s);
}

}  // namespace planarvo::graph
