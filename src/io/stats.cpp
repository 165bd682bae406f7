#include "io/stats.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"

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

// The header of files written before the local plane: the first nine columns.
constexpr std::string_view kHeaderWithoutAttitude =
    "timestamp,vx,vy,omega,iterations,final_cost,inlier_fraction,ms,status";
constexpr size_t kColumnsWithoutAttitude = 9, kColumns = 14;

struct Record {
  std::vector<std::string> fields;
  int line = 0;  // the line the record starts on
};

// RFC 4180 records: fields separated by commas, a quoted field may hold commas, doubled quotes
// and line breaks; CRLF line ends accepted. Empty lines give no record.
std::vector<Record> csv_records(const std::string& path, const std::string& text) {
  std::vector<Record> out;
  Record r;
  std::string field;
  bool quoted = false, in_record = false;
  int line = 1;
  r.line = 1;
  auto end_record = [&] {
    if (in_record) {
      r.fields.push_back(field);
      out.push_back(std::move(r));
    }
    r = Record();
    field.clear();
    in_record = false;
  };
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        if (c == '\n') ++line;
        field += c;
      }
      continue;
    }
    if (!in_record) r.line = line;
    if (c == '\n' || (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n')) {
      if (c == '\r') ++i;
      end_record();
      ++line;
    } else if (c == ',') {
      r.fields.push_back(field);
      field.clear();
      in_record = true;
    } else if (c == '"' && field.empty()) {
      quoted = true;
      in_record = true;
    } else {
      field += c;
      in_record = true;
    }
  }
  if (quoted) throw_invalid_input(detail::where(path, r.line) + ": a quoted field is not closed");
  end_record();
  return out;
}

double parse_double(const std::string& path, int line, const std::string& text, const char* column) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, v);
  if (text.empty() || r.ec != std::errc() || r.ptr != end)
    throw_invalid_input(detail::where(path, line) + ": " + column + " '" + text + "' is not a number");
  return v;
}

FrameStats parse_row(const std::string& path, const Record& rec, size_t columns) {
  static const char* const kNames[kColumns] = {"timestamp", "vx",   "vy",    "omega",      "iterations",
                                               "final_cost", "inlier_fraction", "ms", "status", "roll",
                                               "pitch",      "sigma_roll",      "sigma_pitch", "mounting_changed"};
  const auto& f = rec.fields;
  if (f.size() != columns)
    throw_invalid_input(detail::where(path, rec.line) + ": expected " + std::to_string(columns) + " fields, found " +
                        std::to_string(f.size()));
  auto number = [&](size_t k) { return parse_double(path, rec.line, f[k], kNames[k]); };
  FrameStats r;
  r.timestamp = number(0);
  if (!std::isfinite(r.timestamp))
    throw_invalid_input(detail::where(path, rec.line) + ": the timestamp is not finite");
  r.vx = number(1);
  r.vy = number(2);
  r.omega = number(3);
  const double iterations = number(4);
  if (!(iterations >= 0 && iterations <= 1e9 && iterations == std::trunc(iterations)))
    throw_invalid_input(detail::where(path, rec.line) + ": iterations '" + f[4] + "' is not a count");
  r.iterations = static_cast<int>(iterations);
  r.final_cost = number(5);
  r.inlier_fraction = number(6);
  r.ms = number(7);
  r.status = f[8];
  if (columns == kColumns) {
    size_t empty = 0;
    for (size_t k = 9; k < kColumns; ++k) empty += f[k].empty();
    if (empty != 0 && empty != kColumns - 9)
      throw_invalid_input(detail::where(path, rec.line) + ": the attitude fields are partly empty");
    r.has_attitude = empty == 0;
    if (r.has_attitude) {
      r.roll = number(9);
      r.pitch = number(10);
      r.sigma_roll = number(11);
      r.sigma_pitch = number(12);
      if (f[13] != "0" && f[13] != "1")
        throw_invalid_input(detail::where(path, rec.line) + ": mounting_changed '" + f[13] + "' is not 0 or 1");
      r.mounting_changed = f[13] == "1";
    }
  }
  return r;
}

}  // namespace

std::vector<FrameStats> read_stats(const std::string& path) {
  detail::check_input_file(path, "the statistics CSV");
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) throw_invalid_input(path + ": cannot be read");
  const std::vector<Record> records = csv_records(path, text.str());
  if (records.empty()) throw_invalid_input(path + ": empty, not a statistics CSV");
  std::string header;
  for (size_t k = 0; k < records[0].fields.size(); ++k) header += (k ? "," : "") + records[0].fields[k];
  size_t columns = 0;
  if (header == StatsWriter::kHeader) columns = kColumns;
  if (header == kHeaderWithoutAttitude) columns = kColumnsWithoutAttitude;
  if (columns == 0)
    throw_invalid_input(detail::where(path, records[0].line) + ": the first line is not the statistics header " +
                        StatsWriter::kHeader);
  std::vector<FrameStats> out;
  for (size_t i = 1; i < records.size(); ++i) out.push_back(parse_row(path, records[i], columns));
  if (out.empty()) throw_invalid_input(path + ": has the header but no row");
  return out;
}

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
