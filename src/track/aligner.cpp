#include "track/aligner.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <Eigen/Cholesky>

#include "core/error.h"
#include "core/tasks.h"
#include "ocl/runtime.h"
#include "track/warp_model.h"

namespace planarvo::track {

const char* const kAlignFewValid = "too few valid pixels";
const char* const kAlignNoLiveTexture = "no texture in the live frame";
const char* const kAlignDiverged = "diverged";

namespace {

constexpr int kMinLevelSide = 8;
constexpr double kMadToSigma = 1.4826;

using Vector5d = JointStep::Vector5d;
using Matrix52d = JointStep::Matrix52d;
// At most kMaxJacobian square, on the stack (aligner.h's PriorMatrix and PriorVector).
using MatrixL = PriorMatrix;
using MatrixL2 = Eigen::Matrix<double, Eigen::Dynamic, 2, 0, 5, 2>;
using VectorL = PriorVector;

WarpReduceOptions kernel_options(const AlignerOptions& o, bool stats) {
  WarpReduceOptions k = o.kernel;
  k.stats = stats;
  k.debug_output = false;
  return k;
}

// The fused pass's variants with the default options (the tracker's NPARAM 3, which tracking
// and calibration use, and the roll/pitch estimator's 5, which calibration uses; each plain and
// STATS), registered before main() so that exported kernel binaries hold them without an aligner
// having been made (FPGA flows cannot compile at run time).
const bool kDefaultVariantsRegistered = [] {
  for (int nparam : {kMotionParams, kMotionParams + kOrientationParams, kMotionParams + kAttitudeParams}) {
    const std::vector<std::string> uses =
        nparam == kMotionParams ? std::vector<std::string>{tasks::kTrack, tasks::kCalibrate}
        : nparam == kMotionParams + kOrientationParams ? std::vector<std::string>{tasks::kCalibrate}
                                                       : std::vector<std::string>{tasks::kTrack};
    for (bool stats : {false, true})
      ocl::Runtime::register_build_options(
          "warp_reduce", WarpReduce::build_options(nparam, kernel_options(AlignerOptions(), stats)), uses);
  }
  // The tracker's pass over a subsampled level (planarvo_tracker_options.level0_subsample; one
  // program for every block size): the calibration's tracking stage runs it too (level 1 at 1/4
  // and level 0 at 1/9 are the tracker's defaults).
  for (int nparam : {kMotionParams, kMotionParams + kAttitudeParams})
    for (bool stats : {false, true}) {
      WarpReduceOptions k = kernel_options(AlignerOptions(), stats);
      k.select_block = 2;
      ocl::Runtime::register_build_options("warp_reduce", WarpReduce::build_options(nparam, k),
                                           nparam == kMotionParams
                                               ? std::vector<std::string>{tasks::kTrack, tasks::kCalibrate}
                                               : std::vector<std::string>{tasks::kTrack});
    }
  return true;
}();

bool finite(const SE2& m) { return std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.theta); }

double mean_cost(const std::vector<ReduceSums>& sums) {
  double cost = 0.0, valid = 0.0;
  for (const ReduceSums& s : sums) {
    cost += s.cost;
    valid += s.valid;
  }
  return valid > 0 ? cost / valid : HUGE_VAL;
}

// One pair's block of the normal equations in the order (motion, brightness | orientation):
// where each parameter sits in the pass's sums (motion 0-2, orientation 3-4 when NPARAM is 5,
// then brightness).
struct PairBlock {
  Eigen::Matrix<double, 5, 5> A_ll = Eigen::Matrix<double, 5, 5>::Zero();
  Matrix52d A_ls = Matrix52d::Zero();
  Eigen::Matrix2d A_ss = Eigen::Matrix2d::Zero();
  Vector5d g_l = Vector5d::Zero();
  Eigen::Vector2d g_s = Eigen::Vector2d::Zero();
};

PairBlock pair_block(const ReduceSums& s, int nl, bool orientation) {
  const int np = orientation ? kMotionParams + kOrientationParams : kMotionParams;
  int local[5] = {0, 1, 2, np, np + 1};
  const int shared[2] = {kMotionParams, kMotionParams + 1};
  PairBlock b;
  for (int i = 0; i < nl; ++i) {
    b.g_l(i) = s.JtWr(local[i]);
    for (int j = 0; j < nl; ++j) b.A_ll(i, j) = s.JtWJ(local[i], local[j]);
    if (orientation)
      for (int j = 0; j < 2; ++j) b.A_ls(i, j) = s.JtWJ(local[i], shared[j]);
  }
  if (orientation)
    for (int i = 0; i < 2; ++i) {
      b.g_s(i) = s.JtWr(shared[i]);
      for (int j = 0; j < 2; ++j) b.A_ss(i, j) = s.JtWJ(shared[i], shared[j]);
    }
  return b;
}

// The state of a pair relative to the prior's (the coarser level's estimate), in the pass's sums'
// order: the motion in SE(2)'s tangent space, the local plane's attitudes (local_plane), then
// log-gain and bias (brightness). n entries.
VectorL prior_error(const AlignmentPair& prior, const AlignmentPair& state, bool local_plane, bool brightness) {
  const int n = kMotionParams + (local_plane ? kAttitudeParams : 0) + (brightness ? 2 : 0);
  VectorL e(n);
  e.head<3>() = (prior.motion.inverse() * state.motion).log();
  int i = kMotionParams;
  if (local_plane) {
    e(i++) = state.reference_attitude.roll - prior.reference_attitude.roll;
    e(i++) = state.reference_attitude.pitch - prior.reference_attitude.pitch;
    e(i++) = state.live_attitude.roll - prior.live_attitude.roll;
    e(i++) = state.live_attitude.pitch - prior.live_attitude.pitch;
  }
  if (brightness) {
    e(i++) = state.log_gain - prior.log_gain;
    e(i++) = state.bias - prior.bias;
  }
  return e;
}

// The local plane's attitudes of a pair against their prior's mean, radians.
Eigen::Vector4d attitude_error(const AlignmentPair& p) {
  return Eigen::Vector4d(p.reference_attitude.roll, p.reference_attitude.pitch, p.live_attitude.roll,
                         p.live_attitude.pitch) -
         p.attitude_prior_mean;
}

// The block of the pass's sums over the first n parameters in their own order (motion, the
// model's, brightness when estimated: the homography's nparam followed by a and b, so without
// brightness the first nparam).
MatrixL sums_block(const ReduceSums& s, int n) { return s.JtWJ.topLeftCorner(n, n); }
VectorL sums_gradient(const ReduceSums& s, int n) { return s.JtWr.head(n); }

// Why the prior is tested (prior_consistency_scale, aligner.h): a rear camera 55 degrees from
// vertical over asphalt, where half resolution blurs the foreshortened far field differently as
// the view moves: its estimate is 10-15 of its standard deviations off, and with the prior at
// full weight the subsample kept that bias (0.19 mm per frame where full resolution has 0.06).
double prior_scale_of(const ReduceSums& data, const MatrixL& H, const VectorL& e, double sigma, double chi2) {
  const int n = static_cast<int>(e.size());
  return prior_consistency_scale(sums_block(data, n), sums_gradient(data, n), H, e.head<3>(), sigma, chi2);
}

// Levenberg's damping H_ii (1 + lambda) plus a ridge of 1e-12 of the largest diagonal entry, so
// that a parameter the images do not constrain at all gives a finite step.
template <typename M>
void damp(M* A, int n, double lambda) {
  double largest = 0.0;
  for (int i = 0; i < n; ++i) largest = std::max(largest, std::abs((*A)(i, i)));
  for (int i = 0; i < n; ++i) (*A)(i, i) = (*A)(i, i) * (1.0 + lambda) + 1e-12 * largest;
}

}  // namespace

double prior_consistency_scale(const PriorMatrix& A, const PriorVector& g, const PriorMatrix& H,
                               const Eigen::Vector3d& e_motion, double sigma, double chi2) {
  if (!(chi2 > 0.0)) return 1.0;
  const int n = static_cast<int>(A.rows());
  const Eigen::LDLT<PriorMatrix> Al(A), Hl(H);
  if (Al.info() != Eigen::Success || Hl.info() != Eigen::Success || !Al.isPositive() || !Hl.isPositive()) return 1.0;
  const PriorVector step = -Al.solve(g);
  const Eigen::Vector3d dm = e_motion + step.head<3>();
  const PriorMatrix I = PriorMatrix::Identity(n, n);
  const Eigen::Matrix3d C0 = sigma * sigma * Al.solve(I).topLeftCorner<3, 3>();
  const Eigen::Matrix3d C1 = sigma * sigma * Hl.solve(I).topLeftCorner<3, 3>();
  auto d2 = [&](double scale) { return dm.dot((C0 + C1 / scale).ldlt().solve(dm)); };
  if (!(d2(1.0) > chi2)) return 1.0;  // consistent (or not finite)
  // d2 increases with the scale: bisection in log scale down to 1e-6 (below it, no prior).
  double lo = std::log(1e-6), hi = 0.0;
  if (d2(std::exp(lo)) > chi2) return 0.0;
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    (d2(std::exp(mid)) > chi2 ? hi : lo) = mid;
  }
  return std::exp(lo);
}

namespace {
// The pass of every level (the local plane's attitude levels add a pass of their own).
int model_nparam(AlignerModel m) {
  return m == AlignerModel::CameraTilt ? kMotionParams + kOrientationParams : kMotionParams;
}
}  // namespace

Aligner::Aligner(ocl::Runtime& runtime, const Eigen::Matrix3d& K, const AlignerOptions& options,
                 bool with_orientation)
    : Aligner(runtime, K, options, with_orientation ? AlignerModel::CameraTilt : AlignerModel::Motion) {}

Aligner::Aligner(ocl::Runtime& runtime, const Eigen::Matrix3d& K, const AlignerOptions& options, AlignerModel model)
    : K_(K), options_(options), model_(model), with_orientation_(model == AlignerModel::CameraTilt),
      nparam_(model_nparam(model)), runtime_(runtime),
      pass_(runtime, nparam_, kernel_options(options, false)),
      stats_pass_(runtime, nparam_, kernel_options(options, true)) {
  // The subsampled passes the options ask for, built now rather than at the first frame that
  // reaches their level.
  if (model == AlignerModel::LocalPlane) {
    attitude_pass_ = std::make_unique<WarpReduce>(runtime, kMotionParams + kAttitudeParams, kernel_options(options, false));
    attitude_stats_pass_ =
        std::make_unique<WarpReduce>(runtime, kMotionParams + kAttitudeParams, kernel_options(options, true));
  }
  for (int b : options.select_blocks)
    if (b >= 2) select_passes(b, nparam_);
  if (options.finest_level < 0 && options.auto_finer_block >= 2) {
    select_passes(options.auto_finer_block, nparam_);
    if (options.auto_coarse_block >= 2) select_passes(options.auto_coarse_block, nparam_);
  }
}

std::array<std::unique_ptr<WarpReduce>, 2>& Aligner::select_passes(int block, int nparam) {
  std::array<std::unique_ptr<WarpReduce>, 2>& passes = select_passes_[{block, nparam}];
  if (!passes[0])
    for (int st : {0, 1}) {
      WarpReduceOptions k = kernel_options(options_, st == 1);
      k.select_block = block;
      passes[static_cast<size_t>(st)] = std::make_unique<WarpReduce>(runtime_, nparam, k);
    }
  return passes;
}

AlignmentLevels Aligner::levels(const Pyramid& reference, const Pyramid& live) const {
  AlignmentLevels r;
  int n = std::min({options_.levels, live.num_levels(), reference.num_levels(), kMaxLevels});
  while (n > 1 && (live.levels[static_cast<size_t>(n - 1)].width < kMinLevelSide ||
                   live.levels[static_cast<size_t>(n - 1)].height < kMinLevelSide))
    --n;
  r.coarsest = std::max(0, n - 1);
  r.select_block = options_.select_blocks;
  int finest = options_.finest_level;
  if (finest < 0) {
    finest = 0;
    while (finest < r.coarsest &&
           live.levels[static_cast<size_t>(finest + 1)].width >= options_.min_finest_width)
      ++finest;
    if (finest > 0 && options_.auto_finer_block >= 1) {
      // A itself subsampled (auto_coarse_block) when the level below it is.
      int& a = r.select_block[static_cast<size_t>(finest)];
      if (a < 2 && options_.auto_finer_block >= 2 && options_.auto_coarse_block >= 2) a = options_.auto_coarse_block;
      --finest;
      int& b = r.select_block[static_cast<size_t>(finest)];
      if (b < 2) b = options_.auto_finer_block >= 2 ? options_.auto_finer_block : 0;
    }
  }
  r.finest = std::clamp(finest, 0, r.coarsest);
  return r;
}

double Aligner::texture(const Pyramid& pyramid, int level) {
  const PyramidLevel& L = pyramid.levels[static_cast<size_t>(level)];
  WarpInputs in;
  in.nparam = nparam_;
  for (Eigen::Matrix3d& G : in.G) G.setZero();
  in.huber_k = 1e30;
  ReduceSums s;
  stats_pass_.run(L.data, L.width, L.height, L.data, L.width, L.height, in, &s);
  return s.valid > 0 ? s.gref / s.valid : 0.0;
}

bool Aligner::attitude_level(const AlignmentPair& pair, int level, const AlignmentLevels& levels) const {
  return model_ == AlignerModel::LocalPlane &&
         (level == levels.coarsest ||
          pair.live->levels[static_cast<size_t>(level)].width <= options_.attitude_max_width);
}

void Aligner::evaluate(const AlignmentPair& pair, const Extrinsics& e, int level, bool stats,
                       ReduceSums* out, bool attitudes) {
  const PyramidLevel& R = pair.reference->levels[static_cast<size_t>(level)];
  const PyramidLevel& L = pair.live->levels[static_cast<size_t>(level)];
  const Eigen::Matrix3d Kl = level_camera_matrix(K_, level);
  const MotionHomography mh =
      model_ == AlignerModel::LocalPlane
          ? local_plane_homography(Kl, e, pair.motion, pair.reference_attitude, pair.live_attitude)
          : motion_homography(Kl, e, pair.motion, with_orientation_);
  WarpInputs in;
  in.H = mh.H;
  // The local plane's finer levels hold the attitudes: the motion's generators only.
  in.nparam = model_ == AlignerModel::LocalPlane && !attitudes ? kMotionParams : mh.nparam;
  for (size_t i = 0; i < static_cast<size_t>(in.nparam); ++i) in.G[i] = mh.G[i];
  in.gain = std::exp(pair.log_gain);
  in.bias = pair.bias;
  in.huber_k = options_.huber_factor * pair.sigma[static_cast<size_t>(level)];
  const SelectedPixels* sel = selection_at(pair, level);
  if (!sel) {
    if (attitudes)
      (stats ? *attitude_stats_pass_ : *attitude_pass_).run(R.data, R.width, R.height, L.data, L.width, L.height, in, out);
    else
      (stats ? stats_pass_ : pass_).run(R.data, R.width, R.height, L.data, L.width, L.height, in, out);
    return;
  }
  select_passes(sel->block, in.nparam)[stats ? 1 : 0]->run(sel->data, sel->grid_w, sel->grid_h, L.data, L.width, L.height, in, out);
}

const SelectedPixels* Aligner::selection_at(const AlignmentPair& pair, int level) {
  if (!pair.selection) return nullptr;
  const SelectedPixels& sel = (*pair.selection)[static_cast<size_t>(level)];
  return sel.level == level && sel.block >= 2 ? &sel : nullptr;
}

double Aligner::reference_size(const AlignmentPair& pair, int level) {
  const SelectedPixels* sel = selection_at(pair, level);
  if (sel) return static_cast<double>(sel->grid_w) * sel->grid_h;
  const PyramidLevel& R = pair.reference->levels[static_cast<size_t>(level)];
  return static_cast<double>(R.width) * R.height;
}

// The damped Gauss-Newton step of the whole system: each pair's own block eliminated onto the
// shared orientation (Schur complement), or on its own when nothing is shared. False when a
// block is not positive definite at this damping.
bool solve_joint(const std::vector<ReduceSums>& sums, bool brightness, bool orientation, double lambda,
                 JointStep* step) {
  const int nl = brightness ? 5 : 3;
  step->local.resize(sums.size());
  step->X.resize(sums.size());
  step->x.resize(sums.size());
  step->orientation.setZero();
  Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
  Eigen::Vector2d r = Eigen::Vector2d::Zero();
  std::vector<Matrix52d>& X = step->X;
  std::vector<Vector5d>& x = step->x;
  for (size_t p = 0; p < sums.size(); ++p) {
    PairBlock b = pair_block(sums[p], nl, orientation);
    damp(&b.A_ll, nl, lambda);
    const Eigen::LDLT<MatrixL> ldlt(MatrixL(b.A_ll.topLeftCorner(nl, nl)));
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return false;
    x[p].setZero();
    x[p].head(nl) = ldlt.solve(VectorL(b.g_l.head(nl)));
    if (!orientation) {
      step->local[p] = -x[p];
      if (!step->local[p].allFinite()) return false;
      continue;
    }
    X[p].setZero();
    X[p].topRows(nl) = ldlt.solve(MatrixL2(b.A_ls.topRows(nl)));
    damp(&b.A_ss, 2, lambda);
    S += b.A_ss - b.A_ls.topRows(nl).transpose() * X[p].topRows(nl);
    r += b.g_s - b.A_ls.topRows(nl).transpose() * x[p].head(nl);
  }
  if (!orientation) return true;
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(S);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return false;
  step->orientation = -ldlt.solve(r);
  if (!step->orientation.allFinite()) return false;
  for (size_t p = 0; p < sums.size(); ++p) {
    step->local[p] = -(x[p] + X[p] * step->orientation);
    if (!step->local[p].allFinite()) return false;
  }
  return true;
}

bool solve_dense(const ReduceSums& sums, int n, double lambda, PriorVector* step) {
  MatrixL A = sums_block(sums, n);
  damp(&A, n, lambda);
  const Eigen::LDLT<MatrixL> ldlt(A);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return false;
  *step = -ldlt.solve(sums_gradient(sums, n));
  return step->allFinite();
}

Eigen::Matrix2d joint_orientation_information(const std::vector<ReduceSums>& sums, bool brightness) {
  const int nl = brightness ? 5 : 3;
  Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
  for (const ReduceSums& s : sums) {
    const PairBlock b = pair_block(s, nl, true);
    const Eigen::LDLT<MatrixL> ldlt(MatrixL(b.A_ll.topLeftCorner(nl, nl)));
    const MatrixL2 X = ldlt.solve(MatrixL2(b.A_ls.topRows(nl)));
    S += b.A_ss - b.A_ls.topRows(nl).transpose() * X;
  }
  return S;
}

// The prior's information per pair at a subsampled level (empty: none), formed once for the
// level: the level before it's estimate as a Gaussian prior with its J^T W J (in this level's
// noise units, (sigma_here / sigma_there)^2), so that the subsample adds the fine texture's
// information to the coarser level's instead of replacing it. The prior's parameters are the
// sums' own first n (motion, the local plane's attitudes, brightness), so its indices in the sums
// are 0 .. n-1 (the shared tilt has no such prior).
void Aligner::form_level_priors(const std::vector<AlignmentPair>& pairs, const Level& lv) {
  const size_t P = pairs.size();
  prior_H_.assign(P, MatrixL());
  if (!(options_.subsample_prior && have_prev_ && !with_orientation_ && prev_attitudes_ == lv.att)) return;
  for (size_t p = 0; p < P; ++p)
    if (selection_at(pairs[p], lv.level) != nullptr && prev_sigma_[p] > 0.0) {
      prior_H_[p] = std::pow(measured_[p] / prev_sigma_[p], 2) * sums_block(prev_sums_[p], lv.n);
      prior_H_[p] *= prior_scale_of(cur_[p], prior_H_[p], prior_error(prev_state_[p], pairs[p], lv.att, lv.brightness),
                                    measured_[p], options_.prior_chi2);
    }
}

// Adds information H (cost units) on the sums' parameters `first` .. first + e.size() - 1 at the
// state's error e from its mean.
void Aligner::add_prior(size_t p, const PriorMatrix& H, const PriorVector& e, int first, ReduceSums* sums) const {
  const VectorL He = H * e;
  // For the covariance's sandwich (tracker.cpp): the prior is the Huber cost's Hessian too, and
  // its score, H e with e's covariance sigma_there^2 A_there^-1, has the covariance sigma_here^2 H
  // in this level's units.
  const int nj = static_cast<int>(sums->JtWJ.rows());
  const bool bread = sums->has_stats && sums->JtJ_inlier.rows() == nj;
  const bool meat = sums->score_outer.rows() == nj;
  const double s2 = measured_[p] * measured_[p];
  const int m = static_cast<int>(e.size());
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      sums->JtWJ(first + i, first + j) += H(i, j);
      if (bread) sums->JtJ_inlier(first + i, first + j) += H(i, j);
      if (meat) sums->score_outer(first + i, first + j) += s2 * H(i, j);
    }
    sums->JtWr(first + i) += He(i);
  }
  sums->cost += 0.5 * e.dot(He);
}

// The attitudes' Gaussian prior (radians^-2) in this level's cost units: sigma^2 of the residuals
// (the data's J^T W J is the Hessian of sigma^2 times the negative log-likelihood).
PriorMatrix Aligner::attitude_prior(size_t p, const AlignmentPair& state) const {
  return measured_[p] * measured_[p] * state.attitude_prior_information;
}

void Aligner::apply_prior(size_t p, const AlignmentPair& state, const Level& lv, ReduceSums* sums) const {
  if (prior_H_[p].rows() > 0)
    add_prior(p, prior_H_[p], prior_error(prev_state_[p], state, lv.att, lv.brightness), 0, sums);
  // The coarser level's information (prior_H) holds the data only: its own attitude prior was
  // taken out (finish_level), so that the consistency scale, which weakens prior_H when the
  // motions disagree, does not weaken the attitudes' prior.
  if (lv.attitude_priors) add_prior(p, attitude_prior(p, state), VectorL(attitude_error(state)), kMotionParams, sums);
}

// Each pair's first pass at the level, and the level's robust scale from its residuals. The
// threshold in use came with the pair (a tracker's previous frame); when the scale has moved by
// more than rescale_ratio (the robot starts moving after standing still, the exposure jumps,
// something covers the ground), the level restarts with the new threshold: one more pass, and the
// cost stays one function within the level. The reason and the pair when a pair cannot be aligned.
const char* Aligner::measure_level(std::vector<AlignmentPair>& pairs, const Extrinsics& ext, const Level& lv,
                                   int* passes, size_t* failed) {
  for (size_t p = 0; p < pairs.size(); ++p) {
    AlignmentPair& pair = pairs[p];
    evaluate(pair, ext, lv.level, true, &cur_[p], lv.att);
    ++*passes;
    *failed = p;
    if (!(cur_[p].valid >= options_.min_valid_fraction * reference_size(pair, lv.level))) return kAlignFewValid;
    if (!(cur_[p].glive >= options_.min_texture_ratio * cur_[p].gref)) return kAlignNoLiveTexture;
    measured_[p] = std::clamp(kMadToSigma * cur_[p].median_abs_residual(), options_.min_sigma, options_.max_sigma);
    double& used = pair.sigma[lv.L];
    if (!(measured_[p] <= used * options_.rescale_ratio && measured_[p] >= used / options_.rescale_ratio)) {
      used = measured_[p];
      evaluate(pair, ext, lv.level, true, &cur_[p], lv.att);
      ++*passes;
    }
  }
  return nullptr;
}

// The candidates of the solved step (cand_) and the largest pixel displacement they make.
double Aligner::candidate_step(const std::vector<AlignmentPair>& pairs, const Extrinsics& ext,
                               const Extrinsics& cand_ext, const Level& lv) {
  double step_px = 0.0;
  for (size_t p = 0; p < pairs.size(); ++p) {
    cand_[p] = pairs[p];
    const PyramidLevel& R = pairs[p].reference->levels[lv.L];
    if (model_ == AlignerModel::LocalPlane) {
      const VectorL& d = dense_step_;
      cand_[p].motion = pairs[p].motion * SE2::exp(d.head<3>());
      int i = kMotionParams;
      if (lv.att) {
        cand_[p].reference_attitude = {pairs[p].reference_attitude.roll + d(3), pairs[p].reference_attitude.pitch + d(4)};
        cand_[p].live_attitude = {pairs[p].live_attitude.roll + d(5), pairs[p].live_attitude.pitch + d(6)};
        i += kAttitudeParams;
      }
      if (lv.brightness) {
        cand_[p].log_gain = pairs[p].log_gain + d(i);
        cand_[p].bias = pairs[p].bias + d(i + 1);
      }
      auto H = [&](const AlignmentPair& a) {
        return ground_homography(lv.Kl, on_plane(ext, a.reference_attitude), on_plane(ext, a.live_attitude),
                                 a.motion.matrix3d());
      };
      step_px = std::max(step_px, max_pixel_displacement(H(pairs[p]), H(cand_[p]), R.width, R.height));
      continue;
    }
    const Vector5d& d = step_.local[p];
    cand_[p].motion = pairs[p].motion * SE2::exp(d.head<3>());
    cand_[p].log_gain = pairs[p].log_gain + d(3);
    cand_[p].bias = pairs[p].bias + d(4);
    step_px = std::max(step_px, max_pixel_displacement(lv.Kl, ext, pairs[p].motion, cand_ext, cand_[p].motion,
                                                       R.width, R.height));
  }
  return step_px;
}

// Levenberg-Marquardt at the level: a damped step of the joint system (or the local plane's dense
// one), checked by a pass over every pair unless it is below the convergence threshold.
void Aligner::iterate_level(std::vector<AlignmentPair>& pairs, Extrinsics* ext, const Level& lv, int* passes) {
  const size_t P = pairs.size();
  double lambda = 0.0;
  int steps = 0;
  const int max_steps = std::max(1, options_.max_iterations[lv.L]);
  cand_ = pairs;
  while (steps < max_steps) {
    const bool solved = model_ == AlignerModel::LocalPlane
                            ? solve_dense(cur_[0], lv.n, lambda, &dense_step_)
                            : solve_joint(cur_, lv.brightness, with_orientation_, lambda, &step_);
    if (!solved) {
      if (lambda >= 1e8) break;
      lambda = lambda == 0.0 ? options_.lambda_min : lambda * options_.lambda_up;
      continue;
    }
    ++steps;
    const Extrinsics cand_ext = with_orientation_ ? rotate_orientation(*ext, step_.orientation) : *ext;
    const double step_px = candidate_step(pairs, *ext, cand_ext, lv);
    if (!(step_px < 1e6)) {
      lambda = lambda == 0.0 ? options_.lambda_min : lambda * options_.lambda_up;
      continue;
    }
    // A step below the convergence threshold, or a small last one, is applied without the passes
    // that would check it.
    if (step_px < options_.convergence_px || (steps == max_steps && step_px < 0.5)) {
      std::copy(cand_.begin(), cand_.end(), pairs.begin());  // elements, not buffers: callers keep references
      *ext = cand_ext;
      break;
    }
    bool valid = true;
    for (size_t p = 0; p < P; ++p) {
      evaluate(cand_[p], cand_ext, lv.level, false, &next_[p], lv.att);
      apply_prior(p, cand_[p], lv, &next_[p]);
      ++*passes;
      valid = valid && next_[p].valid >= options_.min_valid_fraction * reference_size(pairs[p], lv.level);
    }
    if (valid && mean_cost(next_) <= mean_cost(cur_)) {
      std::copy(cand_.begin(), cand_.end(), pairs.begin());  // elements, not buffers: callers keep references
      *ext = cand_ext;
      cur_.swap(next_);
      lambda = lambda / options_.lambda_down < options_.lambda_min ? 0.0 : lambda / options_.lambda_down;
    } else {
      lambda = lambda == 0.0 ? options_.lambda_min : lambda * options_.lambda_up;
    }
  }
}

// What the next level and the report keep of this one.
void Aligner::finish_level(std::vector<AlignmentPair>& pairs, const Level& lv, bool finest, AlignmentReport& report) {
  const size_t P = pairs.size();
  if (finest) {
    report.finest_huber_k.resize(P);
    for (size_t p = 0; p < P; ++p) report.finest_huber_k[p] = options_.huber_factor * pairs[p].sigma[lv.L];
  }
  for (size_t p = 0; p < P; ++p) pairs[p].sigma[lv.L] = measured_[p];
  if (lv.att) {
    report.attitude_level = lv.level;
    report.attitude_sums = cur_[0];
  }
  if (finest) report.finest_nparam = lv.att ? kMotionParams + kAttitudeParams : nparam_;
  prev_attitudes_ = lv.att;
  prev_sums_ = cur_;
  if (lv.attitude_priors)
    for (size_t p = 0; p < P; ++p)
      prev_sums_[p].JtWJ.block(kMotionParams, kMotionParams, kAttitudeParams, kAttitudeParams) -=
          attitude_prior(p, pairs[p]);
  prev_state_ = pairs;
  prev_sigma_ = measured_;
  have_prev_ = true;
}

AlignmentReport Aligner::align(std::vector<AlignmentPair>& pairs, Extrinsics* extrinsics,
                               const AlignmentLevels& levels) {
  AlignmentReport report;
  const size_t P = pairs.size();
  cur_.resize(P);
  next_.resize(P);
  report.finest_sigma.assign(P, 0.0);
  measured_.assign(P, 0.0);
  Extrinsics ext = *extrinsics;
  const bool local_plane = model_ == AlignerModel::LocalPlane;
  if (local_plane && P != 1) throw_invalid_argument("Aligner: the local plane aligns one image pair");
  auto fail = [&](const char* why, size_t p) {
    report.ok = false;
    report.reason = why;
    report.failed_pair = static_cast<int>(p);
    *extrinsics = ext;
    return report;
  };
  for (AlignmentPair& pair : pairs)
    for (double& s : pair.sigma)
      if (!(s > 0.0)) s = options_.initial_sigma;
  have_prev_ = false;

  for (int level = levels.coarsest; level >= levels.finest; --level) {
    ++report.levels_used;
    Level lv;
    lv.level = level;
    lv.L = static_cast<size_t>(level);
    // This level estimates the local plane's attitudes (the seven-parameter pass), or holds them.
    lv.att = local_plane && attitude_level(pairs[0], level, levels);
    lv.brightness = options_.estimate_brightness;
    lv.n = (lv.att ? kMotionParams + kAttitudeParams : nparam_) + (lv.brightness ? 2 : 0);
    lv.attitude_priors = lv.att && !pairs[0].attitude_prior_information.isZero();
    lv.Kl = level_camera_matrix(K_, level);
    const auto level_start = std::chrono::steady_clock::now();
    int& passes = report.passes[lv.L];
    size_t failed = 0;
    if (const char* why = measure_level(pairs, ext, lv, &passes, &failed)) return fail(why, failed);
    if (level == levels.finest) report.finest_sigma = measured_;
    if (level == std::max(levels.finest, std::min(1, levels.coarsest))) report.match_stats = cur_;
    form_level_priors(pairs, lv);
    for (size_t p = 0; p < P; ++p) apply_prior(p, pairs[p], lv, &cur_[p]);
    if (level == levels.finest) report.finest_stats = cur_;  // with the prior (if any), for the covariance
    if (lv.att) report.attitude_stats = cur_[0];
    iterate_level(pairs, &ext, lv, &passes);
    finish_level(pairs, lv, level == levels.finest, report);
    report.level_ms[lv.L] =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - level_start).count();
    for (size_t p = 0; p < P; ++p)
      if (!finite(pairs[p].motion) || !std::isfinite(pairs[p].log_gain) || !std::isfinite(pairs[p].bias) ||
          !std::isfinite(pairs[p].reference_attitude.roll + pairs[p].reference_attitude.pitch +
                         pairs[p].live_attitude.roll + pairs[p].live_attitude.pitch))
        return fail(kAlignDiverged, p);
    if (!std::isfinite(ext.roll) || !std::isfinite(ext.pitch)) return fail(kAlignDiverged, 0);
  }
  report.finest = cur_;
  for (const ReduceSums& s : cur_) {
    report.total_wrr += s.wrr;
    report.total_valid += s.valid;
  }
  if (with_orientation_) report.orientation_information = joint_orientation_information(cur_, options_.estimate_brightness);
  report.ok = true;
  *extrinsics = ext;
  return report;
}

}  // namespace planarvo::track
