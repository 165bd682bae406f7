// The per-frame statistics CSV (docs/formats.md, --stats FILE): one row per frame, written
// and flushed as the frames are processed into FILE.partial-<random>, renamed onto FILE by
// close() (core/output_file.h): FILE is complete or untouched; a crash leaves the rows in the
// temporary.
#pragma once
#include <string>
#include <vector>

#include "io/text.h"

namespace planarvo::io {

struct FrameStats {
  double timestamp = 0.0;  // the frame's time, seconds
  double vx = 0.0, vy = 0.0;  // robot-frame velocity over the interval ending at this frame, m/s
  double omega = 0.0;         // angular velocity, rad/s
  int iterations = 0;         // tracker iterations, all pyramid levels
  double final_cost = 0.0;
  double inlier_fraction = 0.0;
  double ms = 0.0;     // engine time for the frame (upload, undistortion, pyramid, tracking)
  std::string status;  // e.g. "ok", "first", "lost"; quoted in the file when it needs to be
  // With the local plane: the body's attitude relative to the local ground plane (radians,
  // R_plane_body = Rx(roll) Ry(pitch)) with its standard deviations, and whether this frame found
  // the camera's mounting changed. Empty fields without it (has_attitude false).
  bool has_attitude = false;
  double roll = 0.0, pitch = 0.0, sigma_roll = 0.0, sigma_pitch = 0.0;
  bool mounting_changed = false;
};

// Writes the header at construction and one flushed row per add(). Every failure is Error(Io)
// naming the file. Neither copyable nor movable (hold it by pointer to pass it on).
class StatsWriter {
 public:
  static constexpr const char* kHeader =
      "timestamp,vx,vy,omega,iterations,final_cost,inlier_fraction,ms,status,roll,pitch,sigma_roll,sigma_pitch,"
      "mounting_changed";

  explicit StatsWriter(const std::string& path);
  void add(const FrameStats& row);
  // Completes the file, reporting a failed final write. Destroyed without close(), the writer
  // removes its partial file and leaves FILE as it was.
  void close();
  const std::string& path() const { return out_.path(); }
  const std::string& temporary_path() const { return out_.temporary_path(); }  // until close()

 private:
  detail::TextWriter out_;
};

// Reads a statistics CSV back: the header StatsWriter writes, or the first nine columns of it
// (files written before the local plane); every row with as many fields as the header; the
// timestamp finite, iterations an integer, the other numbers any double (nan and inf are written
// for a lost frame's figures); the five attitude fields all empty (has_attitude false) or all
// given, mounting_changed 0 or 1; status as written (RFC 4180 quoting). Empty lines are skipped.
// InvalidInput "path:line: ..." otherwise, and for a file with no row.
std::vector<FrameStats> read_stats(const std::string& path);

}  // namespace planarvo::io
