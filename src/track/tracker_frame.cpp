// One frame through the tracker (tracker_impl.h): its time and prediction, Lost frames, the
// first frame, the alignment with retries, the grading, the motion and its covariance, the
// keyframe decision, the rolling shutter's offset and the mounting watch.
#include "track/tracker_impl.h"

namespace planarvo::track {

Tracker::Impl::FrameTiming Tracker::Impl::advance_time(double t) {
  FrameTiming ft;
  if (has_t) {
    ft.dt = std::isfinite(t) ? t - last_t : HUGE_VAL;
    if (!(ft.dt > 0.0) || !std::isfinite(ft.dt)) {
      ft.problem = kBadTime;
      ft.dt = nominal_dt;
    } else if (nominal_dt > 0.0 && ft.dt > opt.max_gap_factor * nominal_dt) {
      ft.problem = kTimeGap;
    } else {
      nominal_dt = nominal_dt > 0.0 ? 0.9 * nominal_dt + 0.1 * ft.dt : ft.dt;
    }
  }
  if (std::isfinite(t) && (!has_t || t > last_t)) {
    last_t = t;
    has_t = true;
  }
  since_good += ft.dt;
  ft.predict = ft.dt > 0.0 && since_good <= opt.max_gap_seconds;
  ft.predicted = ft.predict ? SE2::exp(velocity * ft.dt) : SE2();
  return ft;
}

FrameResult Tracker::Impl::finished(FrameResult& r, const FrameTiming& ft) {
  r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - ft.start).count();
  return r;
}

FrameResult Tracker::Impl::lose(FrameResult& res, const Pyramid& live, const char* why, bool can_be_keyframe, const FrameTiming& ft) {
  res.status = Status::Lost;
  res.reason = why;
  res.motion.value = ft.predicted;
  res.motion.covariance = res.alignment_covariance = lost_covariance();
  if (opt.local_plane) {
    res.attitude = prev.att_live;
    res.attitude_covariance = plane.prior_covariance();
  }
  pose = pose * ft.predicted;
  ++lost_in_a_row;
  // A frame misaligned by the light fixed to the camera is not a bad frame: the keyframe and
  // the light's model are what failed, and a new keyframe takes a new model into use.
  if (can_be_keyframe && (lost_in_a_row >= 2 || !ft.predict || why == kMisaligned)) {
    if (opt.local_plane) plane.take_keyframe(prev.att_live, plane.prior_covariance());
    make_keyframe(live);
    keyframe_twist_measured = false;
    res.keyframe = true;
  } else {
    // The next motion is from this predicted pose: as uncertain as this one.
    prev.T = prev.T * ft.predicted;
    prev_covariance = lost_covariance();
    prev_predicted = true;
  }
  if (since_good > opt.max_gap_seconds) {
    velocity.setZero();
    readout_twist.reset();
  }
  return finished(res, ft);
}

FrameResult Tracker::Impl::start(FrameResult& res, const Pyramid& live, const FrameTiming& ft) {
  missing = nullptr;  // nothing to align with: not a failure of this frame's alignment
  if (!has_own_texture(live)) {
    res.status = Status::Lost;
    res.reason = kNoTexture;
    return finished(res, ft);
  }
  make_keyframe(live);
  keyframe_twist_measured = false;
  lost_in_a_row = 0;
  res.status = Status::First;
  if (opt.local_plane) {
    res.attitude = plane.keyframe();
    res.attitude_covariance = plane.keyframe_covariance();
  }
  res.keyframe = true;
  since_good = 0.0;
  return finished(res, ft);
}

bool Tracker::Impl::align_with_retries(const Pyramid& live, const FrameTiming& ft, FrameResult* res, Estimate* est,
                          const char** reason) {
  Estimate init = prev;
  init.T = prev.T * ft.predicted;
  bool ok = align(live, init, est, res, reason);
  if (ok) finish(res, *est, live);
  if ((!ok || res->status == Status::Lost) && *reason != kAlignNoLiveTexture &&
      !(ft.predicted.x == 0 && ft.predicted.y == 0 && ft.predicted.theta == 0)) {
    FrameResult retry;
    Estimate est2;
    if (align_again(live, prev, *res, &retry, &est2) && retry.status != Status::Lost) {
      *res = retry;
      *est = est2;
      ok = true;
    }
  }
  if ((!ok || res->status == Status::Lost) && *reason != kAlignNoLiveTexture && opt.search_motion) {
    FrameResult found;
    Estimate est4;
    if (search_again(live, *res, &found, &est4)) {
      *res = found;
      *est = est4;
      ok = true;
    }
  }
  if (ok && res->status == Status::Lost && res->reason == kMisaligned && correct_again(live)) {
    FrameResult again;
    Estimate est3;
    if (align_again(live, init, *res, &again, &est3)) {
      *res = again;
      *est = est3;
    }
  }
  return ok;
}

void Tracker::Impl::grade(FrameResult* res, const char* time_problem) {
  if (time_problem && res->status == Status::Ok) {
    res->status = Status::Degraded;
    res->reason = time_problem;
  }
  if ((shutter_unknown || keyframe_shear_assumed) && res->status == Status::Ok) {
    res->status = Status::Degraded;
    res->reason = kShutterUnknown;
  }
  if (prev_predicted && res->status == Status::Ok) {
    res->status = Status::Degraded;
    res->reason = kAfterLost;
  }
  prev_predicted = false;
}

void Tracker::Impl::commit(FrameResult* res, Estimate& est, const Pyramid& live, double t, double dt) {
  // With prev.T = P exp(xi_p) and est.T = E exp(xi_e), the motion is m exp(xi_e - Ad(m^-1) xi_p);
  // prev_covariance already holds xi_p's covariance less the part shared with xi_e.
  res->motion.value = prev.T.inverse() * est.T;
  const Eigen::Matrix3d ad = res->motion.value.inverse().adjoint();
  res->motion.covariance = res->alignment_covariance + ad * prev_covariance * ad.transpose();
  // Its tilt Jacobian the same way: xi_e's and Ad(m^-1) xi_p's (before a new keyframe).
  Eigen::Matrix<double, 3, 2> tilt = Eigen::Matrix<double, 3, 2>::Zero();
  if (opt.tilt_jacobian) {
    if (!tilt_jacobian) tilt_jacobian = std::make_unique<TiltJacobian>(rt, opt.kernel);
    tilt = (*tilt_jacobian)(keyframe, live, camera.K(), ext, est.T, est.a, est.b, est.huber_k, opt.estimate_brightness);
    res->motion_tilt_jacobian = tilt - ad * prev_tilt;
  }
  if (!res->motion.covariance.allFinite()) res->motion.covariance = lost_covariance();
  pose = pose * res->motion.value;
  if (dt > 0.0) velocity = res->motion.value.log() / dt;
  if (has_live_c) readout_twist.commit(live_c, live_tc);
  watch_mounting(t, dt, res, &est);
  since_good = 0.0;
  lost_in_a_row = 0;
  if (res->overlap < opt.keyframe_overlap ||
      log_scale_change(camera.K(), ext, est.T, camera.region()) > opt.keyframe_scale_change) {
    if (opt.local_plane) plane.take_keyframe(est.att_live, res->attitude_covariance);
    make_keyframe(live);
    keyframe_twist_measured = true;
    // Frames aligned with it carry its own shutter offset, which the motions from it must not.
    prev.T = SE2::exp(live_offset);
    res->keyframe = true;
  } else {
    prev = est;
    prev_tilt = tilt;
    prev_covariance = (1.0 - 2.0 * opt.consecutive_alignment_correlation) * res->alignment_covariance;
  }
}

FrameResult Tracker::Impl::track(const Pyramid& live, double t) {
  const auto t0 = std::chrono::steady_clock::now();
  has_live_c = false;
  forget_alignment(kNotAligned);
  FrameResult res;
  res.motion.covariance = lost_covariance();
  res.mounting = ext;
  if (next_odometry && last_odometry) {
    const SE2 d = last_odometry->inverse() * *next_odometry;
    odometry_distance = std::hypot(d.x, d.y);
  } else {
    odometry_distance = NAN;
  }
  last_odometry = next_odometry;
  next_odometry.reset();
  shutter_unknown = false;
  FrameTiming ft = advance_time(t);
  ft.start = t0;

  if (!right_size(live)) {
    missing = kWrongSize;
    return lose(res, live, kWrongSize, false, ft);
  }
  if (!has_keyframe) return start(res, live, ft);

  Estimate est;
  const char* reason = "";
  const bool ok = align_with_retries(live, ft, &res, &est, &reason);
  const SE2 shutter_offset = ok && res.status != Status::Lost ? take_out_shutter(live, t, ft.dt, &res, &est) : SE2();
  if (ok) remember(live, est);  // before a new keyframe replaces the one aligned with
  else missing = reason;
  est.T = est.T * shutter_offset;
  // "No texture in the live frame" compares it with the keyframe: a frame with texture of its
  // own may still replace a keyframe whose texture the frames after it no longer show.
  if (!ok) return lose(res, live, reason, reason != kAlignNoLiveTexture || has_own_texture(live), ft);
  if (res.status == Status::Lost) return lose(res, live, res.reason, true, ft);
  grade(&res, ft.problem);
  commit(&res, est, live, t, ft.dt);
  return finished(res, ft);
}

double Tracker::Impl::shutter_shift(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  const double top = camera.row_time(0.0), bottom = camera.row_time(camera.height - 1.0);
  const double r = std::abs(bottom) >= std::abs(top) ? bottom : top;
  return max_pixel_displacement(camera.K(), ext, SE2::exp(a * r), SE2::exp(b * r), camera.width, camera.height);
}

SE2 Tracker::Impl::take_out_shutter(const Pyramid& live, double t, double dt, FrameResult* res, Estimate* est) {
  live_offset.setZero();
  if (!camera.timed_rows() || !(dt > 0.0) || &live != &slots[live_slot] || !keyframe_kept) return SE2();
  for (int round = 0;; ++round) {
    const Eigen::Vector3d v = (prev.T.inverse() * est->T).log() / dt;
    const bool keyframe_too = !keyframe_twist_measured;
    Eigen::Vector3d twist;
    if (keyframe_too) {
      // The keyframe was undistorted with the same twist as this frame (none measured yet), so
      // their relative pose does not depend on it, and the velocity is the twist's measure.
      // (readout_twist.measure's model holds once the keyframe's own twist is right: with it
      // here, a robot that starts, or recovers, at speed undistorts the keyframe with 1/(1+k)
      // of its twist and the frames stop matching.)
      live_c = v;
      live_tc = t - 0.5 * dt;
      twist = v;
      shutter_unknown = keyframe_shear_assumed = shutter_shift(Eigen::Vector3d::Zero(), v) > kShutterUnknownPx;
    } else {
      twist = readout_twist.measure(t, dt, v, live_twist, &live_c, &live_tc);
    }
    has_live_c = twist.allFinite();
    if (!has_live_c) return SE2();
    if (round == 2 || (!keyframe_too && shutter_shift(live_twist, twist) <= opt.rolling_shutter_tolerance_px)) {
      live_offset = camera.mean_row_time() * (live_twist - twist);
      return SE2::exp(live_offset);
    }
    if (keyframe_too) {
      // The keyframe was the previous frame (the first, or one after a Lost frame): this
      // frame's twist is the best measure of its own.
      pipeline->set_kept_row_warp(rolling_shutter_warp(camera, ext, twist));
      pipeline->reprocess_kept(keyframe);
      select_keyframe_pixels();
      keyframe_twist_measured = true;
    }
    live_twist = twist;
    pipeline->set_row_warp(rolling_shutter_warp(camera, ext, twist));
    pipeline->reprocess(slots[live_slot]);
    FrameResult again;
    Estimate e;
    if (!align_again(live, *est, *res, &again, &e, true)) return SE2();
    *res = again;
    *est = e;
  }
}

void Tracker::Impl::watch_mounting(double t, double dt, FrameResult* res, Estimate* est) {
  using Response = TrackerOptions::MountingResponse;
  // A frame whose attitude the images did not observe says nothing about the mounting.
  if (!opt.local_plane || opt.on_mounting_change == Response::Ignore || !res->attitude_observed) return;
  const std::optional<MountingChange> change =
      watch.add(t, dt, res->motion.value, res->attitude, res->attitude_covariance, odometry_distance);
  if (!change) return;
  res->mounting_changed = true;
  res->mounting_change = *change;
  res->changed_mounting = turned_mounting(ext, change->step, change->dyaw);
  res->changed_mounting.z += change->dz;
  if (opt.on_mounting_change != Response::Recalibrate) return;
  ext = res->changed_mounting;
  est->att_ref = relative_to_turned(est->att_ref, change->step, change->dyaw);
  est->att_live = relative_to_turned(est->att_live, change->step, change->dyaw);
  res->attitude = est->att_live;
  plane.mounting_turned(change->step, change->dyaw);
  watch.mounting_changed(*change);
}

}  // namespace planarvo::track
