// The Gauss–Newton normal equations H δ = −g of a factor graph (H = J̃ᵀJ̃, g = J̃ᵀr̃, whitened and
// robust-weighted) in a CHOLMOD matrix whose pattern is built once, and their sparse Cholesky
// factorisation.
//
// Only the upper triangle of H is stored (CSC, stype = 1). Columns are the free parameters,
// variable after variable; a fixed variable has no columns and a fixed parameter loses its
// column. The pattern comes from the graph's block structure; each factor keeps, per pair of its
// variables, the offset of its block inside the CSC value array, so refilling H is a pass over
// the factors that adds small dense blocks in place — no triplets, no sort, no allocation.
// The symbolic analysis (fill-reducing ordering, symbolic factor) runs once, in the
// constructor; the variables' columns are numbered in the elimination order (for a simplicial
// factor), so that CHOLMOD factorises H as stored, without permuting copies. With the default
// block AMD ordering the order is known before H's pattern is built, and CHOLMOD analyses once.
// factorize() is a numeric factorisation only.
#pragma once
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "graph/solver/factor_graph.h"

struct cholmod_common_struct;
struct cholmod_sparse_struct;
struct cholmod_factor_struct;
struct cholmod_dense_struct;

namespace planarvo::graph {

// How a pose moves by a step δ = (δx, δy, δθ).
enum class PoseRetraction {
  // (x + δx, y + δy, θ + δθ), as g2o's VertexSE2; Jacobians are the factors' own.
  Additive,
  // X · exp(δ), δ in the pose's own frame; Jacobians become J · diag(R(θ), 1). Measured on the
  // reference files and calibration chains (test/bench): fewer iterations where rotations
  // accumulate along chains (ais2klinik 100 → 33, a 10k-pose calibration chain 68 → 27).
  // A pose with a single fixed parameter always steps additively, so that the fixed parameter
  // is an exact world coordinate; the retraction is a per-variable choice of step, either is
  // valid.
  RightExp,
};

// The fill-reducing ordering of cholmod_analyze.
enum class Ordering {
  BlockAMD,   // AMD on the variable graph (one node per variable), expanded to parameters
  Automatic,  // CHOLMOD's default: AMD on parameters, METIS too when AMD fills a lot
  AMD,        // AMD on parameters
  METIS,      // METIS nested dissection on parameters
  Natural,    // none (for tests)
};

enum class Damping {
  Marquardt,  // H + λ·diag(H) (diag clamped to [min_diagonal, max_diagonal]): scale invariant
  Levenberg,  // H + λ·I
};

// Supernodal (dense BLAS kernels on supernodes) or simplicial (CHOLMOD's own up-looking LDLᵀ).
// Which is faster depends on the BLAS: with Debian's reference BLAS, simplicial wins on every
// 2-D pose graph and calibration graph measured (test/bench), supernodal wins with an optimised
// BLAS on problems with dense fronts.
enum class Factorization {
  Automatic,  // supernodal when flops / nnz(L) ≥ supernodal_switch (CHOLMOD's rule)
  Supernodal,
  Simplicial,
};

struct LinearSolverOptions {
  Ordering ordering = Ordering::BlockAMD;
  Factorization factorization = Factorization::Automatic;
  // CHOLMOD's default is 40; 2-D problems reach ~80 (city10000), where the reference BLAS
  // still loses to simplicial, hence the higher default.
  double supernodal_switch = 500.0;
  PoseRetraction retraction = PoseRetraction::RightExp;
  double min_diagonal = 1e-6;  // clamp of diag(H) in Marquardt damping (as Ceres)
  double max_diagonal = 1e32;
};

// Time spent in each phase, seconds.
struct PhaseTimes {
  double linearize = 0.0;  // factor errors and Jacobians, whitening, robust weights, and
                           // their blocks added into H and g (one pass, factor by factor)
  double factorize = 0.0;  // numeric Cholesky
  double solve = 0.0;      // triangular solves
  double evaluate = 0.0;   // cost at trial points
  double analyze = 0.0;    // pattern and symbolic analysis (once)
};

// One factor's whitened and robust-weighted error r̃ and Jacobians J̃_k (residual_dim × dim_k,
// stored coordinates) at the graph's values; returns ρ(eᵀΩe). Independent of NormalEquations
// (tests use it as the dense reference; the covariance code for cross terms).
double linearize_factor(const FactorGraph& graph, int factor, Eigen::VectorXd& residual,
                        std::vector<Eigen::MatrixXd>& jacobians);

class NormalEquations {
 public:
  // `also_fixed`: variables to treat as fixed on top of the graph's own (the Schur complement
  // of observability analysis needs the system of all other variables).
  NormalEquations(const FactorGraph& graph, const LinearSolverOptions& options,
                  const std::vector<VariableId>& also_fixed = {});
  ~NormalEquations();
  NormalEquations(const NormalEquations&) = delete;
  NormalEquations& operator=(const NormalEquations&) = delete;

  // True while the graph's structure is what this system was built for (a structure version
  // belongs to one graph only, so another graph never matches).
  bool matches(const FactorGraph& graph) const;
  int num_columns() const { return n_; }
  // The column of a free parameter, −1 for a fixed one.
  int column(VariableId v, int parameter) const;
  const LinearSolverOptions& options() const { return options_; }

  // Robust cost Σ ρ(eᵀΩe) at `values` (the graph's flat layout).
  double evaluate_cost(const double* values, PhaseTimes* times = nullptr);
  // Evaluates all factors with Jacobians at `values`, fills H and g; returns the cost.
  double linearize(const double* values, PhaseTimes* times = nullptr);
  const Eigen::VectorXd& gradient() const { return g_; }
  const Eigen::VectorXd& hessian_diagonal() const { return h_diag_; }

  // Factorises H + λD (D per `damping`). False when the matrix is not positive definite (or
  // not finite); the factor is then unusable until the next successful factorize().
  bool factorize(double lambda, Damping damping, PhaseTimes* times = nullptr);
  // δ = −(H + λD)⁻¹ g with the last successful factorisation; false when δ is not finite.
  bool solve_step(Eigen::VectorXd& delta, PhaseTimes* times = nullptr);
  // δ ≈ −(H + λD)⁻¹ g for the current H by conjugate gradients preconditioned with the last
  // successful factorisation, which may be of an earlier H and λ: a few sparse products and
  // triangular solves instead of a numeric factorisation. Stops when ‖(H + λD)δ + g‖ ≤
  // tolerance·‖g‖; returns the number of CG iterations, or −1 when there is no factor or CG did
  // not converge within max_iterations (or met a non-positive curvature).
  int solve_step_reusing_factor(double lambda, Damping damping, Eigen::VectorXd& delta,
                                int max_iterations, double tolerance,
                                PhaseTimes* times = nullptr);
  bool has_factor() const { return factor_ok_; }
  // X = (H + λD)⁻¹ B for a dense n × k right-hand side (covariances).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs);
  // The decrease of the quadratic model |r̃|² − |r̃ + J̃δ|² = −2gᵀδ − δᵀHδ for any step δ (exact
  // or not; one product with H).
  double predicted_decrease(const Eigen::VectorXd& delta);
  // The same for δ from solve_step, i.e. (H + λD)δ = −g with the λ and D of the last
  // factorize(): then −2gᵀδ − δᵀHδ = −gᵀδ + λδᵀDδ, no product needed.
  double predicted_decrease_of_solution(const Eigen::VectorXd& delta) const;

  // out = values ⊞ δ (fixed parameters untouched).
  void retract(const double* values, const Eigen::VectorXd& delta, double* out) const;
  // Euclidean norm of the free parameters' values (for the relative step tolerance).
  double free_values_norm(const double* values) const;

  // H (both triangles, undamped) as a dense matrix: tests compare it with a dense reference.
  Eigen::MatrixXd dense_hessian() const;
  // Fill-in of the factor: nnz(L), and what CHOLMOD used (ordering, supernodal).
  double factor_nonzeros() const;
  double factor_flops() const;  // of one numeric factorisation, from the analysis
  // Estimated work (ns on the machine the model was fitted on; only ratios matter) of one
  // numeric factorisation and of one iteration of solve_step_reusing_factor (a product with H
  // and two triangular solves). A model fitted to CHOLMOD's measured times on the benchmark
  // graphs (simplicial, reference BLAS): ~0.3 ns per flop plus ~18 ns per nonzero of L for the
  // factorisation (its per-entry overhead dominates on sparse 2-D problems), ~3 ns per nonzero
  // of L for a pair of triangular solves and ~2 ns per nonzero of H for a product. Flops alone
  // would call a 100k-pose calibration chain's factorisation (95 ms) as cheap as a solve (7 ms).
  double factor_cost() const;
  double cg_iteration_cost() const;
  std::string ordering_used() const;
  // Seconds spent building the pattern and in cholmod_analyze.
  double analyze_seconds() const { return analyze_seconds_; }

 private:
  void build_pattern(const FactorGraph& graph, const std::vector<VariableId>& also_fixed);
  // Assigns columns to the free variables in `order` and builds H's CSC pattern and the
  // factors' block offsets for that numbering.
  void number_columns(const std::vector<VariableId>& order);
  // The free variables in the order of AMD on the variable graph.
  std::vector<VariableId> block_amd_order();
  // Numbers the columns and analyses H (the ordering, the symbolic factor).
  void analyze();
  // cholmod_analyze of H as numbered (no fill-reducing permutation), with or without CHOLMOD's
  // etree postorder; replaces L.
  void analyze_natural(bool postorder);
  static std::string ordering_name(int cholmod_ordering);
  void release();
  void set_damping(double lambda, Damping damping);
  // y = (H + λD)·x, or H·x without the damping.
  void multiply(const double* x, double* y, bool damped) const;
  // y = (last factor)⁻¹·x (y may be x), allocation-free for a simplicial factor.
  bool factor_solve(const double* x, double* y);
  // One factor's whitened, robust-weighted error and Jacobians into e_scratch_ and jac_; adds
  // its cost; false when none of its variables is free.
  bool linearize_factor_into(int f, const double* values, double& cost);
  struct FactorInfo;
  // Adds the factor just linearised (e_scratch_, jac_) to H (J̃ᵀJ̃ blocks) and g (J̃ᵀr̃); M: the
  // residual size when fixed at compile time, 0 for any.
  template <int M>
  void accumulate_factor(const FactorInfo& info);

  LinearSolverOptions options_;
  std::uint64_t version_ = 0;  // the graph's structure version (unique across graphs)
  int n_ = 0;  // free parameters

  // Per variable. Copied from the graph: the system holds no pointer to it (a graph may move;
  // its Factor objects do not).
  std::vector<VariableType> var_type_;
  std::vector<int> var_offset_;       // into the flat value array
  std::vector<int> col_start_;        // first column, −1 if no free parameter (columns follow
                                      // the elimination order, not the variable order)
  std::vector<int> num_free_;         // number of free parameters
  std::vector<int> free_begin_;       // into free_params_
  std::vector<int> free_params_;      // parameter index of each free column, per variable
  std::vector<int> diag_offset_;      // rows above a variable's diagonal block in its columns
  std::vector<VariableId> block_of_column_;  // variable of each column (for ordering)
  std::vector<char> body_frame_;      // the pose steps by X·exp(δ) (else additively)
  std::vector<double> rotation_;      // cos θ, sin θ of body-frame poses at the linearisation

  // Per factor (structure of arrays). A factor's variables are "slots".
  struct FactorInfo {
    const Factor* factor;
    const RobustKernel* kernel;
    const double* sqrt_info;  // constant information; null when state dependent
    int residual_dim;
    int slot_begin, num_slots;
    int pair_begin;       // into pair_offset_: num_slots·(num_slots+1)/2 entries
  };
  std::vector<FactorInfo> factors_;
  std::vector<int> slot_var_;        // variable of each slot
  std::vector<int> slot_value_offset_;
  std::vector<int> slot_jac_offset_;  // into jac_ (from the factor's first slot), −1 when the
                                      // variable has no free parameter
  std::vector<char> slot_body_frame_;  // body_frame_ of the slot's variable
  std::vector<int> pair_offset_;      // offset of the block within its CSC columns (see .cpp)

  // Buffers, allocated once.
  std::vector<double> jac_;  // one factor's whitened Jacobians (full variable dims),
                             // column-major per slot; sized for the largest factor
  std::vector<const double*> ptr_scratch_;
  std::vector<double*> jac_ptr_scratch_;
  std::vector<double> e_scratch_, sqrt_info_scratch_;
  Eigen::VectorXd g_;
  Eigen::VectorXd h_diag_;  // diag(H) before damping
  Eigen::VectorXd d_;       // the damping diagonal D set last
  double lambda_ = 0.0;     // and its λ
  Eigen::VectorXd cg_r_, cg_z_, cg_p_, cg_q_;  // conjugate-gradient workspace
  std::vector<int> diag_pos_;  // index of each diagonal entry in the CSC values

  std::vector<std::vector<int>> adjacency_;  // free variables sharing a factor, per variable
  std::string ordering_name_;
  double analyze_seconds_ = 0.0;
  double flops_ = 0.0, lnz_ = 0.0;

  // CHOLMOD.
  cholmod_common_struct* cc_ = nullptr;
  cholmod_sparse_struct* H_ = nullptr;
  cholmod_factor_struct* L_ = nullptr;
  cholmod_dense_struct* B_ = nullptr;
  cholmod_dense_struct* X_ = nullptr;
  cholmod_dense_struct* Y_ = nullptr;
  cholmod_dense_struct* E_ = nullptr;
  bool factor_ok_ = false;
};

}  // namespace planarvo::graph
