// The robot's twist over a rolling-shutter frame's readout, for undistorting the frame
// (image/rolling_shutter.h), from the tracker's motions.
//
// The motion the tracker measures between two frames depends on the twists they were undistorted
// with: a frame undistorted with a twist off by e is offset, on average over its rows, by about
// e times half the readout (the alignment fits the mean of its rows' offsets), so the velocity
// measured over the interval dt is
//     v = v_true - k ((tw_k - xi_k) - (tw_{k-1} - xi_{k-1})),      k = readout / (2 dt),
// tw the twists used, xi the true ones. Feeding v back as the next twist is a loop with gain -k
// (-0.38 at a 25 ms readout and 30 Hz) that oscillates, and diverges once the twist is also
// extrapolated. Instead the twists' part is taken out:
//     c = v + k (tw_k - tw_{k-1}) = v_true + k (xi_k - xi_{k-1}),
// which does not depend on the twists used; under smooth motion it is the velocity at
// t_k - dt / 2 + readout / 2 (the interval's middle moved by k dt). The frame's twist, the
// velocity at the middle of its readout (t_k + readout / 2), is c extrapolated linearly from the
// previous frame's c. Constant velocity within a frame, as the model of rolling_shutter.h.
#pragma once
#include <Eigen/Core>

namespace planarvo::track {

class ReadoutTwist {
 public:
  explicit ReadoutTwist(double readout) : readout_(readout) {}

  // Nothing measured (the first frame, after a gap or a reset): the twist is zero.
  void reset() { n_ = 0; }

  // The twist for a frame stamped t, before it is aligned: the measured c's extrapolated.
  Eigen::Vector3d predict(double t) const;

  // The twist of a frame stamped t from its measured velocity v over the interval dt before it,
  // the twist it was undistorted with (own) and the one the frame it was measured from was
  // (before). *c gets the frame's c, for commit().
  Eigen::Vector3d measure(double t, double dt, const Eigen::Vector3d& v, const Eigen::Vector3d& own,
                          const Eigen::Vector3d& before, Eigen::Vector3d* c) const;

  // The frame's c (from measure()) enters the model.
  void commit(double t, double dt, const Eigen::Vector3d& c);

 private:
  // The velocity at time `at` from the last two c's (and an extra one, when given).
  Eigen::Vector3d extrapolate(double at, const Eigen::Vector3d* c, double tc) const;

  double readout_;
  int n_ = 0;  // c's measured: 0, 1 or 2 (the last two)
  Eigen::Vector3d c_[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};  // c_[0] the last
  double t_[2] = {0.0, 0.0};  // the times c_ stand for
};

}  // namespace planarvo::track
