// The files users already have (docs/formats.md): OpenCV calibration YAML, extrinsics
// YAML, TUM trajectories, direction labels, frames.txt (the statistics CSV is in stats.h).
// Every reader names the file, and the line where one applies ("file:line: ..."), in its
// InvalidInput errors: wrong field count, unparsable number, NaN or inf, non-increasing
// timestamps, a bad label. Text readers skip blank lines and lines starting with '#', and accept
// CRLF. Every writer throws Error(Io) naming the file when it cannot write, and
// Error(InvalidArgument) for values its reader would reject (non-finite, non-increasing times),
// so that what we write always reads back. Numbers are written locale-independently: timestamps
// with 9 decimals, everything else in the shortest form that reads back to the same double.
#pragma once
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/extrinsics.h"
#include "core/extrinsics_estimate.h"
#include "core/se2.h"
#include "core/camera.h"

namespace planarvo::io {

// image_width, image_height, camera_matrix (3x3, no skew), distortion_coefficients (1x4, 1x5,
// 4x1 or 5x1: k1 k2 p1 p2 [k3]; 8, 12 or 14 are accepted when the coefficients past k3 are all
// zero). Other keys (OpenCV's sample writes many) are ignored. Written as the sample does, with
// a 5x1 distortion vector.
// planarvo's own keys, optional: region_of_interest, rolling_shutter_readout and exposure_time
// (seconds; absent: 0, not modelled). readout_given (when not null): whether the file has
// rolling_shutter_readout (absent: 0, a global shutter, which `calibrate` may estimate instead).
CameraModel read_camera_yaml(const std::string& path, bool* readout_given = nullptr);
void write_camera_yaml(const std::string& path, const CameraModel& camera);

// extrinsics.yaml (core/extrinsics_estimate.h): x y z roll pitch yaw are required;
// T_robot_camera (checked against them to 1e-6 per entry), covariance (6x6), estimated (a
// sequence of those six names, no repeats), method and notes (strings) are optional; observable
// is not in the file (read as false). The writer writes every key, `estimated` in the names'
// order.
ExtrinsicsEstimate read_extrinsics_yaml(const std::string& path);
void write_extrinsics_yaml(const std::string& path, const ExtrinsicsEstimate& e);

struct StampedPose {
  double t;
  SE2 pose;
};
// TUM: "t x y z qx qy qz qw"; planar poses only: |z| and the normalised |qx|, |qy| at most 1e-6,
// else InvalidInput. The quaternion need not be normalised; yaw = 2 atan2(qz, qw), wrapped.
std::vector<StampedPose> read_tum(const std::string& path);
void write_tum(const std::string& path, const std::vector<StampedPose>& poses);

// direction.txt: "t s" per line, s one of +1, -1, 0 (written "1.0" or "-0" also read).
struct DirectionLabel {
  double t;
  int sign;  // +1, -1, 0 for the interval from the previous timestamp to t
};
std::vector<DirectionLabel> read_direction(const std::string& path);
void write_direction(const std::string& path, const std::vector<DirectionLabel>& labels);

// plane.txt (`track --plane-out`, the simulator's truth): "t roll pitch sigma_roll sigma_pitch"
// per line, '#' comments; radians, the body's rotation relative to the local ground plane,
// R_plane_body = Rx(roll) Ry(pitch) (docs/conventions.md). sigma 0: exact (the simulator's
// truth). The reader refuses non-finite values, negative sigma, |roll| or |pitch| over pi/2
// (another unit) and timestamps that do not increase.
struct PlaneAttitude {
  double t = 0.0;
  double roll = 0.0, pitch = 0.0;
  double sigma_roll = 0.0, sigma_pitch = 0.0;
};
std::vector<PlaneAttitude> read_plane(const std::string& path);
void write_plane(const std::string& path, const std::vector<PlaneAttitude>& attitudes);

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
