// NormalEquations (normal_equations.h), the sparse Cholesky part on CHOLMOD: the fill-reducing
// ordering (block AMD) and the symbolic analysis, once; damping, the numeric factorisation, the
// triangular solves, products with H and the conjugate gradients on a reused factor.
#include "graph/solver/normal_equations.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include <cholmod.h>

#include "core/error.h"
#include "graph/solver/normal_equations_internal.h"

namespace planarvo::graph {

using normal_equations_detail::Clock;
using normal_equations_detail::seconds_since;

std::vector<VariableId> NormalEquations::block_amd_order() {
  // AMD on the variable graph (upper pattern, one node per free variable). AMD's permutation is
  // postordered (amd_2 numbers its assembly tree in postorder), which is what a simplicial
  // factorisation wants from an order; the variables in that order.
  const size_t nv = num_free_.size();
  std::vector<int> block_index(nv, -1);
  std::vector<VariableId> blocks;
  for (size_t v = 0; v < nv; ++v)
    if (num_free_[v] > 0) {
      block_index[v] = static_cast<int>(blocks.size());
      blocks.push_back(static_cast<VariableId>(v));
    }
  const size_t nb = blocks.size();
  size_t bnnz = nb;
  for (VariableId v : blocks) bnnz += adjacency_[static_cast<size_t>(v)].size();
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
  std::vector<VariableId> order(nb);
  for (size_t k = 0; k < nb; ++k) order[k] = blocks[static_cast<size_t>(block_perm[k])];
  return order;
}

void NormalEquations::analyze_natural(bool postorder) {
  if (L_) cholmod_free_factor(&L_, cc_);
  cc_->nmethods = 1;
  cc_->method[0].ordering = CHOLMOD_NATURAL;
  cc_->postorder = postorder;
  L_ = cholmod_analyze(H_, cc_);
  if (!L_ || cc_->status < CHOLMOD_OK)
    throw Error(ErrorCode::Failed, "NormalEquations: CHOLMOD's symbolic analysis failed (status " +
                                       std::to_string(cc_->status) + ")");
}

void NormalEquations::analyze() {
  if (n_ == 0) return;
  // A simplicial factorisation of an upper-stored matrix in its natural order reads H as it is;
  // with a permutation CHOLMOD transposes H twice per factorisation (cholmod_factorize.c), the
  // largest single cost after the factorisation itself on sparse graphs. So the columns are
  // numbered in the elimination order, variable by variable, and CHOLMOD analyses H without a
  // permutation: the same factor, no copies.
  if (options_.ordering == Ordering::BlockAMD) {
    // The order is ours: number the columns in it and analyse once. A supernodal factor is
    // analysed again with CHOLMOD's etree postorder, which finds the supernodes.
    number_columns(block_amd_order());
    analyze_natural(false);
    if (L_->is_super) analyze_natural(true);
    ordering_name_ = L_->is_super ? "block AMD, postordered" : "block AMD, columns pre-permuted";
  } else {
    std::vector<VariableId> order;
    for (size_t v = 0; v < num_free_.size(); ++v)
      if (num_free_[v] > 0) order.push_back(static_cast<VariableId>(v));
    number_columns(order);
    cc_->postorder = 1;
    cc_->nmethods = 1;
    switch (options_.ordering) {
      case Ordering::Automatic: cc_->nmethods = 0; break;
      case Ordering::AMD: cc_->method[0].ordering = CHOLMOD_AMD; break;
      case Ordering::METIS: cc_->method[0].ordering = CHOLMOD_METIS; break;
      case Ordering::Natural:
      case Ordering::BlockAMD:
        cc_->method[0].ordering = CHOLMOD_NATURAL;
        cc_->postorder = 0;
        break;
    }
    L_ = cholmod_analyze(H_, cc_);
    if (!L_ || cc_->status < CHOLMOD_OK)
      throw Error(ErrorCode::Failed, "NormalEquations: CHOLMOD's symbolic analysis failed "
                                     "(status " + std::to_string(cc_->status) + ")");
    ordering_name_ = ordering_name(L_->ordering);
    if (!L_->is_super && L_->ordering != CHOLMOD_NATURAL) {
      // CHOLMOD's ordering, as a variable order (parameter orderings keep a variable's
      // parameters together here: the renumbering is by first appearance).
      const int* P = static_cast<const int*>(L_->Perm);
      order.clear();
      std::vector<char> seen(num_free_.size(), 0);
      for (int k = 0; k < n_; ++k) {
        const VariableId v = block_of_column_[static_cast<size_t>(P[k])];
        if (!seen[static_cast<size_t>(v)]) {
          seen[static_cast<size_t>(v)] = 1;
          order.push_back(v);
        }
      }
      number_columns(order);
      analyze_natural(false);
      ordering_name_ += ", columns pre-permuted";
    }
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

}  // namespace planarvo::graph
