// The files users already have (shared/spec/formats.md): OpenCV calibration YAML, extrinsics
// YAML, TUM trajectories, direction labels, per-frame statistics CSV. Every reader names the
// file, and the line where one applies, in its InvalidInput errors; every writer throws
// Error(Io) naming the file when it cannot write.
#pragma once
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/extrinsics.h"
#include "core/se2.h"
#include "image/camera.h"

namespace planarvo::io {

CameraModel read_camera_yaml(const std::string& path);
void write_camera_yaml(const std::string& path, const CameraModel& camera);

struct ExtrinsicsFile {
  Extrinsics value;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();  // x y z r p y
  std::vector<std::string> estimated;  // names of estimated parameters, e.g. {"x", "yaw"}
  std::string method;
  std::string notes;
};
ExtrinsicsFile read_extrinsics_yaml(const std::string& path);
void write_extrinsics_yaml(const std::string& path, const ExtrinsicsFile& e);

struct StampedPose {
  double t;
  SE2 pose;
};
// TUM: "t x y z qx qy qz qw"; planar poses only (z = 0, rotation about z), else InvalidInput.
std::vector<StampedPose> read_tum(const std::string& path);
void write_tum(const std::string& path, const std::vector<StampedPose>& poses);

struct DirectionLabel {
  double t;
  int sign;  // +1, -1, 0 for the interval from the previous timestamp to t
};
std::vector<DirectionLabel> read_direction(const std::string& path);
void write_direction(const std::string& path, const std::vector<DirectionLabel>& labels);

// frames.txt: "timestamp relative/path" per line, '#' comments. The path is everything after
// the whitespace that follows the timestamp, trimmed, so it may contain inner spaces.
struct FrameEntry {
  double t;
  std::string path;  // as written in frames.txt, relative to the data set directory
  int line = 0;      // its line in frames.txt (0 when it did not come from a file), for messages
};
std::vector<FrameEntry> read_frames(const std::string& path);
void write_frames(const std::string& path, const std::vector<FrameEntry>& frames);

}  // namespace planarvo::io
