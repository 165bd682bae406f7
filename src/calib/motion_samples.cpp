#include "calib/motion_samples.h"

namespace planarvo::calib {

void MotionSampler::add(const track::FrameResult& r, double t, const std::optional<SE2>& odometry_pose,
                        const std::optional<int>& direction) {
  using Status = track::FrameResult::Status;
  const bool sampled = has_previous_ && (r.status == Status::Ok || r.status == Status::Degraded) && t > previous_t_;
  if (has_previous_ && r.status == Status::Lost) ++lost_;
  if (sampled) {
    graph::MotionSample s;
    s.interval = t - previous_t_;
    s.sensor = r.motion;
    if (odometry_pose && previous_odometry_) {
      s.odometry = Motion{previous_odometry_->inverse() * *odometry_pose, Eigen::Matrix3d::Zero()};
    } else {
      ++no_odometry_;
    }
    s.direction = direction;
    samples_.push_back(s);
    tilt_jacobians_.push_back(r.motion_tilt_jacobian);
  }
  has_previous_ = true;
  previous_t_ = t;
  previous_odometry_ = odometry_pose;
}

void MotionSampler::clear() { *this = MotionSampler(); }

}  // namespace planarvo::calib
