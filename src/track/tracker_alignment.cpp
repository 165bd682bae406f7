// The tracker's alignment with the keyframe (tracker_impl.h): the coarse-to-fine alignment, its
// acceptance checks and status, the retries from another start and the search for a motion.
#include "track/tracker_impl.h"

namespace planarvo::track {

bool Tracker::Impl::align(const Pyramid& live, const Estimate& init, Estimate* out, FrameResult* res,
             const char** reason, bool refine) {
  AlignmentPair& pair = pairs[0];
  pair.reference = &keyframe;
  pair.live = &live;
  pair.selection = &selection;
  pair.motion = init.T;
  pair.log_gain = init.a;
  pair.bias = init.b;
  pair.sigma = sigma;
  if (opt.local_plane) plane.prepare(init.att_live, &pair);
  Extrinsics e = ext;
  AlignmentLevels levels = aligner.levels(keyframe, live);
  if (refine) levels.coarsest = std::max(levels.finest, std::min(1, levels.coarsest));
  report = aligner.align(pairs, &e, levels);
  res->iterations = report.passes;
  res->level_ms = report.level_ms;
  res->levels_used = report.levels_used;
  // A frame about to become the keyframe goes on to full resolution.
  const ReduceSums* s = report.ok ? &report.finest[0] : nullptr;
  if (s && levels.finest > 0 && opt.refine_keyframes && s->ref > 0 && s->valid / s->ref < opt.keyframe_overlap) {
    levels.coarsest = levels.finest = 0;
    const std::array<int, kMaxLevels> passes = report.passes;
    const std::array<double, kMaxLevels> ms = report.level_ms;
    report = aligner.align(pairs, &e, levels);
    for (size_t l = 0; l < passes.size(); ++l) {
      res->iterations[l] = passes[l] + report.passes[l];
      res->level_ms[l] = ms[l] + report.level_ms[l];
    }
    res->levels_used += report.levels_used;
  }
  sigma = pair.sigma;
  if (!report.ok) {
    *reason = report.reason;
    return false;
  }
  out->T = pair.motion;
  out->a = pair.log_gain;
  out->b = pair.bias;
  out->att_ref = pair.reference_attitude;
  out->att_live = pair.live_attitude;
  out->huber_k = report.finest_huber_k.empty() ? 0.0 : report.finest_huber_k[0];
  out->finest = levels.finest;
  return true;
}

bool Tracker::Impl::weakly_constrained(const Eigen::Matrix3d& cov) const {
  const Eigen::Vector2d ev =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov.topLeftCorner<2, 2>()).eigenvalues();
  return !(std::sqrt(ev(1)) <= opt.max_position_std) || !(ev(1) <= opt.max_std_ratio * opt.max_std_ratio * ev(0)) ||
         !(std::sqrt(cov(2, 2)) <= opt.max_heading_std);
}

double Tracker::Impl::measure_texture_residual(const Pyramid& live, const Estimate& e) {
  const int level = texture_residual_level(camera.width, opt.levels);
  if (!std::isfinite(opt.max_texture_residual) || level >= live.num_levels() || level >= keyframe.num_levels())
    return std::numeric_limits<double>::quiet_NaN();
  return imager->texture_residual(record(live, e), ext, level);  // made with the tracker
}

AlignmentRecord Tracker::Impl::record(const Pyramid& live, const Estimate& e) const {
  AlignmentRecord a;
  a.reference = keyframe;
  a.live = live;
  a.motion = e.T;
  a.log_gain = e.a;
  a.bias = e.b;
  a.huber_k = e.huber_k;
  a.finest_level = e.finest;
  a.reference_attitude = e.att_ref;
  a.live_attitude = e.att_live;
  return a;
}

void Tracker::Impl::finish(FrameResult* res, const Estimate& e, const Pyramid& live) {
  const ReduceSums& s = report.finest[0];
  res->final_cost = s.valid > 0 ? s.cost / s.valid : HUGE_VAL;
  res->inlier_fraction = s.valid > 0 ? s.inlier / s.valid : 0.0;
  res->overlap = s.ref > 0 ? s.valid / s.ref : 0.0;
  res->log_gain = e.a;
  res->bias = e.b;
  const int nb = opt.estimate_brightness ? 2 : 0;
  const int n = report.finest_nparam + nb;  // motion (the local plane's attitudes), brightness
  const double dof = std::max(1.0, s.valid - n);
  res->sigma = report.finest_sigma[0];
  // The independent-pixel covariance sigma^2 (J^T W J)^-1 (sigma^2 at least min_sigma^2, so
  // noise-free synthetic frames do not claim zero variance) judges how well the texture
  // constrains the motion (the thresholds below were measured with it).
  const double floor_s2 = opt.min_sigma * opt.min_sigma;
  const double s2 = std::max(s.wrr / dof, floor_s2);
  const MatrixJ A = s.JtWJ.topLeftCorner(n, n);
  const Eigen::LDLT<MatrixJ> ldlt(A);
  const MatrixJ inv = ldlt.solve(MatrixJ::Identity(n, n));
  Eigen::Matrix3d independent = s2 * inv.topLeftCorner(3, 3);
  if (!independent.allFinite()) independent = lost_covariance();
  // The motion's covariance is composed from this one by the caller (track_gray).
  const MatrixJ C =
      alignment_covariance_all(s, report.finest_stats[0], n, floor_s2, A, ldlt, opt.covariance_step_fraction);
  res->alignment_covariance = C.topLeftCorner(3, 3);
  if (!res->alignment_covariance.allFinite()) res->alignment_covariance = lost_covariance();
  if (opt.local_plane) {
    // The live attitude (parameters 5, 6: after the motion and the keyframe's attitude), from
    // the last level that estimated the attitudes: the finest (C above) unless attitude_max_width
    // held them on the finer levels.
    res->attitude = e.att_live;
    res->attitude_covariance = plane.prior_covariance();
    const int lv = kMotionParams + 2;
    Eigen::Matrix2d cov = Eigen::Matrix2d::Constant(NAN);
    if (report.finest_nparam == kMotionParams + kAttitudeParams) {
      cov = C.block(lv, lv, 2, 2);
    } else if (report.attitude_level >= 0) {
      const int na = kMotionParams + kAttitudeParams + nb;
      const ReduceSums& sa = report.attitude_sums;
      const MatrixJ Aa = sa.JtWJ.topLeftCorner(na, na);
      const Eigen::LDLT<MatrixJ> la(Aa);
      cov = alignment_covariance_all(sa, report.attitude_stats, na, floor_s2, Aa, la, opt.covariance_step_fraction)
                .block(lv, lv, 2, 2);
    }
    if (cov.allFinite()) res->attitude_covariance = cov;
    // Observed when the images know it better than the prior alone does.
    res->attitude_observed = res->attitude_covariance.diagonal().maxCoeff() < 0.5 * plane.prior_covariance()(0, 0);
  }

  // The images' match from the half-resolution level (or the finest, when coarser): at full
  // resolution a noisy, weakly textured view's residual is mostly pixel noise.
  const ReduceSums& st = report.match_stats[0];
  const double var_ref = st.valid > 0 ? st.iref2 / st.valid - std::pow(st.iref / st.valid, 2) : 0.0;
  const double ratio = st.valid > 0 && var_ref > 0 ? (st.rr / st.valid) / var_ref : HUGE_VAL;
  // The floor's texture left in the residual: an alignment that something fixed to the camera
  // holds while the floor moves leaves it there. Images that do not match at all (a frame with
  // nothing in common with the keyframe, as after a gap at speed) say nothing about the light,
  // and forced a model learnt from a few frames into use.
  res->texture_residual = measure_texture_residual(live, e);
  const bool misaligned = res->texture_residual > opt.max_texture_residual;
  light_holds = misaligned && ratio <= opt.lost_residual_ratio;
  if (!(ratio <= opt.lost_residual_ratio)) {
    res->status = Status::Lost;
    res->reason = kMismatch;
  } else if (misaligned) {
    res->status = Status::Lost;
    res->reason = kMisaligned;
  } else if (!(std::abs(e.a) <= opt.max_log_gain)) {
    res->status = Status::Lost;
    res->reason = kBrightness;
  } else if (ratio > opt.degraded_residual_ratio) {
    res->status = Status::Degraded;
    res->reason = "large residuals";
  } else if (res->inlier_fraction < opt.min_inlier_fraction) {
    res->status = Status::Degraded;
    res->reason = "few inliers";
  } else if (weakly_constrained(independent)) {
    res->status = Status::Degraded;
    res->reason = kWeak;
  } else {
    res->status = Status::Ok;
    res->reason = "";
  }
}

bool Tracker::Impl::align_again(const Pyramid& live, const Estimate& from, const FrameResult& before, FrameResult* again,
                   Estimate* est, bool refine) {
  *again = before;
  const char* reason = "";
  if (!align(live, from, est, again, &reason, refine)) return false;
  finish(again, *est, live);
  for (size_t l = 0; l < before.iterations.size(); ++l) {
    again->iterations[l] += before.iterations[l];
    again->level_ms[l] += before.level_ms[l];
  }
  return true;
}

bool Tracker::Impl::search_again(const Pyramid& live, const FrameResult& before, FrameResult* found, Estimate* est) {
  if (!search) search = std::make_unique<MotionSearch>(rt);
  const AlignmentLevels levels = aligner.levels(keyframe, live);
  const std::vector<SE2> peaks =
      search->candidates(keyframe, live, levels.coarsest, camera.K(), ext, prev.T, opt.search);
  for (const SE2& peak : peaks) {
    Estimate from = prev;
    from.T = peak;
    if (align_again(live, from, before, found, est) && found->status != Status::Lost) return true;
  }
  return false;
}

void Tracker::Impl::forget_alignment(const char* why) {
  has_last = false;
  missing = why;
  cached.level = -1;
}

void Tracker::Impl::remember(const Pyramid& live, const Estimate& est) {
  last = record(live, est);
  has_last = true;
}

ResidualImage Tracker::Impl::residuals(int level) {
  if (!has_last && !missing)
    throw_invalid_argument("Tracker::residuals: no frame has been aligned with a keyframe yet");
  if (!has_last)
    throw Error(ErrorCode::Failed, std::string("Tracker::residuals: the last frame was not aligned (") + missing + ")");
  if (cached.level != level) {
    if (!imager) imager = std::make_unique<ResidualImager>(rt, camera.K(), opt.kernel);
    cached.level = -1;
    imager->compute(last, ext, level, &cached);
  }
  return cached;
}

}  // namespace planarvo::track
