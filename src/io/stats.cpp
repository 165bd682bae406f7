#include "io/stats.h"

#include <string>

namespace planarvo::io {

namespace {

// RFC 4180: a field with a comma, quote or line break is quoted, quotes doubled.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + '"';
}

}  // namespace

StatsWriter::StatsWriter(const std::string& path) : out_(path) {
  out_.write(std::string(kHeader) + '\n');
  out_.flush();
}

void StatsWriter::add(const FrameStats& r) {
  using detail::format_exact;
  // Non-finite values (a failed frame's cost) are written as nan/inf, which CSV readers accept.
  std::string line = detail::format_fixed(r.timestamp, 9);
  for (double v : {r.vx, r.vy, r.omega}) line += ',' + format_exact(v);
  line += ',' + std::to_string(r.iterations);
  for (double v : {r.final_cost, r.inlier_fraction, r.ms}) line += ',' + format_exact(v);
  line += ',' + csv_field(r.status);
  if (r.has_attitude) {
    for (double v : {r.roll, r.pitch, r.sigma_roll, r.sigma_pitch}) line += ',' + format_exact(v);
    line += r.mounting_changed ? ",1" : ",0";
  } else {
    line += ",,,,,";
  }
  line += '\n';
  out_.write(line);
  out_.flush();
}

void StatsWriter::close() { out_.close(); }

}  // namespace planarvo::io
