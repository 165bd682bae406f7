#include "track/roll_pitch.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "image/band_pass.h"
#include "image/pipeline.h"
#include "track/light_learning.h"
#include "track/tracker.h"

namespace planarvo::track {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The camera's frame of section 5.1 (eq. 14): on the robot's origin, one unit above the ground,
// no yaw; only the tilt is the camera's.
Extrinsics camera_frame(double roll, double pitch) { return Extrinsics{0.0, 0.0, 1.0, roll, pitch, 0.0}; }

// A camera motion counts as moving above these (camera heights, radians).
constexpr double kMovedTranslation = 2e-3, kMovedRotation = 2e-3;
// Rounds of each leave-one-out alignment (jackknife_covariance): it starts at the estimate.
constexpr int kJackknifeRounds = 2;

std::string degrees(double rad) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f deg", rad * 180.0 / M_PI);
  return b;
}

}  // namespace

const char* status_name(RollPitchResult::Status s) {
  switch (s) {
    case RollPitchResult::Status::Ok: return "ok";
    case RollPitchResult::Status::TooLittleTexture: return "too little texture";
    case RollPitchResult::Status::TooLittleMotion: return "too little motion";
    case RollPitchResult::Status::Failed: return "failed";
  }
  return "?";
}

AlignerOptions RollPitchOptions::default_align() {
  AlignerOptions o;
  o.finest_level = 0;
  o.max_iterations = {4, 8, 10, 12, 12, 12, 12, 12};
  o.convergence_px = 0.02;
  return o;
}

struct RollPitchEstimator::Impl {
  ocl::Runtime& rt;
  CameraModel camera;
  RollPitchOptions opt;
  ImagePipeline pipeline;
  Tracker tracker;
  Aligner aligner;

  Pyramid spare;
  std::vector<Pyramid> keyframes;
  // A rolling shutter: each keyframe's camera frame and stamp, to undistort it again once the
  // joint alignment has measured the motion (unroll_keyframes).
  std::vector<cv::Mat> keyframe_gray;
  std::vector<double> keyframe_t;
  cv::Mat current;  // the frame being added (not a copy)
  double current_t = 0.0;
  std::vector<SE2> motions;  // between consecutive keyframes, from the tracker
  std::vector<int> keyframe_frames;
  SE2 since_keyframe;
  LightLearningGate light_gate;  // when the photometric model learns from a frame
  bool light_fitted = false;  // the photometric model was fitted (learn_light)
  bool band_passed = false;   // the keyframes are band-passed (estimate: from then on)
  bool moved = false, done = false;
  int frames = 0, frames_moving = 0, untextured = 0, restarts = 0;
  double track_ms = 0.0;

  static TrackerOptions tracker_options(const RollPitchOptions& o) {
    TrackerOptions t;
    t.levels = o.align.levels;
    t.kernel = o.align.kernel;
    t.keyframe_overlap = o.keyframe_overlap;
    // At a wrong tilt the ground's homography cannot align two frames exactly: the residual stays
    // large but the motion is roughly right, which is all the map needs from this tracker (the
    // joint alignment decides). Only frames that cannot be aligned at all are lost.
    t.lost_residual_ratio = 2.0;
    t.degraded_residual_ratio = 2.0;
    t.min_inlier_fraction = 0.0;
    t.max_log_gain = 3.0;
    // A wrong tilt misaligns the texture too: measured (for the photometric model's learning,
    // learn_light) but never Lost for it.
    t.max_texture_residual = std::numeric_limits<double>::max();
    return t;
  }

  static ImagePipelineOptions pipeline_options(const RollPitchOptions& o) {
    ImagePipelineOptions p;
    p.photometric = o.photometric;
    return p;
  }

  // The photometric model learns from the frame just tracked when the floor moved
  // (light_learning.h, with the tracker's default thresholds: this tracker measures the texture
  // residual but never judges it, and a wrong tilt leaves texture too, while the floor moved just
  // the same). True when a model other than the identity was fitted now.
  bool learn_light(const FrameResult& r) {
    PhotometricModel* model = pipeline.photometric();
    if (!model || !model->learning()) return false;
    if (r.status == FrameResult::Status::First) {
      pipeline.learn();
      light_gate.learnt();
      return false;
    }
    // After the fit too: the statistics go on to the end of the map, for final_light().
    if (light_gate.learn_from(r)) pipeline.learn();
    // Fitted once here, so from settled statistics (a model from fewer frames would stay in every
    // keyframe of the map).
    if (light_fitted || model->frames() < kPhotometricSettledFrames || !model->refit_due()) return false;
    model->refit();
    light_fitted = true;
    return !model->fit().uniform;
  }

  static const RollPitchOptions& validated(const RollPitchOptions& o) {
    if (o.min_keyframes < 2 || o.max_keyframes < o.min_keyframes)
      throw_invalid_argument("roll/pitch: need 2 <= min_keyframes <= max_keyframes");
    if (!(o.keyframe_overlap > 0.0 && o.keyframe_overlap < 1.0))
      throw_invalid_argument("roll/pitch: keyframe_overlap must be in (0, 1)");
    if (o.max_frames < 0 || o.max_rounds < 1 || o.light_frames < 0 || o.max_unrolls < 0)
      throw_invalid_argument("roll/pitch: max_frames >= 0, max_rounds >= 1, light_frames >= 0, max_unrolls >= 0");
    if (!(o.band_pass_sigma >= 0.0) || !std::isfinite(o.band_pass_sigma))
      throw_invalid_argument("roll/pitch: band_pass_sigma must be >= 0 and finite");
    if (!std::isfinite(o.initial_roll) || !std::isfinite(o.initial_pitch))
      throw_invalid_argument("roll/pitch: the initial orientation must be finite");
    return o;
  }

  Impl(ocl::Runtime& r, const CameraModel& c, const RollPitchOptions& o)
      : rt(r), camera(c), opt(validated(o)), pipeline(r, c, o.align.levels, pipeline_options(o)),
        tracker(r, c, camera_frame(o.initial_roll, o.initial_pitch), tracker_options(o)),
        aligner(r, c.K(), o.align, true),
        light_gate(c.K(), c.width, c.height, camera_frame(o.initial_roll, o.initial_pitch),
                   TrackerOptions().learn_motion_px, TrackerOptions().max_texture_residual) {}

  bool add_frame(const uint8_t* gray, int width, int height, size_t stride, double t) {
    if (done) return true;
    const auto t0 = Clock::now();
    ++frames;
    if (moved) ++frames_moving;
    if (!gray || width != camera.width || height != camera.height || stride < static_cast<size_t>(width)) {
      ++untextured;  // not usable: counted with the frames that could not be tracked
      return finish_frame(t0);
    }
    pipeline.process(gray, width, height, stride, spare);
    current = cv::Mat(height, width, CV_8UC1, const_cast<uint8_t*>(gray), stride);
    current_t = t;
    const FrameResult r = tracker.track(spare, t);
    if (learn_light(r)) {
      // The light is taken out from the next frame on: the map starts again there, so that its
      // keyframes are all corrected alike.
      tracker.reset();
      keyframes.clear();
      motions.clear();
      ++restarts;
      return finish_frame(t0);
    }
    if (r.status == FrameResult::Status::First) {
      start_map();
      return finish_frame(t0);
    }
    if (r.status == FrameResult::Status::Lost) {
      ++untextured;
      if (r.keyframe) restart_map();  // the chain of motions is broken here
      return finish_frame(t0);
    }
    since_keyframe = since_keyframe * r.motion.value;
    if (!moved && (std::hypot(since_keyframe.x, since_keyframe.y) > kMovedTranslation ||
                   std::abs(since_keyframe.theta) > kMovedRotation))
      moved = true;
    if (r.keyframe && static_cast<int>(keyframes.size()) < opt.max_keyframes) {
      keyframes.push_back(std::move(spare));
      keyframe_frames.push_back(frames - 1);
      keep_current();
      spare = Pyramid();
      motions.push_back(since_keyframe);
      since_keyframe = SE2();
    }
    return finish_frame(t0);
  }

  // A lost frame became the tracker's new keyframe: keep the map if it is already usable, else
  // start a new one from this frame.
  void restart_map() {
    if (static_cast<int>(keyframes.size()) >= opt.min_keyframes) {
      done = true;
      return;
    }
    ++restarts;
    start_map();
  }

  // The frame just fed (its pyramid in `spare`) becomes the map's first keyframe.
  void start_map() {
    keyframes.clear();
    motions.clear();
    keyframe_frames.clear();
    keyframe_gray.clear();
    keyframe_t.clear();
    keyframes.push_back(std::move(spare));
    keyframe_frames.push_back(frames - 1);
    keep_current();
    spare = Pyramid();
    since_keyframe = SE2();
  }

  // The keyframes' camera frames, to undistort them again: for a rolling shutter (unroll_keyframes;
  // an exposure alone puts every keyframe's image the same time before its stamp, which the
  // keyframes' relative motions, and so roll and pitch, do not see) and for a learnt light
  // (final_light).
  void keep_current() {
    const PhotometricModel* model = pipeline.photometric();
    if (!(camera.rolling_shutter_readout > 0.0) && !(model && model->learning())) return;
    keyframe_gray.push_back(current.clone());
    keyframe_t.push_back(current_t);
  }

  // The light fitted at 30 frames is the map's from its start, but its statistics' noise is still
  // in it (the mean of a few dozen views of the floor at each pixel), and an error of the model
  // fixed to the camera pulls the joint alignment's orientation. The statistics go on to
  // light_frames moving frames (light_wants_frames): the model is fitted again from them and every
  // keyframe corrected with it, before the alignment (under a rolling shutter, a lamp, a
  // reflection and a shadow, anti_skid_tiles: roll 1.50 -> 0.94 degrees off on its own;
  // src/calib/README.md).
  void final_light() {
    PhotometricModel* model = pipeline.photometric();
    const size_t K = keyframes.size();
    if (!model || !model->learning() || !light_fitted || keyframe_gray.size() != K) return;
    if (model->frames() <= model->fit().frames) return;
    model->refit();
    for (size_t k = 0; k < K; ++k) pipeline.process(keyframe_gray[k], keyframes[k]);
  }

  // A keyframe undistorted again (unroll_keyframes) is band-passed as the others once the
  // refinement has started (estimate; image/band_pass.h: the smooth error the light model leaves
  // fixed to the camera pulls the orientation in proportion to the floor's mean level squared).
  void band_pass_keyframe(Pyramid& k) {
    if (band_passed) band_pass(rt, k, opt.band_pass_sigma);
  }

  // The light found at the first fit still wants frames, up to light_frames (final_light).
  bool light_wants_frames() {
    const PhotometricModel* model = pipeline.photometric();
    return model && model->learning() && light_fitted && !model->fit().identity && model->frames() < opt.light_frames;
  }

  bool finish_frame(Clock::time_point t0) {
    if (static_cast<int>(keyframes.size()) >= opt.max_keyframes && !light_wants_frames()) done = true;
    if (opt.max_frames > 0 && frames_moving >= opt.max_frames) done = true;
    track_ms += ms_since(t0);
    return done;
  }

  std::vector<AlignmentPair> initial_pairs() const {
    std::vector<AlignmentPair> pairs(motions.size());
    for (size_t k = 0; k < motions.size(); ++k) {
      pairs[k].reference = &keyframes[k];
      pairs[k].live = &keyframes[k + 1];
      pairs[k].motion = motions[k];
    }
    return pairs;
  }

  // A pair's residual mean square over its keyframe's intensity variance, from the STATS pass
  // that opened the finest level (about 1 for unrelated images; 0.02-0.1 when aligned).
  static double residual_ratio(const ReduceSums& s) {
    const double var = s.valid > 0 ? s.iref2 / s.valid - std::pow(s.iref / s.valid, 2) : 0.0;
    return s.valid > 0 && var > 0 ? (s.rr / s.valid) / var : HUGE_VAL;
  }

  struct Run {
    AlignmentReport report;
    std::vector<AlignmentPair> pairs;
    Extrinsics ext;
    double ratio = HUGE_VAL;  // the worst pair's residual ratio
    int rounds = 0, passes = 0, dropped = 0;
  };

  // Joint alignments over `levels` from the previous one's result until the orientation settles.
  void rounds(Run* run, const AlignmentLevels& levels, int max_rounds) {
    for (int round = 0; round < max_rounds; ++round) {
      const Extrinsics before = run->ext;
      run->report = aligner.align(run->pairs, &run->ext, levels);
      ++run->rounds;
      for (int p : run->report.passes) run->passes += p;
      if (!run->report.ok) return;
      if (std::hypot(run->ext.roll - before.roll, run->ext.pitch - before.pitch) < opt.round_tolerance) break;
    }
    run->ratio = 0.0;
    for (const ReduceSums& s : run->report.finest_stats) run->ratio = std::max(run->ratio, residual_ratio(s));

  }

  // Pairs that do not align at the joint estimate (the tracker's motion for them was too far
  // off, or they do not overlap) leave the map, and the rest is aligned again, as long as
  // min_keyframes - 1 pairs remain.
  void drop_unaligned(Run* run, const AlignmentLevels& levels) {
    if (!run->report.ok || run->ratio <= opt.search_residual_ratio) return;
    std::vector<AlignmentPair> kept;
    for (size_t p = 0; p < run->pairs.size(); ++p)
      if (residual_ratio(run->report.finest_stats[p]) <= opt.search_residual_ratio) kept.push_back(run->pairs[p]);
    if (static_cast<int>(kept.size()) < opt.min_keyframes - 1 || kept.size() == run->pairs.size()) return;
    run->dropped += static_cast<int>(run->pairs.size() - kept.size());
    run->pairs = std::move(kept);
    rounds(run, levels, opt.max_rounds);
  }

  // A rolling shutter: the keyframes were undistorted as a global shutter's (the tracker here runs
  // at the initial orientation, whose motions are too rough for the row warp); with the joint
  // alignment's orientation and keyframe-to-keyframe motions, each keyframe is undistorted again
  // with the robot's twist at its mean row time (the pairs' velocities, at the middles of their
  // intervals, interpolated linearly and extrapolated at the ends), for the alignment to run again.
  // False when there is nothing to do.
  bool unroll_keyframes(const Run& run) {
    const size_t K = keyframes.size();
    if (!(camera.rolling_shutter_readout > 0.0) || keyframe_gray.size() != K || K < 2) return false;
    std::vector<double> tv;
    std::vector<Eigen::Vector3d> v;
    for (const AlignmentPair& p : run.pairs) {
      const size_t a = static_cast<size_t>(p.reference - keyframes.data()), b = static_cast<size_t>(p.live - keyframes.data());
      if (a >= K || b >= K || !(keyframe_t[b] > keyframe_t[a])) continue;
      tv.push_back(0.5 * (keyframe_t[a] + keyframe_t[b]));
      v.push_back(p.motion.log() / (keyframe_t[b] - keyframe_t[a]));
    }
    if (v.empty()) return false;
    for (size_t k = 0; k < K; ++k) {
      // (With an exposure too, the row warp also takes the image back by half of it to the stamp.)
      const double at = keyframe_t[k] + camera.mean_row_time();
      size_t i = 0;
      while (i + 2 < v.size() && tv[i + 1] < at) ++i;
      Eigen::Vector3d twist = v[i];
      if (v.size() > 1 && tv[i + 1] > tv[i]) twist = v[i] + (v[i + 1] - v[i]) * ((at - tv[i]) / (tv[i + 1] - tv[i]));
      pipeline.set_row_warp(rolling_shutter_warp(camera, run.ext, twist));
      pipeline.process(keyframe_gray[k], keyframes[k]);
      band_pass_keyframe(keyframes[k]);
    }
    pipeline.set_row_warp(identity_row_warp(camera.width, camera.height));
    return true;
  }

  // The jackknife over the pairs (Efron's delete-one): the orientation aligned again without each
  // pair in turn, from the estimate; (n - 1) / n times the spread of
  // the n results about their mean. It sees what is not the same in every pair (a keyframe's
  // rolling-shutter twist, texture that aligns badly, the light's error where each pair puts it)
  // and the analytic covariance, built on independent pixels, does not.
  Eigen::Matrix2d jackknife_covariance(const Run& best, const AlignmentLevels& levels) {
    const size_t n = best.pairs.size();
    if (n < 3) return Eigen::Matrix2d::Zero();
    // At the level above the finest: the pairs' influence is their geometry's and the light's, not
    // the pixels' noise (measured on four drives: the same sigma within 25 %, except where the
    // finest level's were smaller), at 40 % of the cost (1.3 s instead of 3.2 s at 640 x 480).
    AlignmentLevels one = levels;
    one.finest = std::min(levels.finest + 1, levels.coarsest);
    one.coarsest = one.finest;
    std::vector<Eigen::Vector2d> est;
    for (size_t leave = 0; leave < n; ++leave) {
      Run r;
      for (size_t q = 0; q < n; ++q)
        if (q != leave) r.pairs.push_back(best.pairs[q]);
      r.ext = best.ext;
      rounds(&r, one, kJackknifeRounds);
      if (r.report.ok) est.emplace_back(r.ext.roll, r.ext.pitch);
    }
    if (est.size() < 3) return Eigen::Matrix2d::Zero();
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& e : est) mean += e;
    mean /= static_cast<double>(est.size());
    Eigen::Matrix2d c = Eigen::Matrix2d::Zero();
    for (const Eigen::Vector2d& e : est) c += (e - mean) * (e - mean).transpose();
    return c * (static_cast<double>(est.size() - 1) / static_cast<double>(est.size()));
  }

  Run start(double roll, double pitch) {
    Run run;
    run.pairs = initial_pairs();
    run.ext = camera_frame(roll, pitch);
    return run;
  }

  // Refuses, with the reason, a map too small or a camera that moved too little. False then.
  bool enough_motion(RollPitchResult& res) const {
    const int K = res.keyframes;
    if (K < opt.min_keyframes) {
      if (untextured * 2 > frames || K == 0) {
        res.status = RollPitchResult::Status::TooLittleTexture;
        res.reason = std::to_string(untextured) + " of " + std::to_string(frames) +
                     " frames could not be tracked (no texture on the ground, or unusable frames)";
      } else {
        res.status = RollPitchResult::Status::TooLittleMotion;
        res.reason = "the camera moved too little in " + std::to_string(frames) + " frames (" + std::to_string(K) +
                     " keyframes, " + std::to_string(opt.min_keyframes) +
                     " needed): drive over the ground (forwards, backwards or along an arc) while these frames are "
                     "taken, or give more frames";
      }
      return false;
    }
    for (const SE2& m : motions) res.motion += std::hypot(m.x, m.y) + std::abs(m.theta);
    if (res.motion < opt.min_motion) {
      res.status = RollPitchResult::Status::TooLittleMotion;
      res.reason = "the camera moved " + std::to_string(res.motion) + " (camera heights plus radians) over the map, " +
                   std::to_string(opt.min_motion) + " needed: drive or turn while these frames are taken";
      return false;
    }
    return true;
  }

  // A coarse search over the two angles: each start aligned at the coarse levels only (one
  // round), the best by its residual taken down to full resolution; it replaces `best` when it
  // aligns better.
  void search_angles(Run& best, const AlignmentLevels& levels, RollPitchResult& res) {
    AlignmentLevels coarse = levels;
    coarse.finest = std::max(levels.finest, levels.coarsest - 1);
    const int n = static_cast<int>(std::floor(opt.search_range / opt.search_step + 1e-9));
    Run found;
    for (int i = -n; i <= n; ++i)
      for (int j = -n; j <= n; ++j) {
        Run r = start(opt.initial_roll + i * opt.search_step, opt.initial_pitch + j * opt.search_step);
        rounds(&r, coarse, 1);
        res.rounds += r.rounds;
        res.passes += r.passes;
        if (r.report.ok && (!found.report.ok || r.ratio < found.ratio)) found = std::move(r);
      }
    if (found.report.ok) {
      rounds(&found, levels, opt.max_rounds);
      drop_unaligned(&found, levels);
      res.rounds += found.rounds;
      res.passes += found.passes;
      if (found.report.ok && (!best.report.ok || found.ratio < best.ratio)) best = std::move(found);
    }
  }

  // The orientation refined on the band-passed keyframes and, for a rolling shutter, on keyframes
  // undistorted again with the motion measured, until it settles.
  void refine(Run& best, const AlignmentLevels& levels, RollPitchResult& res) {
    // On the band-passed keyframes (image/band_pass.h), from the result on the keyframes as made.
    if (best.report.ok && opt.band_pass_sigma > 0.0 && !band_passed) {
      band_passed = true;
      for (Pyramid& k : keyframes) band_pass(rt, k, opt.band_pass_sigma);
      const int r0 = best.rounds, p0 = best.passes;
      rounds(&best, levels, opt.max_rounds);
      res.rounds += best.rounds - r0;
      res.passes += best.passes - p0;
    }
    // A rolling shutter: the keyframes undistorted again with the motion just measured and the
    // alignment run again from where it stopped, until the orientation settles (the first
    // alignment, of frames undistorted as a global shutter's, can be 2 degrees off under a lamp;
    // the iteration then overshoots and settles in 3-4 rounds).
    for (int again = 0; again < opt.max_unrolls && best.report.ok && unroll_keyframes(best); ++again) {
      const Extrinsics before = best.ext;
      const int r0 = best.rounds, p0 = best.passes;
      rounds(&best, levels, opt.max_rounds);
      res.rounds += best.rounds - r0;
      res.passes += best.passes - p0;
      ++res.unrolls;
      if (std::hypot(best.ext.roll - before.roll, best.ext.pitch - before.pitch) < opt.unroll_tolerance) break;
    }
  }

  // sigma^2 S^-1 with every pair's motion and brightness marginalised (aligner.h), and what the
  // jackknife's covariance has beyond it.
  void covariance(const Run& best, const AlignmentLevels& levels, RollPitchResult& res) {
    const double dof = std::max(1.0, best.report.total_valid - static_cast<double>(
                                          best.pairs.size() * static_cast<size_t>(aligner.local_size()) + 2));
    const double s2 = std::max(best.report.total_wrr / dof, opt.align.min_sigma * opt.align.min_sigma);
    const Eigen::Matrix2d S = best.report.orientation_information;
    const Eigen::LDLT<Eigen::Matrix2d> ldlt(S);
    const bool invertible = ldlt.info() == Eigen::Success && ldlt.vectorD().minCoeff() > 0.0;
    res.covariance = invertible ? Eigen::Matrix2d(opt.covariance_inflation * opt.covariance_inflation * s2 *
                                                  ldlt.solve(Eigen::Matrix2d::Identity()))
                                : Eigen::Matrix2d::Identity() * 1e6;
    if (opt.jackknife && invertible) {
      // What the jackknife's covariance has beyond the analytic one (the positive part of their
      // difference) is added: the sum covers both, and where they agree nothing changes.
      const Eigen::Matrix2d jk = jackknife_covariance(best, levels);
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> d(jk - res.covariance);
      if (d.info() == Eigen::Success) {
        const Eigen::Vector2d excess = d.eigenvalues().cwiseMax(0.0);
        res.covariance += d.eigenvectors() * excess.asDiagonal() * d.eigenvectors().transpose();
      }
      res.jackknife_covariance = jk;
    }
  }

  RollPitchResult estimate() {
    RollPitchResult res;
    res.frames_used = frames;
    res.keyframes = static_cast<int>(keyframes.size());
    res.keyframe_frames = keyframe_frames;
    res.track_ms = track_ms;
    if (!enough_motion(res)) return res;

    const auto t0 = Clock::now();
    final_light();
    const AlignmentLevels levels = aligner.levels(keyframes.front(), keyframes.back());
    Run best = start(opt.initial_roll, opt.initial_pitch);
    rounds(&best, levels, opt.max_rounds);
    drop_unaligned(&best, levels);
    res.rounds = best.rounds;
    res.passes = best.passes;
    if (opt.search && (!best.report.ok || best.ratio > opt.search_residual_ratio)) search_angles(best, levels, res);
    // Which pairs align, the search and the refusals are judged on the keyframes as the pipeline
    // made them (their residual against their intensity's variance: a band-passed faint floor's
    // variance is mostly noise, the ratio near 1 when aligned).
    const double ratio_as_made = best.ratio;
    refine(best, levels, res);
    res.align_ms = ms_since(t0);
    if (!best.report.ok) {
      res.status = RollPitchResult::Status::Failed;
      res.reason = std::string("the joint alignment of the keyframes failed: ") + best.report.reason;
      return res;
    }
    res.residual_ratio = ratio_as_made;
    res.pairs = static_cast<int>(best.pairs.size());
    res.roll = best.ext.roll;
    res.pitch = best.ext.pitch;
    for (const AlignmentPair& p : best.pairs)
      res.pair_motions.push_back({static_cast<int>(p.reference - keyframes.data()),
                                  static_cast<int>(p.live - keyframes.data()), p.motion});
    covariance(best, levels, res);
    const double worst_sigma = std::sqrt(std::max(res.covariance(0, 0), res.covariance(1, 1)));
    if (!(worst_sigma <= opt.max_sigma)) {
      res.status = RollPitchResult::Status::TooLittleMotion;
      res.reason = "the motion does not determine roll and pitch (standard deviation " + degrees(worst_sigma) +
                   ", at most " + degrees(opt.max_sigma) +
                   " allowed): drive forwards, backwards or along an arc, or turn further";
      return res;
    }
    if (ratio_as_made > opt.search_residual_ratio) {
      res.status = RollPitchResult::Status::Failed;
      res.reason = "the keyframes do not align (residual " + std::to_string(ratio_as_made) +
                   " of the image's variance): the ground is not planar, or the frames are not of one surface";
      return res;
    }
    res.status = RollPitchResult::Status::Ok;
    return res;
  }
};

RollPitchEstimator::RollPitchEstimator(ocl::Runtime& runtime, const CameraModel& camera,
                                       const RollPitchOptions& options)
    : impl_(std::make_unique<Impl>(runtime, camera, options)) {}
RollPitchEstimator::~RollPitchEstimator() = default;
bool RollPitchEstimator::add_frame(const uint8_t* gray, int width, int height, size_t stride, double timestamp) {
  return impl_->add_frame(gray, width, height, stride, timestamp);
}
bool RollPitchEstimator::complete() const { return impl_->done; }
int RollPitchEstimator::keyframes() const { return static_cast<int>(impl_->keyframes.size()); }
RollPitchResult RollPitchEstimator::estimate() { return impl_->estimate(); }

}  // namespace planarvo::track
