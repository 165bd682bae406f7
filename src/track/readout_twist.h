// The robot's twist over a frame whose rows do not all stand for its stamp (a rolling shutter's
// readout, an exposure; CameraModel::row_time), for undistorting the frame
// (image/rolling_shutter.h), from the tracker's motions. m = CameraModel::mean_row_time(), the
// mean of the rows' times relative to the stamp ((readout - exposure) / 2).
//
// The pose the tracker measures for a frame depends on the twist it was undistorted with: a frame
// undistorted with a twist tw where the robot's was xi looks, on average over its rows, like the
// instantaneous global shutter's image at pose P exp(-m (tw - xi)) (the alignment fits the mean
// of its rows' offsets). The tracker takes that mean offset out of each frame's pose (so motions
// between corrected poses are right to first order) and refines the twist:
// measured from a corrected previous pose over the interval dt, the velocity is
//     v = v_true - k (tw - xi),      k = m / dt,
// so c = (v + k tw) / (1 + k) = (v_true + k xi) / (1 + k) does not depend on the twist used; under
// smooth motion it is the velocity at t_c = ((t - dt / 2) + k (t + m)) / (1 + k), a weighted
// mean of the interval's middle and the frame's mean row time (k < 0, an extrapolation, for an
// exposure longer than the readout; 1 + k > 0 for any exposure under two frame intervals). The
// frame's twist, the velocity at t + m, is c extrapolated linearly from the previous frame's.
// (Feeding v back as the next twist instead is a loop with gain -k, -0.38 at a 25 ms readout and
// 30 Hz, that oscillates, and diverges once the twist is also extrapolated.) Constant velocity
// within a frame, as the model of rolling_shutter.h.
#pragma once
#include <Eigen/Core>

namespace planarvo::track {

class ReadoutTwist {
 public:
  // mean_row_time: CameraModel::mean_row_time(), seconds.
  explicit ReadoutTwist(double mean_row_time) : m_(mean_row_time) {}

  // Nothing measured (the first frame, after a gap or a reset): the twist is zero.
  void reset() { n_ = 0; }

  // The twist for a frame stamped t, before it is aligned: the measured c's extrapolated.
  Eigen::Vector3d predict(double t) const;

  // The twist of a frame stamped t from its velocity v measured over the interval dt before it
  // (from the previous frame's corrected pose) and the twist it was undistorted with (own). *c
  // and *tc get the frame's c and its time, for commit().
  Eigen::Vector3d measure(double t, double dt, const Eigen::Vector3d& v, const Eigen::Vector3d& own,
                          Eigen::Vector3d* c, double* tc) const;

  // The frame's c (from measure()) enters the model.
  void commit(const Eigen::Vector3d& c, double tc);

 private:
  // The velocity at time `at` from the last two c's (or the last and an extra one, when given).
  Eigen::Vector3d extrapolate(double at, const Eigen::Vector3d* c, double tc) const;

  double m_;
  int n_ = 0;  // c's measured: 0, 1 or 2 (the last two)
  Eigen::Vector3d c_[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};  // c_[0] the last
  double t_[2] = {0.0, 0.0};  // the times c_ stand for
};

}  // namespace planarvo::track
