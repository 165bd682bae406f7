// The tracker's results as ROS odometry: nav_msgs/Odometry on `odometry` and the transform
// odom_frame -> base_frame on /tf (tf2_msgs/TFMessage, published directly: no tf2_ros needed).
//
// pose: the tracker's accumulated planar pose (composed after an offset when the tracker was
// reset, so that the odom frame stays continuous), its covariance propagated frame by frame from
// the motions' 3x3 covariances; twist: the motion over the interval divided by its duration, in
// base_frame, with the motion's covariance / dt^2. Both 6x6 in (x, y, z, roll, pitch, yaw) with
// kUnusedVariance on z, roll and pitch, as robot_localization expects of planar odometry.
#pragma once
#include <array>
#include <string>

#include <planarvo/planarvo.h>
#include <ros/ros.h>

namespace planarvo_node {

constexpr double kUnusedVariance = 1e6;

class OdometryPublisher {
 public:
  OdometryPublisher(ros::NodeHandle& nh, const std::string& odom_frame, const std::string& base_frame, bool publish_tf);
  // Publishes the result of a frame stamped `stamp`; dt: seconds since the previous published
  // frame (0 for the first after a start or a reset).
  void publish(const ros::Time& stamp, const planarvo_track_result& result, double dt);
  // The tracker was reset: its poses start again at the identity, composed after the last pose.
  void tracker_reset();

 private:
  ros::Publisher odometry_, tf_;
  std::string odom_frame_, base_frame_;
  bool publish_tf_;
  planarvo_se2 offset_{0, 0, 0};  // the odom-frame pose of the tracker's first frame
  planarvo_se2 last_{0, 0, 0};    // the last published odom-frame pose
  std::array<double, 9> pose_covariance_{};  // of last_ (x, y, yaw), world-frame perturbation
};

// a then b (b expressed in a's frame).
planarvo_se2 compose(const planarvo_se2& a, const planarvo_se2& b);

}  // namespace planarvo_node
