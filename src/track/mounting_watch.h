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
// Height. The images of a plane fix the camera's height only with the scale of the motion: without
// wheel odometry the mounting's height is all there is. With it (add()'s odometry distance), the
// ratio of the distance tracked to the wheels' distance is the mounting's height over the true one
// times the wheels' scale: a step in it that holds is the height changed. Judged over the most
// recent height_window_metres of wheel travel against the history since the last change (at least
// height_history_metres): a change when the window's ratio differs by at least min_height_step (as
// a height) and height_sigmas of its standard deviation (from the frames' scatter about it), both
// halves of the window on the same side by at least half of it, and the attitude within half of
// min_step of its level at every frame of the window (a turned camera not yet found shows as a
// height: the local plane turns the body about the ground, which moves the camera; a bump makes the
// test wait for a stretch without one). The change is then measured across the split of
// the frames since the last change that best tells two ratios apart (its time).
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
  // The height (with odometry): the mounting's height (metres; 0: not watched), and the test's.
  double height = 0.0;
  double min_height_step = 0.005;
  double height_window_metres = 3.0;
  double height_history_metres = 2.0;
  double height_sigmas = 5.0;
  double height_min_travel = 0.005;  // metres of wheel travel in a frame for it to count
  // The direction of travel (an attitude change's yaw) from frames at this speed at least, m/s.
  double min_heading_speed = 0.3;
  // A change taken into use is measured once more over the first window tracked with it; what is
  // left of it, when at least this (radians) and 3 sigma, is reported as its refinement.
  double min_refinement = 0.05 * M_PI / 180.0;
};

// A change of the mounting, in the body's attitude: the attitude measured against the mounting
// in use stepped by `step` and held (radians), with its standard deviation per angle.
struct MountingChange {
  double time = 0.0;           // the first frame at the new level (seconds)
  double detected_time = 0.0;  // the frame that confirmed it
  BodyAttitude step;
  Eigen::Vector2d sigma = Eigen::Vector2d::Zero();  // roll, pitch
  // The height's change (metres) and its standard deviation; NaN sigma when not judged (no
  // odometry, or this change is the attitude's).
  double dz = 0.0, sigma_z = NAN;
  // With an attitude change: the turn about the body's vertical that came with it (radians; a
  // camera tilted forward and knocked about its own axis turns about the vertical too), from the
  // direction of travel tracked (a car's is straight ahead: its origin on the rear axle) before and
  // after; NaN sigma (and 0) when there were too few frames moving to tell.
  double dyaw = 0.0, sigma_yaw = NAN;
  // A refinement of the last change taken into use (MountingWatch::mounting_changed): the step
  // left after it, measured from the first window tracked with it (time: the change's).
  bool refinement = false;
};

class MountingWatch {
 public:
  explicit MountingWatch(const MountingWatchOptions& options = {}) : opt_(options) {}

  // One tracked frame at time t: its motion over the dt seconds since the frame before (for the
  // yaw rate, the speed and the acceleration), its attitude and the attitude's covariance.
  // Frames that were not tracked are not given (a gap: the acceleration restarts). Returns the
  // change this frame confirmed, if any; the level then moves to the new attitude.
  // odometry_distance: the wheels' distance over the same interval (metres), NaN when there is none.
  std::optional<MountingChange> add(double t, double dt, const SE2& motion, const BodyAttitude& attitude,
                                    const Eigen::Matrix2d& covariance, double odometry_distance = NAN);

  // The caller changed the mounting as `change` says (the change just reported): attitudes measured
  // from now on are its step lower, distances tracked (z + dz) / z longer, directions dyaw turned.
  void mounting_changed(const MountingChange& change);

  void reset();

 private:
  struct Sample {
    double t, s;        // time, distance driven (metres)
    double w, a;        // yaw rate, acceleration
    double roll, pitch;
    double var_roll, var_pitch;  // the attitude's own variances
    double vis, odo;             // distance tracked and the wheels' (NaN: no odometry)
    double heading;              // the direction of travel, robot frame (NaN: hardly moving)
  };
  void fit_lean(size_t end);
  std::optional<MountingChange> test();
  struct AngleJudgement {
    double base = 0.0, median = 0.0, step = 0.0, sigma = 0.0;
    bool judged = false;   // steady and comparable: its step is measured
    bool stepped = false;  // held a new level by min_step at least
  };
  AngleJudgement judge_angle(int angle, size_t begin) const;
  size_t change_start(size_t begin, const bool stepped[2], const double bases[2], const double medians[2]) const;
  std::optional<MountingChange> test_height(const double levels[2]);
  // An attitude change's yaw: the window [begin, end) against the history before `first`.
  void measure_yaw(size_t begin, size_t first, MountingChange* change) const;
  // The roll's step at sample `first` fitted with the lean's slope (and its sigma).
  void joint_roll_step(size_t first, double* step, double* sigma);
  // After a change taken into use: the first judged window after it against the level before it.
  std::optional<MountingChange> refine(size_t begin, const bool judged[2], const double medians[2],
                                       const Eigen::Vector2d& sigma);
  // The roll less the lean its yaw rate explains (angle 0), the pitch (1).
  double residual(const Sample& s, int angle) const;

  MountingWatchOptions opt_;
  std::deque<Sample> samples_;  // the window and at most history_seconds before it
  // Roll, pitch, height, the direction of travel: the last change (the history's start).
  double since_[4] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  BodyAttitude level_;          // the expected attitude before any history (the mounting's)
  // The refinement of the last change taken into use (mounting_changed): per angle, whether it is
  // due and the level before the change; after when (its detection) and the change's time.
  bool refining_[2] = {false, false};
  double refine_base_[2] = {0.0, 0.0}, last_bases_[2] = {0.0, 0.0};
  double refine_after_ = 0.0, refine_time_ = 0.0;
  double k_roll_ = 0.0;       // roll per yaw rate, fitted robustly over the history
  bool lean_known_ = false;   // k_roll_ fitted (else zero)
  double distance_ = 0.0;
  double last_speed_ = 0.0;
  bool has_speed_ = false;
};

}  // namespace planarvo::track
