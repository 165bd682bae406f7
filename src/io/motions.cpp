#include "io/motions.h"

#include <array>
#include <cmath>
#include <fstream>
#include <map>

#include "core/error.h"
#include "io/text.h"

namespace planarvo::io {
namespace {

using detail::LineReader;

std::string trim(std::string_view s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string_view::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r");
  return std::string(s.substr(a, b - a + 1));
}

std::vector<std::string> split_commas(std::string_view line) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

const std::array<const char*, 8> kColumns = {"interval_s", "odo_dx",    "odo_dy",    "odo_dtheta",
                                             "sensor_dx",  "sensor_dy", "sensor_dtheta", "direction"};

}  // namespace

MotionPairs read_motion_pairs(const std::string& path, double still_speed) {
  // The header is the first line, a comment naming the columns.
  std::string header;
  {
    std::ifstream in(path);
    if (!in) throw_invalid_input(path + ": cannot open the motion-pair file");
    std::getline(in, header);
  }
  const std::string h = trim(header);
  if (h.empty() || h[0] != '#')
    throw_invalid_input(detail::where(path, 1) +
                        ": the first line must be a '#' header naming the columns (interval_s, odo_dx, "
                        "odo_dy, odo_dtheta, sensor_dx, sensor_dy, sensor_dtheta[, direction])");
  std::map<std::string, size_t> column;
  const auto names = split_commas(std::string_view(h).substr(1));
  for (size_t i = 0; i < names.size(); ++i) {
    bool known = false;
    for (const char* c : kColumns) known = known || names[i] == c;
    if (!known) throw_invalid_input(detail::where(path, 1) + ": unknown column '" + names[i] + "'");
    if (!column.emplace(names[i], i).second)
      throw_invalid_input(detail::where(path, 1) + ": column '" + names[i] + "' appears twice");
  }
  for (const char* c : {"interval_s", "sensor_dx", "sensor_dy", "sensor_dtheta"})
    if (!column.count(c)) throw_invalid_input(detail::where(path, 1) + ": missing column '" + c + "'");
  const int odo = static_cast<int>(column.count("odo_dx") + column.count("odo_dy") + column.count("odo_dtheta"));
  if (odo != 0 && odo != 3)
    throw_invalid_input(detail::where(path, 1) + ": odo_dx, odo_dy and odo_dtheta come together or not at all");

  MotionPairs out;
  out.has_odometry = odo == 3;
  out.has_direction_column = column.count("direction") > 0;
  out.still_speed = still_speed;
  LineReader r(path);
  std::string line;
  while (r.next(line)) {
    const auto f = split_commas(line);
    if (f.size() != names.size())
      r.fail("expected " + std::to_string(names.size()) + " comma-separated values, found " +
             std::to_string(f.size()));
    auto value = [&](const char* name) { return detail::parse_number(r, f[column.at(name)], name); };
    auto metres = [&](const char* name) {
      const double v = value(name);
      if (std::abs(v) > kMaxPositionMetres)
        r.fail(std::string(name) + " = " + detail::format_exact(v) + " m is beyond " +
               detail::format_exact(kMaxPositionMetres) + " m: a corrupt value or another unit");
      return v;
    };
    MotionPair p;
    p.interval = value("interval_s");
    if (!(p.interval > 0)) r.fail("interval_s must be positive");
    p.sensor.value = SE2(metres("sensor_dx"), metres("sensor_dy"), value("sensor_dtheta"));
    if (out.has_odometry) p.odometry = Motion{SE2(metres("odo_dx"), metres("odo_dy"), value("odo_dtheta"))};
    if (out.has_direction_column) {
      const double s = value("direction");
      if (s != 1.0 && s != -1.0 && s != 0.0) r.fail("direction must be +1, -1 or 0");
      p.direction = static_cast<int>(s);
    } else if (p.odometry) {
      const double dx = p.odometry->value.x;
      p.direction = std::abs(dx) < still_speed * p.interval ? 0 : (dx > 0 ? 1 : -1);
    }
    out.pairs.push_back(p);
  }
  if (out.pairs.empty()) throw_invalid_input(path + ": no motion pairs");
  return out;
}

void write_motion_pairs(const std::string& path, const std::vector<MotionPair>& pairs) {
  const bool odo = !pairs.empty() && pairs.front().odometry.has_value();
  const bool dir = !pairs.empty() && pairs.front().direction.has_value();
  for (const MotionPair& p : pairs)
    if (p.odometry.has_value() != odo || p.direction.has_value() != dir)
      throw_invalid_argument(path + ": every motion pair must have the same columns");
  detail::TextWriter w(path);
  w.write(std::string("# interval_s,") + (odo ? "odo_dx,odo_dy,odo_dtheta," : "") +
          "sensor_dx,sensor_dy,sensor_dtheta" + (dir ? ",direction" : "") + "\n");
  using detail::format_exact;
  for (const MotionPair& p : pairs) {
    std::string row = format_exact(p.interval) + ",";
    if (odo) {
      const SE2& m = p.odometry->value;
      row += format_exact(m.x) + "," + format_exact(m.y) + "," + format_exact(m.theta) + ",";
    }
    const SE2& m = p.sensor.value;
    row += format_exact(m.x) + "," + format_exact(m.y) + "," + format_exact(m.theta);
    if (dir) row += "," + std::to_string(*p.direction);
    w.write(row + "\n");
  }
  w.close();
}

}  // namespace planarvo::io
