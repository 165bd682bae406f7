#include "live_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <ros/ros.h>

namespace planarvo_node {
namespace {

double yaw_of(const geometry_msgs::Quaternion& q) {
  return std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
}

}  // namespace

LiveCalibration::LiveCalibration(planarvo_context* context, const planarvo_camera& camera, const NodeParams& params)
    : params_(params) {
  planarvo_camera_calibration_options o;
  planarvo_camera_calibration_options_init(&o);
  o.method = PLANARVO_CALIBRATE_ODOMETRY;
  o.height = params.calibration_height;
  o.accept_unusual_extrinsics = params.force ? 1 : 0;
  o.tracker = &params.tracker;
  if (planarvo_camera_calibrator_create(context, &camera, &o, &calibrator_) != PLANARVO_OK)
    throw std::runtime_error(std::string("planarvo_camera_calibrator_create: ") + planarvo_last_error());
  result_.struct_size = sizeof result_;
}

LiveCalibration::~LiveCalibration() { planarvo_camera_calibrator_destroy(calibrator_); }

void LiveCalibration::add_odometry(const nav_msgs::Odometry& m) {
  const Pose p{static_cast<int64_t>(m.header.stamp.toNSec()),
               {m.pose.pose.position.x, m.pose.pose.position.y, yaw_of(m.pose.pose.orientation)}};
  std::lock_guard<std::mutex> lock(mutex_);
  if (p.ns <= newest_ns_) return;  // a repeat, or time went back (a new run: its frames are left out too)
  newest_ns_ = p.ns;
  odometry_.push_back(p);
}

void LiveCalibration::add_frame(const planarvo_image& image, int64_t stamp_ns, double t) {
  if (finished_) return;
  if (t <= last_t_) {
    ROS_WARN_THROTTLE(5, "planarvo_node: calibration: a frame at t = %.6f s after one at %.6f s is left out", t, last_t_);
    return;
  }
  if (!has_origin_) {
    origin_ns_ = stamp_ns - static_cast<int64_t>(std::llround(t * 1e9));
    has_origin_ = true;
  }
  last_t_ = t;
  Frame f;
  const size_t bpp = image.format == PLANARVO_GRAY8 ? 1 : 3;
  const size_t row = static_cast<size_t>(image.width) * bpp;
  f.pixels.resize(row * static_cast<size_t>(image.height));
  for (int32_t y = 0; y < image.height; ++y)
    std::memcpy(f.pixels.data() + row * static_cast<size_t>(y),
                static_cast<const uint8_t*>(image.data) + image.stride * static_cast<size_t>(y), row);
  f.image = image;
  f.image.data = f.pixels.data();
  f.image.stride = row;
  f.ns = stamp_ns;
  f.t = t;
  waiting_.push_back(std::move(f));
}

// Hands the odometry received so far to the calibrator, which interpolates the frame's pose from it
// (none when the frame lies outside it; final: the odometry will not grow any more).
void LiveCalibration::feed(Frame& f, bool final) {
  std::deque<Pose> received;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    received.swap(odometry_);
  }
  for (const Pose& p : received) {
    const double t = static_cast<double>(p.ns - origin_ns_) * 1e-9;
    if (planarvo_camera_calibrator_add_odometry(calibrator_, t, &p.pose) != PLANARVO_OK) {
      ROS_WARN_THROTTLE(5, "planarvo_node: calibration: odometry left out: %s", planarvo_last_error());
      continue;
    }
    if (first_given_ns_ < 0) {
      first_given_ns_ = p.ns;
    } else {
      travelled_ += std::hypot(p.pose.x - last_given_.x, p.pose.y - last_given_.y);
      turned_ += std::abs(std::remainder(p.pose.theta - last_given_.theta, 2 * M_PI));
    }
    last_given_ns_ = p.ns;
    last_given_ = p.pose;
  }
  const bool has = first_given_ns_ >= 0 && first_given_ns_ <= f.ns && f.ns <= last_given_ns_;
  if (!has && !warned_no_odometry_) {
    ROS_WARN("planarvo_node: calibration: no odometry around the frame at t = %.3f s%s; frames without it give "
             "the calibration no interval",
             f.t, final ? " (shutdown)" : " within ~calibration_odom_wait");
    warned_no_odometry_ = true;
  }
  const planarvo_status st = planarvo_camera_calibrator_add_frame(calibrator_, &f.image, f.t, nullptr, nullptr);
  if (st != PLANARVO_OK)
    ROS_ERROR_THROTTLE(5, "planarvo_node: calibration: frame at t = %.3f s: %s", f.t, planarvo_last_error());
  ++fed_;
  with_odometry_ += has ? 1 : 0;
}

bool LiveCalibration::poll() {
  while (!finished_ && !waiting_.empty()) {
    Frame& f = waiting_.front();
    int64_t newest = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      newest = newest_ns_;
    }
    const bool covered = newest >= f.ns;
    const bool waited_too_long =
        static_cast<double>(waiting_.back().ns - f.ns) * 1e-9 > params_.calibration_odom_wait;
    if (!covered && !waited_too_long) break;
    feed(f, false);
    waiting_.pop_front();
    if (params_.calibration_frames > 0 && fed_ >= params_.calibration_frames) complete();
  }
  return finished_;
}

void LiveCalibration::finish() {
  if (finished_) return;
  while (!waiting_.empty()) {
    feed(waiting_.front(), true);
    waiting_.pop_front();
  }
  complete();
}

void LiveCalibration::complete() {
  finished_ = true;
  waiting_.clear();
  ROS_INFO("planarvo_node: calibrating from %lld frames (%lld with odometry)...", static_cast<long long>(fed_),
           static_cast<long long>(with_odometry_));
  const planarvo_status st = planarvo_camera_calibrator_finish(calibrator_, &result_);
  if (st != PLANARVO_OK) {
    ROS_ERROR("planarvo_node: calibration failed (%s): %s; %s not written", planarvo_status_name(st),
              st == PLANARVO_ERROR_FAILED ? result_.reason : planarvo_last_error(), params_.calibration_output.c_str());
    return;
  }
  const std::string notes = "planarvo_node live calibration, " + std::to_string(fed_) + " frames";
  if (planarvo_camera_calibration_save(params_.calibration_output.c_str(), &result_, notes.c_str()) != PLANARVO_OK) {
    ROS_ERROR("planarvo_node: calibration: %s", planarvo_last_error());
    return;
  }
  succeeded_ = true;
  const planarvo_extrinsics& e = result_.extrinsics;
  double sigma[6];  // the standard deviations: the covariance's diagonal (x y z roll pitch yaw)
  for (int i = 0; i < 6; ++i) sigma[i] = std::sqrt(std::max(0.0, result_.covariance[7 * i]));
  const double deg = 180 / M_PI;
  ROS_INFO("planarvo_node: calibrated: x %.4f +- %.4f, y %.4f +- %.4f, z %.4f +- %.4f m; roll %.3f +- %.3f, pitch "
           "%.3f +- %.3f, yaw %.3f +- %.3f deg; wrote %s",
           e.x, sigma[0], e.y, sigma[1], e.z, sigma[2], e.roll * deg, sigma[3] * deg, e.pitch * deg, sigma[4] * deg,
           e.yaw * deg, sigma[5] * deg, params_.calibration_output.c_str());
}

}  // namespace planarvo_node
