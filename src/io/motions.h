// Motion pairs for calibration without images (docs/formats.md, "Motion-pair CSV"): per interval,
// the robot's motion from wheel odometry (optional) and the sensor's own motion, in the robot
// frame and the sensor frame at the interval's start, plus an optional direction label.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "core/motion.h"

namespace planarvo::io {

// The file has no covariance columns: the motions' covariances are zero (not given) when read,
// and not written.
struct MotionPair {
  double interval = 0;               // seconds
  std::optional<Motion> odometry;    // robot motion from wheel odometry, when the file has it
  Motion sensor;                     // the sensor's motion in its own frame
  std::optional<int> direction;      // +1 / -1 / 0: the file's column, else the odometry's sign
};

struct MotionPairs {
  std::vector<MotionPair> pairs;
  bool has_odometry = false;
  bool has_direction_column = false;
  // Linear speed (m/s) under which odometry counts as "no linear motion" (label 0) when the
  // labels come from the odometry's sign.
  double still_speed = 0.0;
};

// Reads the comma-separated file whose '#' header line names the columns: interval_s, odo_dx,
// odo_dy, odo_dtheta (all three or none), sensor_dx, sensor_dy, sensor_dtheta, and optionally
// direction, in any order. Without a direction column, odometry's forward motion gives the label:
// +1 / -1 by the sign of odo_dx, 0 when |odo_dx| / interval_s < still_speed. Every error is
// InvalidInput naming the file and the line.
MotionPairs read_motion_pairs(const std::string& path, double still_speed = 1e-3);

void write_motion_pairs(const std::string& path, const std::vector<MotionPair>& pairs);

}  // namespace planarvo::io
