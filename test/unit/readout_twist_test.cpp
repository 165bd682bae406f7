// The rolling shutter's twist model (track/readout_twist.h) against its derivation: velocities
// "measured" from the previous frame's corrected pose by the linear model
// v = v_true - k (tw_k - xi_k), k = m / dt (m the mean row time, (readout - exposure) / 2), from
// a velocity profile linear in time, whatever twists the frames were undistorted with; the model
// must return xi_k, the velocity at frame k's mean row time, exactly (a linear profile is what it
// extrapolates exactly), and predict the next frame's before it is measured. Over readouts and
// exposures that make k positive, zero and negative.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "track/readout_twist.h"

namespace planarvo::track {
namespace {

TEST(ReadoutTwist, RecoversTheTwistOverTheReadoutWhateverTheFramesWereUndistortedWith) {
  const double shutters[][2] = {{0.025, 0.0}, {0.0, 0.004}, {0.025, 0.004}, {0.01, 0.01}, {0.005, 0.03}};
  for (const auto& shutter : shutters) {
    const double readout = shutter[0], exposure = shutter[1], dt = 1.0 / 30.0;
    const double m = 0.5 * (readout - exposure);
    SCOPED_TRACE("readout " + std::to_string(readout) + " exposure " + std::to_string(exposure));
    const Eigen::Vector3d v0(0.2, -0.05, 0.3), a(1.5, 0.4, -2.0);  // per second, per second^2
    auto velocity = [&](double t) -> Eigen::Vector3d { return v0 + a * t; };
    ReadoutTwist model(m);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> off(-0.3, 0.3);
    for (int k = 1; k < 12; ++k) {
      const double t = k * dt;
      const Eigen::Vector3d xi = velocity(t + m);
      // Undistorted with a twist off by a random amount (a prediction, or nothing yet).
      const Eigen::Vector3d tw = xi + Eigen::Vector3d(off(rng), off(rng), off(rng));
      const Eigen::Vector3d v_true = velocity(t - 0.5 * dt);  // the mean over the interval
      const Eigen::Vector3d v = v_true - m / dt * (tw - xi);
      Eigen::Vector3d c;
      double tc = 0.0;
      const Eigen::Vector3d got = model.measure(t, dt, v, tw, &c, &tc);
      if (k >= 2) {
        EXPECT_LT((got - xi).norm(), 1e-9) << "frame " << k;
      }
      EXPECT_LT((c - velocity(tc)).norm(), 1e-9) << "frame " << k;
      model.commit(c, tc);
      if (k >= 2) {  // the next frame's twist before it is measured
        EXPECT_LT((model.predict(t + dt) - velocity(t + dt + m)).norm(), 1e-9) << "frame " << k;
      }
    }
    model.reset();
    EXPECT_EQ(model.predict(1.0), Eigen::Vector3d::Zero());
  }
}

}  // namespace
}  // namespace planarvo::track
