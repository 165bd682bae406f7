// The graph calibration's input from the tracker: one sample per tracked frame interval, the
// camera's planar motion with the tracker's covariance (in units of the camera height when the
// tracker runs at x = y = 0, z = 1, yaw = 0), the wheel odometry's motion over the same interval
// (the data set's poses interpolated to the frame times) and the interval's direction label.
#pragma once
#include <optional>
#include <vector>

#include "core/se2.h"
#include "graph/calibration/calibration.h"
#include "track/tracker.h"

namespace planarvo::calib {

class MotionSampler {
 public:
  // Frame k's tracking result, its time, the robot's odometry pose at that time (none when the
  // odometry does not cover it) and the direction label of the interval ending at it. A lost
  // frame, the first one, and an interval without a positive duration give no sample (the
  // chain of samples simply has a gap; each sample is a relative motion on its own).
  void add(const track::FrameResult& result, double timestamp, const std::optional<SE2>& odometry_pose,
           const std::optional<int>& direction);
  void clear();

  const std::vector<graph::MotionSample>& samples() const { return samples_; }
  // Per sample, its motion's d / d (roll, pitch) (FrameResult::motion_tilt_jacobian; zero unless
  // the tracker made them).
  const std::vector<Eigen::Matrix<double, 3, 2>>& tilt_jacobians() const { return tilt_jacobians_; }
  int lost() const { return lost_; }                    // intervals not sampled: tracking lost
  int without_odometry() const { return no_odometry_; } // samples whose odometry is missing

 private:
  std::vector<graph::MotionSample> samples_;
  std::vector<Eigen::Matrix<double, 3, 2>> tilt_jacobians_;
  bool has_previous_ = false;
  double previous_t_ = 0.0;
  std::optional<SE2> previous_odometry_;
  int lost_ = 0, no_odometry_ = 0;
};

}  // namespace planarvo::calib
