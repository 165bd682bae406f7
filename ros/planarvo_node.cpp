// planarvo_node: dense planar visual odometry (and the live extrinsics calibration) as a ROS 1
// node on planarvo's C API (ros/README.md).
//
// Threads: roscpp's spinner thread runs the subscriber callbacks, which only queue (an image
// callback is a push onto a deque, so roscpp's own subscriber queue never overflows); the main
// thread tracks the queued frames in order and publishes. A frame is dropped only when
// ~max_pending frames are waiting, and counted: nothing is lost silently. On SIGINT or SIGTERM the
// frames still queued are tracked (for up to ~drain_seconds), the calibration finishes, and the
// counts are logged and published once more.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/Odometry.h>
#include <planarvo/planarvo.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>

#include "frame_counts.h"
#include "image_input.h"
#include "live_calibration.h"
#include "node_params.h"
#include "odometry_publisher.h"

namespace planarvo_node {
namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

// A time jump back by more than this (a bag played again, a simulation restarted) resets the
// tracker; a smaller one is tracked as it is (the tracker reports it DEGRADED).
constexpr int64_t kResetJumpNs = 1000000000LL;

struct TrackerDeleter {
  void operator()(planarvo_tracker* t) const { planarvo_tracker_destroy(t); }
};

class Node {
 public:
  Node(ros::NodeHandle& nh, ros::NodeHandle& pnh, const NodeParams& params, planarvo_context* context,
       std::optional<planarvo_camera> camera, std::optional<planarvo_extrinsics> extrinsics)
      : params_(params),
        context_(context),
        camera_from_yaml_(camera.has_value()),
        camera_(camera),
        extrinsics_(extrinsics),
        publisher_(nh, params.odom_frame, params.base_frame, params.publish_tf) {
    counts_topic_ = pnh.advertise<std_msgs::String>("counts", 1, true);
    diagnostics_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10);
  }

  void on_image(const sensor_msgs::ImageConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.received;
    if (have_seq_ && m->header.seq > last_seq_ + 1) counts_.seq_gaps += m->header.seq - last_seq_ - 1;
    have_seq_ = true;
    last_seq_ = m->header.seq;
    if (queue_.size() >= static_cast<size_t>(params_.max_pending)) {
      queue_.pop_front();
      ++counts_.dropped_queue_full;
      ROS_WARN_THROTTLE(2, "planarvo_node: %d frames wait for the tracker (~max_pending): dropping the oldest "
                           "(%lld dropped so far)",
                        params_.max_pending, static_cast<long long>(counts_.dropped_queue_full));
    }
    queue_.push_back({m, ros::WallTime::now()});
    counts_.max_queue = std::max<int64_t>(counts_.max_queue, static_cast<int64_t>(queue_.size()));
    ready_.notify_one();
  }

  void on_camera_info(const sensor_msgs::CameraInfoConstPtr& m) {
    planarvo_camera c{};
    std::string error;
    if (!to_planarvo_camera(*m, &c, &error)) {
      ROS_ERROR_THROTTLE(10, "planarvo_node: %s", error.c_str());
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (!camera_) {
      camera_ = c;
      ROS_INFO("planarvo_node: camera from camera_info: %dx%d, fx %.3f fy %.3f cx %.3f cy %.3f", c.width, c.height,
               c.fx, c.fy, c.cx, c.cy);
      ready_.notify_one();
    } else if (!same_camera(c, *camera_) && !warned_camera_) {
      ROS_WARN("planarvo_node: camera_info (%dx%d, fx %.3f) differs from the camera in use (%s, %dx%d, fx %.3f); "
               "keeping the latter",
               c.width, c.height, c.fx, camera_from_yaml_ ? "~camera" : "the first camera_info", camera_->width,
               camera_->height, camera_->fx);
      warned_camera_ = true;
    }
  }

  void on_odometry(const nav_msgs::OdometryConstPtr& m) {
    std::lock_guard<std::mutex> lock(odometry_mutex_);
    if (calibration_) calibration_->add_odometry(*m);
    else if (early_odometry_.size() < 100000) early_odometry_.push_back(m);  // before the camera (and so the
                                                                         // calibrator) is known
  }

  // The worker loop; returns the exit code.
  int run() {
    auto last_counts = std::chrono::steady_clock::now();
    std::optional<std::chrono::steady_clock::time_point> drain_until;
    for (;;) {
      if (!drain_until && (g_stop || !ros::ok())) {
        drain_until = std::chrono::steady_clock::now() +
                      std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                          std::chrono::duration<double>(params_.drain_seconds));
        std::lock_guard<std::mutex> lock(mutex_);
        ROS_INFO("planarvo_node: stopping: %zu frames still queued", queue_.size());
      }
      Queued q;
      planarvo_camera camera{};
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait_for(lock, std::chrono::milliseconds(100), [&] { return !queue_.empty() && camera_; });
        if (drain_until && (queue_.empty() || !camera_ || std::chrono::steady_clock::now() > *drain_until)) {
          (camera_ ? counts_.unprocessed : counts_.no_camera) += static_cast<int64_t>(queue_.size());
          if (!camera_ && !queue_.empty())
            ROS_ERROR("planarvo_node: %zu frames were never tracked: no camera (no camera_info message arrived and "
                      "~camera is not set)",
                      queue_.size());
          queue_.clear();
          break;
        }
        if (queue_.empty() || !camera_) {
          if (!queue_.empty() && !warned_waiting_camera_) {
            ROS_WARN("planarvo_node: frames wait for a camera: no camera_info yet and ~camera is not set");
            warned_waiting_camera_ = true;
          }
          lock.unlock();
          maybe_publish_counts(&last_counts);
          report_progress();
          continue;
        }
        q = std::move(queue_.front());
        queue_.pop_front();
        camera = *camera_;
      }
      process(q, camera);
      maybe_publish_counts(&last_counts);
      report_progress();
    }
    if (calibration_) {
      calibration_->finish();
      std::lock_guard<std::mutex> lock(mutex_);
      counts_.calibration_frames = calibration_->frames_fed();
    }
    FrameCounts c;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      c = counts_;
    }
    publish_counts(c);
    if (counts_topic_.getNumSubscribers() > 0) ros::WallDuration(0.2).sleep();  // let the last counts go out
    ROS_INFO("%s", c.summary().c_str());
    std::printf("%s\n", c.summary().c_str());
    std::fflush(stdout);
    if (calibration_ && !calibration_->succeeded()) return 1;
    return 0;
  }

 private:
  struct Queued {
    sensor_msgs::ImageConstPtr msg;
    ros::WallTime received;
  };

  // The tracker and the calibrator, once the camera is known.
  void start(const planarvo_camera& given) {
    started_ = true;
    planarvo_camera camera = given;
    if (params_.readout_time >= 0) camera.rolling_shutter_readout = params_.readout_time;
    if (params_.exposure_time >= 0) camera.exposure_time = params_.exposure_time;
    if (extrinsics_) create_tracker(camera, *extrinsics_);
    if (params_.calibrate) {
      std::lock_guard<std::mutex> lock(odometry_mutex_);
      calibration_ = std::make_unique<LiveCalibration>(context_, camera, params_);
      for (const auto& m : early_odometry_) calibration_->add_odometry(*m);
      early_odometry_.clear();
    }
  }

  void create_tracker(const planarvo_camera& camera, const planarvo_extrinsics& e) {
    planarvo_tracker* t = nullptr;
    planarvo_tracker_options options = params_.tracker;
    options.flat_field = params_.flat_field.empty() ? nullptr : params_.flat_field.c_str();
    if (planarvo_tracker_create(context_, &camera, &e, &options, &t) != PLANARVO_OK)
      throw std::runtime_error(std::string("planarvo_tracker_create: ") + planarvo_last_error());
    tracker_.reset(t);
  }

  void process(const Queued& q, const planarvo_camera& camera) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!started_) start(camera);
    const sensor_msgs::Image& m = *q.msg;
    planarvo_image image{};
    std::string error;
    if (!to_planarvo_image(m, &buffer_, &image, &error)) return reject(m, error);
    if (image.width != camera.width || image.height != camera.height)
      return reject(m, "the image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                           " but the camera (" + (camera_from_yaml_ ? params_.camera : std::string("camera_info")) +
                           ") is " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
    ros::Time stamp = m.header.stamp;
    if (stamp.isZero()) {
      stamp = ros::Time::now();
      ROS_WARN_ONCE("planarvo_node: images without a header stamp: using the time they are processed");
    }
    const int64_t ns = static_cast<int64_t>(stamp.toNSec());
    // Times relative to the first frame in integer ns, then seconds: exact differences at any epoch.
    if (!have_origin_ || ns < last_ns_ - kResetJumpNs) {
      if (have_origin_) {
        ROS_WARN("planarvo_node: time went back by %.3f s: resetting the tracker (the odom frame continues)",
                 static_cast<double>(last_ns_ - ns) * 1e-9);
        if (tracker_) planarvo_tracker_reset(tracker_.get());
        publisher_.tracker_reset();
      }
      origin_ns_ = ns;
      have_origin_ = true;
      have_last_ = false;
    }
    if (!have_calibration_origin_) calibration_origin_ns_ = ns, have_calibration_origin_ = true;
    last_ns_ = ns;
    const double t = static_cast<double>(ns - origin_ns_) / 1e9;

    if (tracker_) track(q, image, stamp, t, t0);
    else {
      std::lock_guard<std::mutex> lock(mutex_);
      ++counts_.not_tracked;
    }
    if (calibration_ && !calibration_->finished()) {
      calibration_->add_frame(image, ns, static_cast<double>(ns - calibration_origin_ns_) / 1e9);
      if (calibration_->poll() && calibration_->succeeded() && !tracker_) {
        ROS_INFO("planarvo_node: tracking from now on with the calibrated extrinsics");
        create_tracker(camera, calibration_->extrinsics());
      }
      std::lock_guard<std::mutex> lock(mutex_);
      counts_.calibration_frames = calibration_->frames_fed();
    }
  }

  void track(const Queued& q, const planarvo_image& image, const ros::Time& stamp, double t,
             std::chrono::steady_clock::time_point t0) {
    planarvo_track_result r{};
    r.struct_size = sizeof r;
    const planarvo_status st = planarvo_tracker_track(tracker_.get(), &image, t, &r);
    if (st != PLANARVO_OK) {
      ROS_ERROR_THROTTLE(5, "planarvo_node: tracking the frame stamped %u.%09u failed: %s", stamp.sec, stamp.nsec,
                         planarvo_last_error());
      std::lock_guard<std::mutex> lock(mutex_);
      ++counts_.failed;
      return;
    }
    if (r.status == PLANARVO_TRACK_LOST || r.status == PLANARVO_TRACK_DEGRADED)
      ROS_WARN_THROTTLE(5, "planarvo_node: frame at t = %.3f s %s: %s", t,
                        r.status == PLANARVO_TRACK_LOST ? "lost" : "degraded", r.reason ? r.reason : "");
    if (r.mounting_changed) report_mounting_change(stamp, r);
    publisher_.publish(stamp, r, have_last_ ? t - last_t_ : 0.0);
    have_last_ = true;
    last_t_ = t;
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const double latency = (ros::WallTime::now() - q.received).toSec() * 1e3;
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.tracked;
    ++counts_.published;
    counts_.ok += r.status == PLANARVO_TRACK_OK || r.status == PLANARVO_TRACK_FIRST ? 1 : 0;
    counts_.degraded += r.status == PLANARVO_TRACK_DEGRADED ? 1 : 0;
    counts_.lost += r.status == PLANARVO_TRACK_LOST ? 1 : 0;
    counts_.process_ms.add(ms);
    counts_.engine_ms.add(r.ms);
    counts_.max_latency_ms = std::max(counts_.max_latency_ms, latency);
  }

  // The local plane found the camera's mounting changed: a warning, and a WARN diagnostic (the ROS
  // convention rqt_runtime_monitor and /diagnostics aggregators read) with the change and the
  // mounting now in use.
  void report_mounting_change(const ros::Time& stamp, const planarvo_track_result& r) {
    constexpr double kDeg = M_PI / 180.0;
    const planarvo_extrinsics& m = r.changed_mounting;
    const bool recalibrated = params_.tracker.on_mounting_change == PLANARVO_MOUNTING_RECALIBRATE;
    ROS_WARN("planarvo_node: the camera's mounting changed at t = %.3f s: the body's attitude stepped by roll %+.2f "
             "+- %.2f deg, pitch %+.2f +- %.2f deg and held; %s %.4f,%.4f,%.4f,%.3f,%.3f,%.3f (x,y,z m; "
             "roll,pitch,yaw deg)",
             r.mounting_change_time, r.mounting_step[0] / kDeg, r.mounting_step_sigma[0] / kDeg,
             r.mounting_step[1] / kDeg, r.mounting_step_sigma[1] / kDeg,
             recalibrated ? "tracking on with the mounting" : "keeping the mounting given (~mounting_change report); "
                                                              "the images say",
             m.x, m.y, m.z, m.roll / kDeg, m.pitch / kDeg, m.yaw / kDeg);
    diagnostic_msgs::DiagnosticArray a;
    a.header.stamp = stamp;
    diagnostic_msgs::DiagnosticStatus d;
    d.level = diagnostic_msgs::DiagnosticStatus::WARN;
    d.name = "planarvo_node: camera mounting";
    d.hardware_id = params_.base_frame;
    d.message = recalibrated ? "mounting changed: recalibrated" : "mounting changed: reported only";
    auto kv = [&d](const char* key, double value) {
      diagnostic_msgs::KeyValue k;
      k.key = key;
      k.value = std::to_string(value);
      d.values.push_back(k);
    };
    kv("change_time_s", r.mounting_change_time);
    kv("refinement", r.mounting_refinement);
    kv("roll_step_deg", r.mounting_step[0] / kDeg);
    kv("roll_step_sigma_deg", r.mounting_step_sigma[0] / kDeg);
    kv("pitch_step_deg", r.mounting_step[1] / kDeg);
    kv("pitch_step_sigma_deg", r.mounting_step_sigma[1] / kDeg);
    kv("yaw_step_deg", r.mounting_step[2] / kDeg);
    kv("yaw_step_sigma_deg", r.mounting_step_sigma[2] / kDeg);
    kv("x_m", m.x);
    kv("y_m", m.y);
    kv("z_m", m.z);
    kv("roll_deg", m.roll / kDeg);
    kv("pitch_deg", m.pitch / kDeg);
    kv("yaw_deg", m.yaw / kDeg);
    a.status.push_back(d);
    diagnostics_.publish(a);
  }

  void reject(const sensor_msgs::Image& m, const std::string& why) {
    ROS_ERROR_THROTTLE(5, "planarvo_node: frame seq %u stamped %u.%09u skipped: %s", m.header.seq, m.header.stamp.sec,
                       m.header.stamp.nsec, why.c_str());
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_.rejected;
  }

  // Said while nothing seems to happen: no image on the topic a few seconds after the start (with
  // the image topics that are published, every 30 s while none comes), and the live calibration's
  // progress every 5 s while it takes frames.
  void report_progress() {
    const auto now = std::chrono::steady_clock::now();
    int64_t received = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      received = counts_.received;
    }
    if (received == 0 && now - start_time_ >= std::chrono::seconds(4) && now >= next_no_image_warning_) {
      next_no_image_warning_ = now + std::chrono::seconds(30);
      ros::master::V_TopicInfo topics;
      std::string published;
      if (ros::master::getTopics(topics))
        for (const ros::master::TopicInfo& t : topics)
          if (t.datatype == "sensor_msgs/Image" || t.datatype == "sensor_msgs/CompressedImage")
            published += (published.empty() ? "" : ", ") + t.name + " (" + t.datatype + ")";
      ROS_WARN("planarvo_node: no image on %s after %.0f s; image topics being published: %s%s",
               ros::names::resolve("image").c_str(), std::chrono::duration<double>(now - start_time_).count(),
               published.empty() ? "none" : published.c_str(),
               published.empty() ? "" : " (remap with image:=TOPIC)");
    }
    if (calibration_ && !calibration_->finished() && calibration_->frames_fed() != progress_fed_ &&
        now - last_progress_ >= std::chrono::seconds(5)) {
      last_progress_ = now;
      progress_fed_ = calibration_->frames_fed();
      const double metres = calibration_->odometry_travelled(), degrees = calibration_->odometry_turned() * 180 / M_PI;
      if (params_.calibration_frames > 0)
        ROS_INFO("planarvo_node: calibration: %lld of %d frames (%lld with odometry); odometry so far %.3f m, "
                 "%.1f deg turned",
                 static_cast<long long>(progress_fed_), params_.calibration_frames,
                 static_cast<long long>(calibration_->frames_with_odometry()), metres, degrees);
      else
        ROS_INFO("planarvo_node: calibration: %lld frames so far (%lld with odometry); odometry so far %.3f m, "
                 "%.1f deg turned; it finishes at shutdown",
                 static_cast<long long>(progress_fed_), static_cast<long long>(calibration_->frames_with_odometry()),
                 metres, degrees);
    }
  }

  void maybe_publish_counts(std::chrono::steady_clock::time_point* last) {
    const auto now = std::chrono::steady_clock::now();
    if (now - *last < std::chrono::seconds(1)) return;
    *last = now;
    FrameCounts c;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (counts_.received == published_received_ && counts_.tracked == published_tracked_) return;
      published_received_ = counts_.received;
      published_tracked_ = counts_.tracked;
      c = counts_;
    }
    publish_counts(c);
  }

  void publish_counts(const FrameCounts& c) {
    std_msgs::String s;
    s.data = c.yaml();
    counts_topic_.publish(s);
    // The same counts as the ROS convention for a node's health, which rqt_runtime_monitor and
    // /diagnostics aggregators read: one status, each count a key/value; WARN once frames were
    // dropped or lost.
    diagnostic_msgs::DiagnosticArray a;
    a.header.stamp = ros::Time::now();
    diagnostic_msgs::DiagnosticStatus d;
    d.name = ros::this_node::getName() + ": frames";
    d.hardware_id = ros::this_node::getName();
    d.level = c.dropped() > 0 || c.lost > 0 ? diagnostic_msgs::DiagnosticStatus::WARN : diagnostic_msgs::DiagnosticStatus::OK;
    d.message = "received " + std::to_string(c.received) + ", tracked " + std::to_string(c.tracked) + ", lost " +
                std::to_string(c.lost) + ", dropped " + std::to_string(c.dropped());
    std::istringstream lines(s.data);
    std::string line;
    while (std::getline(lines, line)) {
      const size_t colon = line.find(": ");
      if (colon == std::string::npos) continue;
      diagnostic_msgs::KeyValue kv;
      kv.key = line.substr(0, colon);
      kv.value = line.substr(colon + 2);
      d.values.push_back(kv);
    }
    a.status.push_back(d);
    diagnostics_.publish(a);
  }

  const NodeParams& params_;
  planarvo_context* context_;
  const bool camera_from_yaml_;

  std::mutex mutex_;  // guards the queue, the camera, the counts and the seq numbers
  std::condition_variable ready_;
  std::deque<Queued> queue_;
  std::optional<planarvo_camera> camera_;
  FrameCounts counts_;
  bool have_seq_ = false, warned_camera_ = false, warned_waiting_camera_ = false;
  uint32_t last_seq_ = 0;
  int64_t published_received_ = -1, published_tracked_ = -1;
  const std::chrono::steady_clock::time_point start_time_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point next_no_image_warning_ = start_time_, last_progress_ = start_time_;
  int64_t progress_fed_ = 0;

  std::mutex odometry_mutex_;  // guards calibration_'s creation against on_odometry
  std::vector<nav_msgs::OdometryConstPtr> early_odometry_;
  std::unique_ptr<LiveCalibration> calibration_;

  // The worker thread's own.
  std::optional<planarvo_extrinsics> extrinsics_;
  std::unique_ptr<planarvo_tracker, TrackerDeleter> tracker_;
  OdometryPublisher publisher_;
  ros::Publisher diagnostics_;  // the counts, and with the local plane a change of the camera's mounting
  ros::Publisher counts_topic_;
  std::vector<uint8_t> buffer_;
  bool started_ = false, have_origin_ = false, have_last_ = false, have_calibration_origin_ = false;
  int64_t origin_ns_ = 0, last_ns_ = 0, calibration_origin_ns_ = 0;
  double last_t_ = 0;
};

struct ContextDeleter {
  void operator()(planarvo_context* c) const { planarvo_context_destroy(c); }
};

int run(int argc, char** argv) {
  ros::init(argc, argv, "planarvo_node", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  ros::NodeHandle nh, pnh("~");
  NodeParams params;
  if (!read_params(pnh, &params)) return 2;

  std::optional<planarvo_extrinsics> extrinsics;
  if (!params.extrinsics.empty()) {
    planarvo_extrinsics e{};
    if (planarvo_extrinsics_load(params.extrinsics.c_str(), &e) != PLANARVO_OK) {
      ROS_FATAL("planarvo_node: ~extrinsics: %s", planarvo_last_error());
      return 2;
    }
    extrinsics = e;
  }
  std::optional<planarvo_camera> camera;
  if (!params.camera.empty()) {
    planarvo_camera c{};
    if (planarvo_camera_load(params.camera.c_str(), &c) != PLANARVO_OK) {
      ROS_FATAL("planarvo_node: ~camera: %s", planarvo_last_error());
      return 2;
    }
    camera = c;
  }

  planarvo_context_options o;
  planarvo_context_options_init(&o);
  if (!params.device.empty()) o.device = params.device.c_str();
  if (!params.cache_dir.empty()) o.cache_dir = params.cache_dir.c_str();
  if (!params.kernel_binaries.empty()) o.kernel_binaries_dir = params.kernel_binaries.c_str();
  planarvo_context* raw = nullptr;
  const planarvo_status st = planarvo_context_create(&o, &raw);
  if (st != PLANARVO_OK) {
    ROS_FATAL("planarvo_node: no OpenCL context (~device \"%s\"): %s", params.device.c_str(), planarvo_last_error());
    return st == PLANARVO_ERROR_NO_DEVICE ? 3 : 2;
  }
  std::unique_ptr<planarvo_context, ContextDeleter> context(raw);
  planarvo_device_info info{};
  info.struct_size = sizeof info;
  if (planarvo_context_device(context.get(), &info) == PLANARVO_OK)
    ROS_INFO("planarvo_node: planarvo %s on %s (%s)", planarvo_version_string(), info.device_name, info.platform_name);
  if (params.prepare_kernels && planarvo_context_prepare_kernels(context.get()) != PLANARVO_OK) {
    ROS_FATAL("planarvo_node: building the kernels: %s", planarvo_last_error());
    return 1;
  }

  int rc = 0;
  {
    Node node(nh, pnh, params, context.get(), camera, extrinsics);
    // Subscribed last: a subscriber on `image` means the node is ready.
    ros::Subscriber info_sub = nh.subscribe("camera_info", 10, &Node::on_camera_info, &node);
    ros::Subscriber odom_sub;
    if (params.calibrate) odom_sub = nh.subscribe("odom", 1000, &Node::on_odometry, &node);
    ros::Subscriber image_sub = nh.subscribe("image", static_cast<uint32_t>(params.queue_size), &Node::on_image, &node,
                                             ros::TransportHints().tcpNoDelay());
    ROS_INFO("planarvo_node: ready: %s on %s%s", params.calibrate ? (extrinsics ? "tracking and calibrating" : "calibrating") : "tracking",
             image_sub.getTopic().c_str(), camera ? "" : " (camera from camera_info)");
    ros::AsyncSpinner spinner(1);
    spinner.start();
    rc = node.run();
    spinner.stop();
  }
  ros::shutdown();
  return rc;
}

}  // namespace
}  // namespace planarvo_node

int main(int argc, char** argv) {
  // Line-buffered even when stdout is a file or a pipe (a service, a container): each log line is
  // there as it happens, not when the node exits.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    return planarvo_node::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "planarvo_node: %s\n", e.what());
    return 1;
  }
}
