#include "graph/normal_equations.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>

#include <cholmod.h>

#include "core/error.h"

namespace planarvo::graph {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

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
  int residual_total = 0, jac_total = 0, max_m = 0, max_slots = 0;
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
    info.residual_offset = residual_total;
    residual_total += info.residual_dim;
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
    max_m = std::max(max_m, info.residual_dim);
    max_slots = std::max(max_slots, info.num_slots);
    factors_.push_back(info);
  }
  for (auto& a : adjacency_) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }

  // Buffers.
  r_.assign(static_cast<size_t>(residual_total), 0.0);
  jac_.assign(static_cast<size_t>(jac_total), 0.0);
  ptr_scratch_.assign(static_cast<size_t>(max_slots), nullptr);
  jac_ptr_scratch_.assign(static_cast<size_t>(max_slots), nullptr);
  e_scratch_.assign(static_cast<size_t>(max_m), 0.0);
  sqrt_info_scratch_.assign(static_cast<size_t>(max_m * max_m), 0.0);
  g_ = Eigen::VectorXd::Zero(n_);
  h_diag_ = Eigen::VectorXd::Zero(n_);
  d_ = Eigen::VectorXd::Zero(n_);

  // Columns in variable order to begin with; analyze() may renumber them.
  std::vector<VariableId> order;
  for (VariableId v = 0; v < nv; ++v)
    if (num_free_[static_cast<size_t>(v)] > 0) order.push_back(v);
  number_columns(order);
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

std::vector<int> NormalEquations::block_amd_permutation() {
  // AMD on the variable graph (upper pattern, one node per free variable), expanded to columns.
  const size_t nv = num_free_.size();
  std::vector<int> block_index(nv, -1);
  std::vector<int> blocks;
  for (size_t v = 0; v < nv; ++v)
    if (num_free_[v] > 0) {
      block_index[v] = static_cast<int>(blocks.size());
      blocks.push_back(static_cast<int>(v));
    }
  const size_t nb = blocks.size();
  size_t bnnz = nb;
  for (int v : blocks) bnnz += adjacency_[static_cast<size_t>(v)].size();
  cholmod_sparse* A = cholmod_allocate_sparse(nb, nb, bnnz, 1, 1, 1, CHOLMOD_PATTERN, cc_);
  if (!A) throw Error(ErrorCode::Failed, "NormalEquations: out of memory for the block graph");
  int* Ap = static_cast<int*>(A->p);
  int* Ai = static_cast<int*>(A->i);
  int q = 0;
  for (size_t b = 0; b < nb; ++b) {
    Ap[b] = q;
    for (int u : adjacency_[static_cast<size_t>(blocks[b])])
      if (block_index[static_cast<size_t>(u)] < static_cast<int>(b))
        Ai[q++] = block_index[static_cast<size_t>(u)];
    Ai[q++] = static_cast<int>(b);
  }
  Ap[nb] = q;
  std::vector<int> block_perm(nb);
  const int ok = cholmod_amd(A, nullptr, 0, block_perm.data(), cc_);
  cholmod_free_sparse(&A, cc_);
  if (!ok) throw Error(ErrorCode::Failed, "NormalEquations: AMD on the block graph failed");
  std::vector<int> perm;
  perm.reserve(static_cast<size_t>(n_));
  for (int b : block_perm) {
    const auto v = static_cast<size_t>(blocks[static_cast<size_t>(b)]);
    for (int j = 0; j < num_free_[v]; ++j) perm.push_back(col_start_[v] + j);
  }
  return perm;
}

void NormalEquations::analyze() {
  if (n_ == 0) return;
  cc_->postorder = 1;
  cc_->nmethods = 1;
  switch (options_.ordering) {
    case Ordering::Automatic: cc_->nmethods = 0; break;
    case Ordering::AMD: cc_->method[0].ordering = CHOLMOD_AMD; break;
    case Ordering::METIS: cc_->method[0].ordering = CHOLMOD_METIS; break;
    case Ordering::Natural:
      cc_->method[0].ordering = CHOLMOD_NATURAL;
      cc_->postorder = 0;
      break;
    case Ordering::BlockAMD: cc_->method[0].ordering = CHOLMOD_GIVEN; break;
  }
  if (options_.ordering == Ordering::BlockAMD) {
    std::vector<int> perm = block_amd_permutation();
    L_ = cholmod_analyze_p(H_, perm.data(), nullptr, 0, cc_);
  } else {
    L_ = cholmod_analyze(H_, cc_);
  }
  if (!L_ || cc_->status < CHOLMOD_OK)
    throw Error(ErrorCode::Failed, "NormalEquations: CHOLMOD's symbolic analysis failed (status " +
                                       std::to_string(cc_->status) + ")");
  ordering_name_ = ordering_name(L_->ordering);

  // A simplicial factorisation of an upper-stored matrix in its natural order reads H as it is;
  // with a permutation CHOLMOD transposes H twice per factorisation (cholmod_factorize.c), the
  // largest single cost after the factorisation itself on sparse graphs. So number the columns
  // in the (postordered) elimination order, variable by variable, and analyse again without a
  // permutation: the same factor, no copies.
  if (!L_->is_super && L_->ordering != CHOLMOD_NATURAL) {
    const int* P = static_cast<const int*>(L_->Perm);
    std::vector<VariableId> order;
    std::vector<char> seen(num_free_.size(), 0);
    for (int k = 0; k < n_; ++k) {
      const VariableId v = block_of_column_[static_cast<size_t>(P[k])];
      if (!seen[static_cast<size_t>(v)]) {
        seen[static_cast<size_t>(v)] = 1;
        order.push_back(v);
      }
    }
    cholmod_free_factor(&L_, cc_);
    number_columns(order);
    cc_->nmethods = 1;
    cc_->method[0].ordering = CHOLMOD_NATURAL;
    cc_->postorder = 0;
    L_ = cholmod_analyze(H_, cc_);
    if (!L_ || cc_->status < CHOLMOD_OK)
      throw Error(ErrorCode::Failed, "NormalEquations: CHOLMOD's symbolic analysis failed "
                                     "(status " + std::to_string(cc_->status) + ")");
    ordering_name_ += ", columns pre-permuted";
  }
  flops_ = cc_->fl;
  lnz_ = cc_->lnz;
  B_ = cholmod_zeros(static_cast<size_t>(n_), 1, CHOLMOD_REAL, cc_);
  if (!B_) throw Error(ErrorCode::Failed, "NormalEquations: out of memory");
}

double NormalEquations::factor_nonzeros() const { return L_ ? lnz_ : 0.0; }
double NormalEquations::factor_flops() const { return flops_; }

double NormalEquations::factor_cost() const { return 0.3 * flops_ + 18.0 * lnz_; }

double NormalEquations::cg_iteration_cost() const {
  const double nnz_h = H_ ? static_cast<const int*>(H_->p)[n_] : 0.0;
  return 3.0 * lnz_ + 2.0 * nnz_h + 2.0 * n_;
}

std::string NormalEquations::ordering_name(int ordering) {
  switch (ordering) {
    case CHOLMOD_NATURAL: return "natural";
    case CHOLMOD_GIVEN: return "block AMD";
    case CHOLMOD_AMD: return "AMD";
    case CHOLMOD_METIS: return "METIS";
    case CHOLMOD_NESDIS: return "NESDIS";
    case CHOLMOD_COLAMD: return "COLAMD";
    case CHOLMOD_POSTORDERED: return "natural, postordered";
    default: return "ordering " + std::to_string(ordering);
  }
}

std::string NormalEquations::ordering_used() const {
  if (!L_) return "none";
  return ordering_name_ + (L_->is_super ? ", supernodal" : ", simplicial");
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

void NormalEquations::linearize_factor_into(int f, const double* values, double& cost) {
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
  double* e = r_.data() + info.residual_offset;
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
  if (!any_free) return;
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
}

namespace {

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

template <int M>
void NormalEquations::accumulate_factor(const FactorInfo& info) {
  double* Hx = static_cast<double*>(H_->x);
  const int* Hp = static_cast<const int*>(H_->p);
  double* g = g_.data();
  const int m = info.residual_dim;
  const double* r = r_.data() + info.residual_offset;
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
  auto t0 = Clock::now();
  // cos, sin of each body-frame pose's heading, once per pose rather than once per factor.
  for (size_t v = 0; v < body_frame_.size(); ++v)
    if (body_frame_[v]) {
      const double theta = values[var_offset_[v] + 2];
      rotation_[2 * v] = std::cos(theta);
      rotation_[2 * v + 1] = std::sin(theta);
    }
  double cost = 0.0;
  const int nf = static_cast<int>(factors_.size());
  for (int f = 0; f < nf; ++f) linearize_factor_into(f, values, cost);
  if (times) times->linearize += seconds_since(t0);

  t0 = Clock::now();
  double* Hx = static_cast<double*>(H_ ? H_->x : nullptr);
  if (H_) std::memset(Hx, 0, static_cast<size_t>(static_cast<const int*>(H_->p)[n_]) * sizeof(double));
  g_.setZero();
  for (const FactorInfo& info : factors_) {
    // Fixed-size dot products for the common residual sizes.
    switch (info.residual_dim) {
      case 1: accumulate_factor<1>(info); break;
      case 2: accumulate_factor<2>(info); break;
      case 3: accumulate_factor<3>(info); break;
      default: accumulate_factor<0>(info); break;
    }
  }
  for (int c = 0; c < n_; ++c) h_diag_[c] = Hx[diag_pos_[static_cast<size_t>(c)]];
  if (times) times->build += seconds_since(t0);
  return cost;
}

void NormalEquations::set_damping(double lambda, Damping damping) {
  double* Hx = static_cast<double*>(H_->x);
  for (int c = 0; c < n_; ++c) {
    const double h = h_diag_[c];
    d_[c] = damping == Damping::Marquardt
                ? std::min(std::max(h, options_.min_diagonal), options_.max_diagonal)
                : 1.0;
    Hx[diag_pos_[static_cast<size_t>(c)]] = h + lambda * d_[c];
  }
  lambda_ = lambda;
}

void NormalEquations::multiply(const double* x, double* y, bool damped) const {
  const int* Hp = static_cast<const int*>(H_->p);
  const int* Hi = static_cast<const int*>(H_->i);
  const double* Hx = static_cast<const double*>(H_->x);
  for (int c = 0; c < n_; ++c) y[c] = 0.0;
  for (int c = 0; c < n_; ++c) {
    const double xc = x[c];
    double yc = 0.0;
    const int end = Hp[c + 1] - 1;  // the last entry of a column is its diagonal
    for (int p = Hp[c]; p < end; ++p) {
      const int r = Hi[p];
      y[r] += Hx[p] * xc;
      yc += Hx[p] * x[r];
    }
    y[c] += yc + (damped ? Hx[end] : h_diag_[c]) * xc;
  }
}

bool NormalEquations::factor_solve(const double* x, double* y) {
  if (!L_->is_super && !L_->is_ll && L_->ordering == CHOLMOD_NATURAL) {
    // L·D·Lᵀ·y = x with the columns already in elimination order: forward substitution with
    // the unit lower triangle, the diagonal, back substitution. (cholmod_solve2 would do the
    // same, but reallocates its workspace on every call.)
    const int* Lp = static_cast<const int*>(L_->p);
    const int* Li = static_cast<const int*>(L_->i);
    const int* Lnz = static_cast<const int*>(L_->nz);
    const double* Lx = static_cast<const double*>(L_->x);
    if (y != x) std::memcpy(y, x, static_cast<size_t>(n_) * sizeof(double));
    for (int j = 0; j < n_; ++j) {
      const double yj = y[j];
      for (int p = Lp[j] + 1, end = Lp[j] + Lnz[j]; p < end; ++p) y[Li[p]] -= Lx[p] * yj;
    }
    for (int j = 0; j < n_; ++j) y[j] /= Lx[Lp[j]];
    for (int j = n_ - 1; j >= 0; --j) {
      double yj = y[j];
      for (int p = Lp[j] + 1, end = Lp[j] + Lnz[j]; p < end; ++p) yj -= Lx[p] * y[Li[p]];
      y[j] = yj;
    }
    return true;
  }
  std::memcpy(B_->x, x, static_cast<size_t>(n_) * sizeof(double));
  if (!cholmod_solve2(CHOLMOD_A, L_, B_, nullptr, &X_, nullptr, &Y_, &E_, cc_)) return false;
  std::memcpy(y, X_->x, static_cast<size_t>(n_) * sizeof(double));
  return true;
}

int NormalEquations::solve_step_reusing_factor(double lambda, Damping damping,
                                               Eigen::VectorXd& delta, int max_iterations,
                                               double tolerance, PhaseTimes* times) {
  if (!factor_ok_ || n_ == 0) return -1;
  const auto t0 = Clock::now();
  set_damping(lambda, damping);
  cg_r_.resize(n_);
  cg_z_.resize(n_);
  cg_p_.resize(n_);
  cg_q_.resize(n_);
  delta.setZero(n_);
  cg_r_ = -g_;
  const double stop = tolerance * cg_r_.norm();
  if (!factor_solve(cg_r_.data(), cg_z_.data())) return -1;
  cg_p_ = cg_z_;
  double rz = cg_r_.dot(cg_z_);
  int result = -1;
  for (int k = 1; k <= max_iterations; ++k) {
    multiply(cg_p_.data(), cg_q_.data(), true);
    const double pq = cg_p_.dot(cg_q_);
    if (!(pq > 0.0) || !std::isfinite(rz)) break;
    const double alpha = rz / pq;
    delta += alpha * cg_p_;
    cg_r_ -= alpha * cg_q_;
    if (cg_r_.norm() <= stop) {
      result = k;
      break;
    }
    if (!factor_solve(cg_r_.data(), cg_z_.data())) break;
    const double rz_next = cg_r_.dot(cg_z_);
    cg_p_ = cg_z_ + (rz_next / rz) * cg_p_;
    rz = rz_next;
  }
  if (result > 0 && !delta.allFinite()) result = -1;
  if (times) times->solve += seconds_since(t0);
  return result;
}

bool NormalEquations::factorize(double lambda, Damping damping, PhaseTimes* times) {
  factor_ok_ = false;
  if (n_ == 0) return false;
  const auto t0 = Clock::now();
  set_damping(lambda, damping);
  const int ok = cholmod_factorize(H_, L_, cc_);
  bool good = ok && cc_->status == CHOLMOD_OK && L_->minor == L_->n;
  if (good && !L_->is_super && !L_->is_ll) {
    // Simplicial LDLᵀ accepts negative pivots: positive definite only if D > 0.
    const int* Lp = static_cast<const int*>(L_->p);
    const double* Lx = static_cast<const double*>(L_->x);
    for (int j = 0; j < n_ && good; ++j) good = Lx[Lp[j]] > 0.0;
  }
  if (times) times->factorize += seconds_since(t0);
  factor_ok_ = good;
  return good;
}

bool NormalEquations::solve_step(Eigen::VectorXd& delta, PhaseTimes* times) {
  if (!factor_ok_) return false;
  const auto t0 = Clock::now();
  delta = -g_;
  const bool ok = factor_solve(delta.data(), delta.data()) && delta.allFinite();
  if (times) times->solve += seconds_since(t0);
  return ok;
}

Eigen::MatrixXd NormalEquations::solve(const Eigen::MatrixXd& rhs) {
  if (!factor_ok_) throw Error(ErrorCode::Internal, "NormalEquations::solve without a factor");
  if (rhs.rows() != n_) throw_invalid_argument("NormalEquations::solve: wrong number of rows");
  cholmod_dense* B = cholmod_allocate_dense(static_cast<size_t>(n_), static_cast<size_t>(rhs.cols()),
                                            static_cast<size_t>(n_), CHOLMOD_REAL, cc_);
  if (!B) throw Error(ErrorCode::Failed, "NormalEquations::solve: out of memory");
  std::memcpy(B->x, rhs.data(), static_cast<size_t>(rhs.size()) * sizeof(double));
  cholmod_dense* X = cholmod_solve(CHOLMOD_A, L_, B, cc_);
  cholmod_free_dense(&B, cc_);
  if (!X) throw Error(ErrorCode::Failed, "NormalEquations::solve: CHOLMOD's solve failed");
  Eigen::MatrixXd out = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(X->x), n_, rhs.cols());
  cholmod_free_dense(&X, cc_);
  return out;
}

double NormalEquations::predicted_decrease_of_solution(const Eigen::VectorXd& delta) const {
  return -g_.dot(delta) + lambda_ * (d_.array() * delta.array().square()).sum();
}

double NormalEquations::predicted_decrease(const Eigen::VectorXd& delta) {
  cg_q_.resize(n_);
  multiply(delta.data(), cg_q_.data(), false);
  return -2.0 * g_.dot(delta) - delta.dot(cg_q_);
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
