// Accuracy of estimated frame-to-frame motions against ground truth, in the figures the paper
// and the issues use: fitted slopes of linear and angular velocity (the paper's Figure 9),
// per-frame translation error, gross errors, and end-point drift relative to distance.
#pragma once
#include <vector>

#include "core/se2.h"

namespace planarvo::track {

struct MotionAccuracy {
  int intervals = 0;              // compared
  double distance = 0;            // metres travelled (ground truth)
  double slope_linear = 0;        // least-squares line estimated = a * true + b over forward
  double slope_angular = 0;       //   speed v = dx/dt and angular speed omega = dtheta/dt
  double rms_translation = 0;     // per-interval translation error |t_est - t_true|, metres
  double max_translation = 0;
  double rms_rotation = 0;        // radians
  int gross_errors = 0;           // translation errors above the threshold
  double endpoint_error = 0;      // |end position of the composed estimate - truth|, metres
  double endpoint_drift = 0;      // endpoint_error / distance (fraction)
  double endpoint_heading = 0;    // radians
};

// The least-squares line y = slope x + offset (the velocity slopes above, the lean in
// body_lean.h).
struct LineFit {
  double slope = 0.0, offset = 0.0;
  double slope_sigma = 0.0;  // standard error of the slope: infinite below 3 samples or without spread in x
  double r2 = 0.0;           // the share of the variance the line explains
  int samples = 0;
};
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

// estimated[i], truth[i]: motion over interval i (the robot's pose at its end in the robot
// frame at its start); dt[i] its duration. Intervals with valid[i] == false (if given) are left
// out of the per-interval figures, but the composed trajectory always uses the estimate.
MotionAccuracy evaluate_motions(const std::vector<SE2>& estimated, const std::vector<SE2>& truth,
                                const std::vector<double>& dt, double gross_threshold = 1e-3,
                                const std::vector<bool>& valid = {});

}  // namespace planarvo::track
