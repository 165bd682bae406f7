// The vehicle's lean (the paper's section 6.4, its Figure 18): how the body's attitude relative to
// the local ground plane, as the local plane tracks it (local_plane.h), follows the drive. A car's
// body rolls with the yaw rate in turns (the centripetal acceleration is v omega, and at the
// speeds a turn is driven the paper found roll proportional to omega: -0.07 degrees per
// degree/s) and pitches with the longitudinal acceleration (braking dips the nose).
//
// Fitted by least squares over the frames given: roll = k_roll omega + c_roll and pitch =
// k_pitch a + c_pitch. omega is each frame's yaw rate (its motion's heading over its interval);
// a is the forward speed's central difference around the frame. The offsets take up what the
// mounting's calibration is off by. The sigma are the slope's standard errors from the fit's own
// residual scatter: the per-frame attitudes' errors are not independent of each other from frame to
// frame (they share keyframes), so this is a lower bound when the residual is mostly their error.
#pragma once
#include <vector>

#include "core/se2.h"
#include "track/evaluation.h"

namespace planarvo::track {

struct BodyLean {
  LineFit roll_per_yaw_rate;        // radians per (radian/s): seconds, the same as degrees per degree/s
  LineFit pitch_per_acceleration;   // radians per (m/s^2)
};

// Frame k (k >= 1) has motion[k] over the interval t[k-1]..t[k] and the attitude roll[k],
// pitch[k]; use[k] false leaves it out (Lost frames, for example). Frame 0 is only a time.
BodyLean fit_body_lean(const std::vector<double>& t, const std::vector<SE2>& motion, const std::vector<double>& roll,
                       const std::vector<double>& pitch, const std::vector<bool>& use);

}  // namespace planarvo::track
