#include "io/text.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <system_error>

#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"

namespace planarvo::io::detail {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string where(const std::string& path, int line) {
  return path + ":" + std::to_string(line);
}

std::string input_file_problem(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ENOENT || err == ENOTDIR) return "does not exist";
    return "cannot be read (" + std::generic_category().message(err) + ")";
  }
  if (S_ISDIR(st.st_mode)) return "is a directory, not a file";
  if (S_ISFIFO(st.st_mode)) return "is a named pipe (FIFO), not a regular file";
  if (S_ISSOCK(st.st_mode)) return "is a socket, not a regular file";
  if (!S_ISREG(st.st_mode)) return "is a device, not a regular file";
  if (::access(path.c_str(), R_OK) != 0) {
    const int err = errno;
    return "cannot be read (" + std::generic_category().message(err) + ")";
  }
  return std::string();
}

void check_input_file(const std::string& path, const std::string& context) {
  const std::string problem = input_file_problem(path);
  if (!problem.empty()) throw_invalid_input(path + ": " + problem + (context.empty() ? "" : " (" + context + ")"));
}

LineReader::LineReader(std::string path) : path_(std::move(path)) {
  check_input_file(path_);
  in_.open(path_, std::ios::binary);
  if (!in_) {
    const int err = errno;
    throw_invalid_input(path_ + ": cannot open (" + std::generic_category().message(err) + ")");
  }
}

bool LineReader::next(std::string& line) {
  std::string raw;
  while (std::getline(in_, raw)) {
    ++line_number_;
    const std::string_view t = trim(raw);
    if (t.empty() || t.front() == '#') continue;
    line.assign(t.data(), t.size());
    return true;
  }
  if (in_.bad()) throw_invalid_input(path_ + ": read error after line " + std::to_string(line_number_));
  return false;
}

void LineReader::fail(const std::string& message) const {
  throw_invalid_input(where(path_, line_number_) + ": " + message);
}

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

double parse_number(const LineReader& reader, std::string_view field, const char* what) {
  std::string_view s = field;
  // from_chars does not take a leading '+', which people write for direction labels.
  if (s.size() > 1 && s.front() == '+' && s[1] != '-' && s[1] != '+') s.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size())
    reader.fail(std::string(what) + " '" + std::string(field) + "' is not a number");
  if (!std::isfinite(v))
    reader.fail(std::string(what) + " '" + std::string(field) + "' is not finite (NaN or inf)");
  return v;
}

std::string format_exact(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string format_fixed(double v, int decimals) {
  char buf[512];  // fixed notation of a large double is long; timestamps are far below 1e300
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals);
  if (r.ec != std::errc()) return format_exact(v);
  return std::string(buf, r.ptr);
}

TextWriter::TextWriter(std::string path) : file_(std::move(path)) {}

TextWriter::~TextWriter() = default;

void TextWriter::write(std::string_view text) {
  if (!file_.is_open()) throw Error(ErrorCode::Internal, path() + ": written after it was closed");
  if (std::fwrite(text.data(), 1, text.size(), file_.stream()) != text.size()) fail("write failed");
}

void TextWriter::flush() {
  if (!file_.is_open()) throw Error(ErrorCode::Internal, path() + ": flushed after it was closed");
  if (std::fflush(file_.stream()) != 0) fail("write failed");
}

void TextWriter::close() {
  if (!file_.is_open()) return;
  file_.commit();
}

void TextWriter::fail(const char* what) const {
  const int err = errno;
  throw Error(ErrorCode::Io,
              path() + ": " + what + " (" + std::generic_category().message(err) + ")");
}

}  // namespace planarvo::io::detail
