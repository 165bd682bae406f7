// The live calibration (~calibrate): planarvo_camera_calibrator fed with the frames as they come
// and the wheel odometry's samples (nav_msgs/Odometry on `odom`), which the calibrator interpolates
// to each frame's stamp. A frame waits until an odometry message at or after its stamp has arrived (at most
// ~calibration_odom_wait seconds of frames; then it goes in without odometry, with a warning). The
// calibration finishes after ~calibration_frames frames, or on shutdown, and writes
// ~calibration_output.
#pragma once
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <planarvo/planarvo.h>

#include "node_params.h"

namespace planarvo_node {

class LiveCalibration {
 public:
  LiveCalibration(planarvo_context* context, const planarvo_camera& camera, const NodeParams& params);
  ~LiveCalibration();
  LiveCalibration(const LiveCalibration&) = delete;
  LiveCalibration& operator=(const LiveCalibration&) = delete;

  // Any thread (the odom subscriber's).
  void add_odometry(const nav_msgs::Odometry& odometry);
  // The worker thread: a frame (copied), its stamp in ns and its time in seconds since the first frame.
  void add_frame(const planarvo_image& image, int64_t stamp_ns, double t);
  // Feeds what waits and finishes when enough frames went in; true once finished.
  bool poll();
  // Feeds every waiting frame (with the odometry there is) and finishes, if not yet finished.
  void finish();
  bool finished() const { return finished_; }
  bool succeeded() const { return succeeded_; }
  const planarvo_extrinsics& extrinsics() const { return result_.extrinsics; }
  int64_t frames_fed() const { return fed_; }
  int64_t frames_with_odometry() const { return with_odometry_; }
  // The wheel odometry's motion handed to the calibrator so far: the path's length (m) and the
  // sum of the absolute turns (rad) between consecutive samples.
  double odometry_travelled() const { return travelled_; }
  double odometry_turned() const { return turned_; }

 private:
  struct Frame {
    std::vector<uint8_t> pixels;
    planarvo_image image;
    int64_t ns;
    double t;
  };
  struct Pose {
    int64_t ns;
    planarvo_se2 pose;
  };
  void feed(Frame& frame, bool final);
  void complete();

  const NodeParams& params_;
  planarvo_camera_calibrator* calibrator_ = nullptr;
  std::mutex mutex_;         // guards odometry_ and newest_ns_
  std::deque<Pose> odometry_;  // received, not yet handed to the calibrator
  int64_t newest_ns_ = -1;     // the newest odometry stamp received
  int64_t origin_ns_ = 0;      // the stamp of t = 0 (the first frame's)
  bool has_origin_ = false;
  int64_t first_given_ns_ = -1, last_given_ns_ = -1;  // the odometry handed to the calibrator
  planarvo_se2 last_given_{};
  double travelled_ = 0, turned_ = 0;
  std::deque<Frame> waiting_;
  int64_t fed_ = 0, with_odometry_ = 0;
  double last_t_ = -1;
  bool finished_ = false, succeeded_ = false, warned_no_odometry_ = false;
  planarvo_camera_calibration_result result_{};
};

}  // namespace planarvo_node
