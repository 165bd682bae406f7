#include "odometry_publisher.h"

#include <cmath>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <tf2_msgs/TFMessage.h>

namespace planarvo_node {
namespace {

geometry_msgs::Quaternion yaw_quaternion(double yaw) {
  geometry_msgs::Quaternion q;
  q.x = 0;
  q.y = 0;
  q.z = std::sin(yaw / 2);
  q.w = std::cos(yaw / 2);
  return q;
}

// A 3x3 (x, y, yaw) covariance into a row-major 6x6 (x, y, z, roll, pitch, yaw) one.
void to_6x6(const double c3[9], double scale, boost::array<double, 36>* c6) {
  c6->fill(0.0);
  const int index[3] = {0, 1, 5};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) (*c6)[static_cast<size_t>(index[r] * 6 + index[c])] = c3[r * 3 + c] * scale;
  for (int i = 2; i <= 4; ++i) (*c6)[static_cast<size_t>(i * 7)] = kUnusedVariance;
}

bool finite_covariance(const double c[9]) {
  for (int i = 0; i < 9; ++i)
    if (!std::isfinite(c[i])) return false;
  return true;
}

// c = A c A' + B m B' for 3x3 matrices.
std::array<double, 9> propagate(const std::array<double, 9>& c, const double a[9], const double m[9], const double b[9]) {
  auto mul = [](const double* x, const double* y, bool transpose_y) {
    std::array<double, 9> r{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) r[static_cast<size_t>(i * 3 + j)] += x[i * 3 + k] * (transpose_y ? y[j * 3 + k] : y[k * 3 + j]);
    return r;
  };
  const std::array<double, 9> ac = mul(a, c.data(), false), aca = mul(ac.data(), a, true);
  const std::array<double, 9> bm = mul(b, m, false), bmb = mul(bm.data(), b, true);
  std::array<double, 9> r{};
  for (size_t i = 0; i < 9; ++i) r[i] = aca[i] + bmb[i];
  return r;
}

}  // namespace

planarvo_se2 compose(const planarvo_se2& a, const planarvo_se2& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, std::remainder(a.theta + b.theta, 2 * M_PI)};
}

OdometryPublisher::OdometryPublisher(ros::NodeHandle& nh, const std::string& odom_frame, const std::string& base_frame,
                                     bool publish_tf)
    : odom_frame_(odom_frame), base_frame_(base_frame), publish_tf_(publish_tf) {
  odometry_ = nh.advertise<nav_msgs::Odometry>("odometry", 100);
  if (publish_tf_) tf_ = nh.advertise<tf2_msgs::TFMessage>("/tf", 100);
}

void OdometryPublisher::tracker_reset() { offset_ = last_; }

void OdometryPublisher::publish(const ros::Time& stamp, const planarvo_track_result& r, double dt) {
  const planarvo_se2 pose = compose(offset_, r.pose);
  const bool first = r.status == PLANARVO_TRACK_FIRST;
  const bool covariance_ok = finite_covariance(r.covariance);
  // The pose's covariance: the last one moved along the step, plus the motion's rotated into the
  // odom frame (first order; frames tracked against one keyframe have correlated errors, which
  // this treats as independent, so it tends to overstate the uncertainty).
  if (!first) {
    double m[9];
    for (int i = 0; i < 9; ++i) m[i] = covariance_ok ? r.covariance[i] : (i % 4 == 0 ? kUnusedVariance : 0.0);
    const double a[9] = {1, 0, -(pose.y - last_.y), 0, 1, pose.x - last_.x, 0, 0, 1};
    const double c = std::cos(pose.theta), s = std::sin(pose.theta);
    const double b[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
    pose_covariance_ = propagate(pose_covariance_, a, m, b);
  }
  last_ = pose;

  nav_msgs::Odometry o;
  o.header.stamp = stamp;
  o.header.frame_id = odom_frame_;
  o.child_frame_id = base_frame_;
  o.pose.pose.position.x = pose.x;
  o.pose.pose.position.y = pose.y;
  o.pose.pose.position.z = 0;
  o.pose.pose.orientation = yaw_quaternion(pose.theta);
  to_6x6(pose_covariance_.data(), 1.0, &o.pose.covariance);
  if (!first && dt > 0 && covariance_ok) {
    o.twist.twist.linear.x = r.motion.x / dt;
    o.twist.twist.linear.y = r.motion.y / dt;
    o.twist.twist.angular.z = r.motion.theta / dt;
    to_6x6(r.covariance, 1.0 / (dt * dt), &o.twist.covariance);
  } else {  // no interval to take a velocity over: zero, and unknown
    const double unknown[9] = {kUnusedVariance, 0, 0, 0, kUnusedVariance, 0, 0, 0, kUnusedVariance};
    to_6x6(unknown, 1.0, &o.twist.covariance);
  }
  odometry_.publish(o);

  if (!publish_tf_) return;
  tf2_msgs::TFMessage tf;
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = odom_frame_;
  t.child_frame_id = base_frame_;
  t.transform.translation.x = pose.x;
  t.transform.translation.y = pose.y;
  t.transform.translation.z = 0;
  t.transform.rotation = o.pose.pose.orientation;
  tf.transforms.push_back(t);
  tf_.publish(tf);
}

}  // namespace planarvo_node
