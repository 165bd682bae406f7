// The line-oriented formats of formats.h: TUM trajectories, direction labels, frames.txt.
#include <cmath>
#include <string>

#include "core/error.h"
#include "io/formats.h"
#include "io/text.h"

namespace planarvo::io {

namespace {

using detail::format_exact;
using detail::format_fixed;
using detail::LineReader;
using detail::parse_number;
using detail::split_fields;

// A planar pose's z and its quaternion's qx, qy must be zero to this tolerance (after the
// quaternion is normalised): far above the rounding of any writer, far below a real tilt.
constexpr double kPlanarTolerance = 1e-6;
constexpr int kTimestampDecimals = 9;  // nanoseconds

void check_increasing(const LineReader& r, bool has_previous, double previous, double t) {
  if (has_previous && !(t > previous))
    r.fail("timestamp " + format_exact(t) + " is not after the previous one (" +
           format_exact(previous) + "): timestamps must increase");
}

void check_writer_time(const std::string& path, size_t i, bool has_previous, double previous,
                       double t) {
  if (!std::isfinite(t))
    throw_invalid_argument(path + ": entry " + std::to_string(i) + " has a non-finite timestamp");
  if (has_previous && !(t > previous))
    throw_invalid_argument(path + ": entry " + std::to_string(i) + " has timestamp " +
                           format_exact(t) + ", not after the previous one (" +
                           format_exact(previous) + ")");
}

}  // namespace

std::vector<StampedPose> read_tum(const std::string& path) {
  LineReader r(path);
  std::vector<StampedPose> poses;
  std::string line;
  static const char* const kNames[8] = {"t", "x", "y", "z", "qx", "qy", "qz", "qw"};
  while (r.next(line)) {
    const auto f = split_fields(line);
    if (f.size() != 8)
      r.fail("expected 8 fields 't x y z qx qy qz qw', found " + std::to_string(f.size()));
    double v[8];
    for (int k = 0; k < 8; ++k) v[k] = parse_number(r, f[k], kNames[k]);
    const double t = v[0];
    check_increasing(r, !poses.empty(), poses.empty() ? 0.0 : poses.back().t, t);
    for (int k = 1; k <= 2; ++k)
      if (std::abs(v[k]) > kMaxPositionMetres)
        r.fail(std::string(kNames[k]) + " = " + format_exact(v[k]) + " m is beyond " +
               format_exact(kMaxPositionMetres) + " m: a corrupt value or another unit");
    if (std::abs(v[3]) > kPlanarTolerance)
      r.fail("z = " + format_exact(v[3]) + " is not 0: only planar poses are supported");
    const double norm = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
    if (!(norm > 1e-9)) r.fail("the quaternion (qx qy qz qw) has zero length");
    const double qx = v[4] / norm, qy = v[5] / norm, qz = v[6] / norm, qw = v[7] / norm;
    if (std::abs(qx) > kPlanarTolerance || std::abs(qy) > kPlanarTolerance)
      r.fail("the rotation is not about z only (normalised qx = " + format_exact(qx) +
             ", qy = " + format_exact(qy) + "): only planar poses are supported");
    // A rotation by yaw about z is (0, 0, sin(yaw/2), cos(yaw/2)); q and -q are the same rotation.
    poses.push_back({t, SE2(v[1], v[2], wrap_angle(2.0 * std::atan2(qz, qw)))});
  }
  return poses;
}

void write_tum(const std::string& path, const std::vector<StampedPose>& poses) {
  for (size_t i = 0; i < poses.size(); ++i) {
    check_writer_time(path, i, i > 0, i > 0 ? poses[i - 1].t : 0.0, poses[i].t);
    const SE2& p = poses[i].pose;
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.theta))
      throw_invalid_argument(path + ": pose " + std::to_string(i) + " is not finite");
  }
  detail::TextWriter w(path);
  w.write("# timestamp x y z qx qy qz qw\n");
  std::string line;
  for (const StampedPose& s : poses) {
    const double half = 0.5 * s.pose.theta;
    line = format_fixed(s.t, kTimestampDecimals);
    line += ' ' + format_exact(s.pose.x) + ' ' + format_exact(s.pose.y) + " 0 0 0 " +
            format_exact(std::sin(half)) + ' ' + format_exact(std::cos(half)) + '\n';
    w.write(line);
  }
  w.close();
}

std::vector<DirectionLabel> read_direction(const std::string& path) {
  LineReader r(path);
  std::vector<DirectionLabel> labels;
  std::string line;
  while (r.next(line)) {
    const auto f = split_fields(line);
    if (f.size() != 2) r.fail("expected 2 fields 't s', found " + std::to_string(f.size()));
    const double t = parse_number(r, f[0], "timestamp");
    const double s = parse_number(r, f[1], "direction label");
    check_increasing(r, !labels.empty(), labels.empty() ? 0.0 : labels.back().t, t);
    if (s != 1.0 && s != -1.0 && s != 0.0)
      r.fail("direction label '" + std::string(f[1]) + "' is not one of +1, -1, 0");
    labels.push_back({t, static_cast<int>(s)});
  }
  return labels;
}

void write_direction(const std::string& path, const std::vector<DirectionLabel>& labels) {
  for (size_t i = 0; i < labels.size(); ++i) {
    check_writer_time(path, i, i > 0, i > 0 ? labels[i - 1].t : 0.0, labels[i].t);
    if (labels[i].sign < -1 || labels[i].sign > 1)
      throw_invalid_argument(path + ": label " + std::to_string(i) + " is " +
                             std::to_string(labels[i].sign) + ", not one of +1, -1, 0");
  }
  detail::TextWriter w(path);
  w.write("# timestamp direction (+1 forwards, -1 backwards, 0 no linear motion) of the interval "
          "from the previous timestamp\n");
  for (const DirectionLabel& l : labels)
    w.write(format_fixed(l.t, kTimestampDecimals) + (l.sign > 0 ? " +1\n" : l.sign < 0 ? " -1\n" : " 0\n"));
  w.close();
}

std::vector<PlaneAttitude> read_plane(const std::string& path) {
  LineReader r(path);
  std::vector<PlaneAttitude> out;
  std::string line;
  static const char* const kNames[5] = {"timestamp", "roll", "pitch", "sigma_roll", "sigma_pitch"};
  while (r.next(line)) {
    const auto f = split_fields(line);
    if (f.size() != 5)
      r.fail("expected 5 fields 't roll pitch sigma_roll sigma_pitch', found " + std::to_string(f.size()));
    double v[5];
    for (int k = 0; k < 5; ++k) v[k] = parse_number(r, f[static_cast<size_t>(k)], kNames[k]);
    check_increasing(r, !out.empty(), out.empty() ? 0.0 : out.back().t, v[0]);
    for (int k = 1; k <= 2; ++k)
      if (std::abs(v[k]) > 0.5 * M_PI)
        r.fail(std::string(kNames[k]) + " = " + format_exact(v[k]) +
               " is beyond pi/2: angles are radians (degrees by mistake?)");
    for (int k = 3; k <= 4; ++k)
      if (!(v[k] >= 0)) r.fail(std::string(kNames[k]) + " = " + format_exact(v[k]) + " is negative");
    out.push_back({v[0], v[1], v[2], v[3], v[4]});
  }
  return out;
}

void write_plane(const std::string& path, const std::vector<PlaneAttitude>& attitudes) {
  for (size_t i = 0; i < attitudes.size(); ++i) {
    const PlaneAttitude& a = attitudes[i];
    check_writer_time(path, i, i > 0, i > 0 ? attitudes[i - 1].t : 0.0, a.t);
    if (!std::isfinite(a.roll + a.pitch + a.sigma_roll + a.sigma_pitch) || a.sigma_roll < 0 || a.sigma_pitch < 0)
      throw_invalid_argument(path + ": entry " + std::to_string(i) +
                             " has a non-finite angle or a negative or non-finite sigma");
  }
  detail::TextWriter w(path);
  w.write("# timestamp roll pitch sigma_roll sigma_pitch: the body's rotation relative to the local ground "
          "plane, R_plane_body = Rx(roll) Ry(pitch), radians\n");
  for (const PlaneAttitude& a : attitudes)
    w.write(format_fixed(a.t, kTimestampDecimals) + " " + format_exact(a.roll) + " " + format_exact(a.pitch) + " " +
            format_exact(a.sigma_roll) + " " + format_exact(a.sigma_pitch) + "\n");
  w.close();
}

std::vector<FrameEntry> read_frames(const std::string& path) {
  LineReader r(path);
  std::vector<FrameEntry> frames;
  std::string line;
  while (r.next(line)) {
    // The line is trimmed; the path is what follows the first run of blanks after the timestamp.
    const size_t end_t = line.find_first_of(" \t");
    const size_t start_path = end_t == std::string::npos ? end_t : line.find_first_not_of(" \t", end_t);
    if (start_path == std::string::npos) r.fail("expected 'timestamp path', found one field");
    const double t = parse_number(r, std::string_view(line).substr(0, end_t), "timestamp");
    check_increasing(r, !frames.empty(), frames.empty() ? 0.0 : frames.back().t, t);
    frames.push_back({t, line.substr(start_path), r.line_number()});
  }
  return frames;
}

void write_frames(const std::string& path, const std::vector<FrameEntry>& frames) {
  for (size_t i = 0; i < frames.size(); ++i) {
    check_writer_time(path, i, i > 0, i > 0 ? frames[i - 1].t : 0.0, frames[i].t);
    const std::string& p = frames[i].path;
    // What read_frames could not give back unchanged.
    if (p.empty() || p.find_first_of("\n\r") != std::string::npos ||
        p.front() == ' ' || p.front() == '\t' || p.back() == ' ' || p.back() == '\t')
      throw_invalid_argument(path + ": frame " + std::to_string(i) + " has path '" + p +
                             "', which is empty or has leading/trailing blanks or a line break");
  }
  detail::TextWriter w(path);
  w.write("# timestamp path (relative to this directory)\n");
  for (const FrameEntry& f : frames) w.write(format_fixed(f.t, kTimestampDecimals) + ' ' + f.path + '\n');
  w.close();
}

}  // namespace planarvo::io
