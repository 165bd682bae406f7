// Online recalibration (issue 24, the paper's section 6.4): noticing that the camera's mounting
// has changed (a bracket bent, a bumper replaced) while the local plane is tracked.
//
// What the images show. The local plane (local_plane.h) measures the body's attitude relative to
// the ground with every frame, against the mounting given. A knock turns the camera on the body:
// from then on every attitude is off by the same step, whatever the body does. The body's own
// lean is transient: its roll follows the yaw rate in turns and its pitch the acceleration
// (body_lean.h), and over a bump its pitch rises and falls within the bump's length.
//
// The test. Each frame's roll less the lean its yaw rate explains (the slope fitted robustly over
// the recent drive), and its pitch, are its residuals. Over the most recent window (at least
// window_metres driven and window_seconds) each angle's residuals are compared with their level
// before the window (the median over up to history_seconds before it, since the last change):
// a change is an angle whose window median differs from that level by at least min_step while
// every residual in the window stays within steady_tolerance of that median. A bump never holds
// steady over a metre (its pitch changes by most of its height over 40 % of its length), nor does
// a turn once the lean's slope is known; a window driven unlike the history (a turn before the
// slope is known, braking or accelerating: the pitch's slope with acceleration is not fitted,
// since bumps, which a car drives over while its speed changes, would bend it) is not compared at
// all. A knock is a step that then holds. The window is
// measured in metres so that a slow car's bump is judged over the same stretch of road as a fast
// one's; standing still adds nothing to it (the plane is not observed then).
//
// Height is not in the test: the images of a plane fix the camera's height only relative to the
// scale of the motion, which without wheel odometry is the mounting's height itself.
#pragma once
#include <cmath>
#include <deque>
#include <optional>

#include <Eigen/Core>

#include "core/body_attitude.h"
#include "core/se2.h"

namespace planarvo::track {

struct MountingWatchOptions {
  double min_step = 1.0 * M_PI / 180.0;           // radians: the smallest change reported
  double steady_tolerance = 0.3 * M_PI / 180.0;   // radians: how far a window's residuals may stray
  double window_metres = 1.0;
  double window_seconds = 0.25;
  double history_seconds = 30.0;                  // the level before the window: at most this long
  // The roll's slope is fitted when the yaw rate (rad/s) spreads by at least this (standard
  // deviation over the history); until then, and for the pitch always, a window whose yaw rate or
  // acceleration (m/s^2) is further than this from the history's median is not compared.
  double min_yaw_rate_spread = 2.0 * M_PI / 180.0;
  double min_acceleration_spread = 0.5;
};

// A change of the mounting, in the body's attitude: the attitude measured against the mounting
// in use stepped by `step` and held (radians), with its standard deviation per angle.
struct MountingChange {
  double time = 0.0;           // the first frame at the new level (seconds)
  double detected_time = 0.0;  // the frame that confirmed it
  BodyAttitude step;
  Eigen::Vector2d sigma = Eigen::Vector2d::Zero();  // roll, pitch
};

class MountingWatch {
 public:
  explicit MountingWatch(const MountingWatchOptions& options = {}) : opt_(options) {}

  // One tracked frame at time t: its motion over the dt seconds since the frame before (for the
  // yaw rate, the speed and the acceleration), its attitude and the attitude's covariance.
  // Frames that were not tracked are not given (a gap: the acceleration restarts). Returns the
  // change this frame confirmed, if any; the level then moves to the new attitude.
  std::optional<MountingChange> add(double t, double dt, const SE2& motion, const BodyAttitude& attitude,
                                    const Eigen::Matrix2d& covariance);

  // The caller changed the mounting by `step` (the change just reported): attitudes measured from
  // now on are `step` lower.
  void mounting_changed(const BodyAttitude& step);

  // The lean's slope in use: roll per yaw rate (s).
  double roll_per_yaw_rate() const { return k_roll_; }

  void reset();

 private:
  struct Sample {
    double t, s;        // time, distance driven (metres)
    double w, a;        // yaw rate, acceleration
    double roll, pitch;
    double var_roll, var_pitch;  // the attitude's own variances
  };
  void fit_lean(size_t end);
  std::optional<MountingChange> test();

  MountingWatchOptions opt_;
  std::deque<Sample> samples_;  // the window and at most history_seconds before it
  double since_[2] = {-HUGE_VAL, -HUGE_VAL};  // per angle: its last change (its history begins)
  BodyAttitude level_;          // the expected attitude before any history (the mounting's)
  double k_roll_ = 0.0;       // roll per yaw rate, fitted robustly over the history
  bool lean_known_ = false;   // k_roll_ fitted (else zero)
  double distance_ = 0.0;
  double last_speed_ = 0.0;
  bool has_speed_ = false;
};

}  // namespace planarvo::track
