// The one coarse-to-fine damped Gauss-Newton (ESM) aligner of the engine (paper eqs. 10-13 and
// 19-24), used by the planar tracker (one image pair; the motion and an affine brightness change)
// and by the roll/pitch estimator of section 5.1 (several keyframe pairs sharing the camera's
// orientation to the ground).
//
// Each image pair p has its own block of parameters, its planar motion T_p (3) and brightness
// (a_p, b_p) (2, optional), and all pairs may share the camera's tilt y (2, warp_model.h). Each
// pair is one fused pass (kernels/track/warp_reduce.cl, NPARAM 3 or 5: a fixed size whatever the
// number of pairs) whose sums give that pair's block of the normal equations; the joint system
// over all pairs has the block-arrow structure of a bundle adjustment and is solved on the host
// by eliminating each pair's block (Schur complement onto y). Levenberg damping on the total
// robust cost; robust scale per pair and level from the STATS pass's histogram.
#pragma once
#include <array>
#include <map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/body_attitude.h"
#include "core/extrinsics.h"
#include "core/se2.h"
#include <memory>

#include "image/pyramid.h"
#include "track/pixel_selection.h"
#include "track/warp_model.h"
#include "track/warp_reduce.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::track {

inline constexpr int kMaxLevels = 8;

// What the alignment does at each pyramid level (the tracker's options inherit these).
struct AlignerOptions {
  // Pyramid levels used, coarsest first: levels - 1 down to finest_level. Levels smaller than
  // 8x8 pixels are skipped.
  int levels = 4;
  // The finest level aligned: 0 is full resolution. -1 (the default): the coarsest level at
  // least min_finest_width pixels wide, A, on every pixel, and then (when A > 0) the level below
  // it on one pixel per auto_finer_block x auto_finer_block block with A's estimate as a prior
  // (select_blocks, subsample_prior): at 640x480 level 1 and then level 0 at 1/9, 1.4 times the
  // time of stopping at level 1 for 0.6-0.9 of its RMS error and 0.3-1.0 of its worst frame
  // (src/track/README.md, "The default"); at 320x240 level 0 on every pixel. auto_finer_block 1:
  // the level below A on every pixel; 0: stop at A. When the level below A is subsampled, A is
  // too, on one pixel per auto_coarse_block x auto_coarse_block block (2: at 640x480 level 1 at
  // 1/4 with level 2 as its prior: that pass in 0.64 of the time, the frame 9-10 % faster, the
  // same per-frame RMS on the benchmark's scenes; test/bench/results/track.md, "Speed (issue 28 ...)");
  // 0 or 1: A on every pixel.
  int finest_level = -1;
  int min_finest_width = 320;
  int auto_finer_block = 3;
  int auto_coarse_block = 2;
  // Gauss-Newton steps per level, index = level (each step costs one fused pass per pair at that
  // level except the last, which is applied without checking when it is below convergence_px).
  std::array<int, kMaxLevels> max_iterations = {2, 6, 10, 12, 12, 12, 12, 12};
  // Convergence: a step that moves no pixel of the level (its corners and centre, in any pair)
  // by more than this many pixels of that level ends the level.
  double convergence_px = 0.05;
  // Huber threshold k = huber_factor * sigma, sigma = 1.4826 * median |r| per pair and level
  // (clamped to [min_sigma, max_sigma]), measured at the level's first pass. That pass is
  // weighted with the sigma the pair brought (initial_sigma at first); when the new one differs
  // by more than a factor rescale_ratio the level restarts with it (one more pass), so that the
  // cost is one function within a level.
  double huber_factor = 2.0;
  double initial_sigma = 8.0, min_sigma = 0.5, max_sigma = 40.0;  // grey levels
  double rescale_ratio = 1.25;
  // Subsampled levels (pixel_selection.h): at level l with select_blocks[l] = B >= 2, a tracker
  // aligns one pixel per B x B block of its keyframe's level (a jittered grid, chosen once per
  // keyframe); 0 or 1: every pixel of the level.
  std::array<int, kMaxLevels> select_blocks = {0, 0, 0, 0, 0, 0, 0, 0};
  bool subsample_prior = true;
  // The prior's covariance is inflated when the subsampled level's own estimate and the prior
  // differ by more than their covariances explain (prior_consistency_scale below): until the
  // difference's chi-square (3 degrees of freedom) is prior_chi2. 3, its expected value, matches
  // the covariance to the discrepancy (as adaptive Kalman filters match innovations); 11.34 (1 %
  // of consistent cases) kept the rear cameras' NEES at 8-9 and their worst frames 5-10 % larger
  // (src/track/README.md, "The default"). 0: the prior always at full weight.
  double prior_chi2 = 3.0;
  // Estimate the affine brightness change (r = e^a I_l + b - I_r) jointly with the motion.
  bool estimate_brightness = true;
  // Levenberg damping: H + lambda diag(H); lambda starts at 0 (Gauss-Newton) and grows by
  // lambda_up (from lambda_min) when a step increases the cost, shrinks by lambda_down after
  // an accepted step.
  double lambda_min = 1e-4, lambda_up = 10.0, lambda_down = 10.0;
  // A pair fails (the reason says which) with fewer valid pixels than min_valid_fraction of the
  // level's, or with live texture (mean squared gradient over the overlap) below
  // min_texture_ratio of the reference's.
  double min_valid_fraction = 0.05;
  double min_texture_ratio = 0.1;
  // The fused pass's work-group shape etc. (stats and debug_output are set by the aligner).
  WarpReduceOptions kernel = WarpReduceOptions();
  // AlignerModel::LocalPlane: the attitudes are estimated on the levels at most this many pixels
  // wide (and on the coarsest level in any case), with the seven-parameter pass; the finer levels
  // align the motion alone (the three-parameter pass) with the attitudes where the coarser ones
  // left them. 160: levels 2-3 at 640x480, 1-3 at 320x240 (src/track/README.md, "The local plane").
  int attitude_max_width = 1 << 30;
};

// What the homography's parameters are beyond the planar motion (warp_model.h).
enum class AlignerModel {
  Motion,      // the planar motion only (NPARAM 3): the tracker on a rigid body
  CameraTilt,  // the pairs share the camera's tilt about its centre (NPARAM 5): roll and pitch
               // calibration (section 5.1), updating the extrinsics
  LocalPlane,  // the body's attitude relative to the local ground plane at the reference and at
               // the live frame (NPARAM 7, section 6.4), per pair, with a Gaussian prior; one pair
};

// One image pair and the estimate of its own parameters: the live robot pose in the reference
// robot frame and the brightness of the live image relative to the reference.
struct AlignmentPair {
  const Pyramid* reference = nullptr;
  const Pyramid* live = nullptr;
  // The reference's selected pixels per level (pixel_selection.h), which stand for the
  // reference at their level; nullptr, or an entry whose level is -1: every pixel of that level.
  const std::array<SelectedPixels, kMaxLevels>* selection = nullptr;
  SE2 motion;
  double log_gain = 0.0, bias = 0.0;
  // The robust scale per level (grey levels): brought in (a tracker keeps it from frame to
  // frame; 0 means initial_sigma) and left as measured.
  std::array<double, kMaxLevels> sigma{};
  // AlignerModel::LocalPlane: the body's attitude at the reference and at the live frame (both
  // estimated, from these values), and their Gaussian prior over (reference roll, reference
  // pitch, live roll, live pitch): mean and information (radians^-2; zero: no prior).
  BodyAttitude reference_attitude, live_attitude;
  Eigen::Vector4d attitude_prior_mean = Eigen::Vector4d::Zero();
  Eigen::Matrix4d attitude_prior_information = Eigen::Matrix4d::Zero();
};

struct AlignmentLevels {
  int coarsest = 0, finest = 0;
  // Per level: B >= 2 aligns one pixel per B x B block of the reference (a tracker's keyframe
  // selection at that level); 0, every pixel.
  std::array<int, kMaxLevels> select_block{};
};

struct AlignmentReport {
  bool ok = false;
  const char* reason = "";  // why not ok (one of the reasons below)
  int failed_pair = -1;
  std::array<int, kMaxLevels> passes{};      // fused passes per level, all pairs
  std::array<double, kMaxLevels> level_ms{};  // wall time per level
  int levels_used = 0;
  // Per pair, at the finest level: the sums of the last pass at the estimate (its J^T W J for
  // the covariance), the STATS pass that opened the level, and the robust scale measured there.
  std::vector<ReduceSums> finest;
  std::vector<ReduceSums> finest_stats;
  // Per pair, the STATS pass that opened the finest level at half resolution or coarser (the
  // finest level itself when that is level 1 or coarser, or the only level): where pixel noise
  // does not yet mask the texture, so a residual measured there says whether the images match.
  std::vector<ReduceSums> match_stats;
  std::vector<double> finest_sigma;
  // Per pair, the Huber threshold k the finest level's passes were weighted with (huber_factor
  // times the scale in use there: finest_sigma, or the one the pair brought when within
  // rescale_ratio of it), grey levels.
  std::vector<double> finest_huber_k;
  // The homography's parameters at the finest level (the layout of `finest`): AlignerModel::
  // LocalPlane estimates the attitudes on the coarser levels only (attitude_max_width).
  int finest_nparam = kMotionParams;
  // AlignerModel::LocalPlane: the last level that estimated the attitudes, its last pass's sums
  // at the estimate and the STATS pass that opened it (both with the attitudes' prior), for the
  // attitudes' covariance; attitude_level -1 when none did.
  int attitude_level = -1;
  ReduceSums attitude_sums, attitude_stats;
  // With the orientation: its information (Schur complement of the whole system at the finest
  // level, undamped, unscaled: J^T W J in grey levels^-2 units) and sum of w r^2 and valid pixels
  // over all pairs, for the covariance sigma^2 S^-1.
  Eigen::Matrix2d orientation_information = Eigen::Matrix2d::Zero();
  double total_wrr = 0.0, total_valid = 0.0;
};

// Reasons (compared by address by the callers).
extern const char* const kAlignFewValid;       // "too few valid pixels"
extern const char* const kAlignNoLiveTexture;  // "no texture in the live frame"
extern const char* const kAlignDiverged;       // "diverged"

// A damped Gauss-Newton step of the joint system over image pairs: per pair its local block
// (motion, then brightness a, b when `brightness`) and, with `orientation`, the shared tilt.
struct JointStep {
  using Vector5d = Eigen::Matrix<double, 5, 1>;
  using Matrix52d = Eigen::Matrix<double, 5, 2>;
  std::vector<Vector5d> local;  // per pair: motion (3), then a, b (zero without brightness)
  Eigen::Vector2d orientation = Eigen::Vector2d::Zero();
  std::vector<Matrix52d> X;     // scratch: per pair A_ll^-1 A_ls
  std::vector<Vector5d> x;      // scratch: per pair A_ll^-1 g_l
};

// Solves (H + lambda diag(H) + ridge) delta = -g for the system whose pair blocks are the passes'
// sums (ReduceLayout's order: motion, tilt when NPARAM is 5, brightness) by eliminating each
// pair's block onto the tilt (Schur complement) and back-substituting. False when a block is not
// positive definite at this damping.
bool solve_joint(const std::vector<ReduceSums>& sums, bool brightness, bool orientation, double lambda,
                 JointStep* step);
// The tilt's information with every pair's block marginalised (undamped Schur complement).
Eigen::Matrix2d joint_orientation_information(const std::vector<ReduceSums>& sums, bool brightness);

// A subsampled level's prior (the coarser level's estimate, information H in this level's noise
// units: covariance sigma^2 H^-1, n x n over motion and brightness, n = 3 or 5) against the
// level's own data (A = J^T W J, g = J^T W r at the state, which lies at `e_motion` from the
// prior): the data alone's estimate is one Gauss-Newton step, -A^-1 g, from the state; its
// motion's difference dm from the prior has d^2 = dm^T (sigma^2 (A^-1 + H^-1)_motion)^-1 dm,
// chi-square with 3 degrees of freedom when both covariances are right. Returns 1 when d^2 <=
// chi2 (or chi2 <= 0), else the factor s on H that makes the inflated prior explain the
// difference (d^2 with H^-1 / s equal to chi2), 0 below 1e-6.
using PriorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJacobian, kMaxJacobian>;
using PriorVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJacobian, 1>;
double prior_consistency_scale(const PriorMatrix& A, const PriorVector& g, const PriorMatrix& H,
                               const Eigen::Vector3d& e_motion, double sigma, double chi2);
// Solves the first n parameters of one pass's sums (their own order) densely: (A + lambda
// diag(A) + ridge) step = -g. False when not positive definite at this damping.
bool solve_dense(const ReduceSums& sums, int n, double lambda, PriorVector* step);

class Aligner {
 public:
  // K: the camera matrix of level 0 (undistorted pinhole). with_orientation: the pairs share the
  // camera's tilt (NPARAM 5) and align() updates the extrinsics' roll and pitch.
  Aligner(ocl::Runtime& runtime, const Eigen::Matrix3d& K, const AlignerOptions& options,
          bool with_orientation);
  Aligner(ocl::Runtime& runtime, const Eigen::Matrix3d& K, const AlignerOptions& options, AlignerModel model);

  // The levels to align for pyramids like these (options' levels, finest_level, select_blocks
  // and auto_finer_block).
  AlignmentLevels levels(const Pyramid& reference, const Pyramid& live) const;

  // Aligns every pair from its current estimate, coarse to fine over `levels`, updating the
  // pairs' motions, brightness and scales, (with the orientation) *extrinsics and (the local
  // plane) the pairs' attitudes. The report says whether it worked; the estimates are finite
  // either way (the last good ones). The local plane aligns one pair (InvalidArgument otherwise).
  AlignmentReport align(std::vector<AlignmentPair>& pairs, Extrinsics* extrinsics,
                        const AlignmentLevels& levels);

  // Texture of a pyramid level on its own: mean squared gradient (grey levels^2 per pixel^2, a
  // pass of the level against itself), for a frame that has nothing to be compared with.
  double texture(const Pyramid& pyramid, int level);

  // J^T W J of a pair's local block (motion and brightness, the orientation marginalised out
  // is not included): the inverse of its motion block's covariance up to sigma^2. n = 3 or 5.
  int local_size() const { return options_.estimate_brightness ? 5 : 3; }
  bool with_orientation() const { return with_orientation_; }
  AlignerModel model() const { return model_; }
  const AlignerOptions& options() const { return options_; }

 private:
  void evaluate(const AlignmentPair& pair, const Extrinsics& e, int level, bool stats, ReduceSums* out,
                bool attitudes = false);
  // align()'s steps, level by level (aligner.cpp): what a level is, its first passes and robust
  // scale, the subsample's prior, the damped iterations, and what the next level keeps.
  struct Level {
    int level = 0;
    size_t L = 0;
    bool att = false;         // the local plane's attitudes are estimated at this level
    bool brightness = false;  // gain and bias are estimated
    int n = 0;                // the prior's parameters: the sums' first n
    bool attitude_priors = false;
    Eigen::Matrix3d Kl;       // the level's camera matrix
  };
  const char* measure_level(std::vector<AlignmentPair>& pairs, const Extrinsics& ext, const Level& lv, int* passes,
                            size_t* failed);
  void form_level_priors(const std::vector<AlignmentPair>& pairs, const Level& lv);
  void add_prior(size_t p, const PriorMatrix& H, const PriorVector& e, int first, ReduceSums* sums) const;
  PriorMatrix attitude_prior(size_t p, const AlignmentPair& state) const;
  void apply_prior(size_t p, const AlignmentPair& state, const Level& lv, ReduceSums* sums) const;
  double candidate_step(const std::vector<AlignmentPair>& pairs, const Extrinsics& ext, const Extrinsics& cand_ext,
                        const Level& lv);
  void iterate_level(std::vector<AlignmentPair>& pairs, Extrinsics* ext, const Level& lv, int* passes);
  void finish_level(std::vector<AlignmentPair>& pairs, const Level& lv, bool finest, AlignmentReport& report);
  // AlignerModel::LocalPlane: whether `level` estimates the attitudes (attitude_max_width).
  bool attitude_level(const AlignmentPair& pair, int level, const AlignmentLevels& levels) const;
  // The reference's size at `level` as the pass sees it: the level's pixels, or its selection's grid.
  static double reference_size(const AlignmentPair& pair, int level);

  Eigen::Matrix3d K_;
  AlignerOptions options_;
  AlignerModel model_;
  bool with_orientation_;  // model_ == CameraTilt
  int nparam_;
  ocl::Runtime& runtime_;
  WarpReduce pass_, stats_pass_;
  std::unique_ptr<WarpReduce> attitude_pass_, attitude_stats_pass_;  // LocalPlane: NPARAM 7
  // The passes over selected pixels (plain, STATS) per block size, made when first needed.
  // Keyed by block size and NPARAM (the local plane's attitude levels use 7).
  std::map<std::pair<int, int>, std::array<std::unique_ptr<WarpReduce>, 2>> select_passes_;
  std::array<std::unique_ptr<WarpReduce>, 2>& select_passes(int block, int nparam);
  static const SelectedPixels* selection_at(const AlignmentPair& pair, int level);
  // The level just aligned: its last sums, the pairs' estimates and robust scales.
  std::vector<ReduceSums> prev_sums_;
  std::vector<AlignmentPair> prev_state_;
  std::vector<double> prev_sigma_;
  bool have_prev_ = false;
  bool prev_attitudes_ = false;  // the level just aligned estimated the attitudes (its sums' layout)
  // Per pair, the prior's J^T W J at a subsampled level.
  std::vector<PriorMatrix> prior_H_;
  std::vector<ReduceSums> cur_, next_;
  std::vector<AlignmentPair> cand_;
  std::vector<double> measured_;
  JointStep step_;
  PriorVector dense_step_;
};

}  // namespace planarvo::track
