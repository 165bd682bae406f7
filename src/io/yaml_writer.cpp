// YAML as cv::FileStorage writes it (yaml_writer.h).
#include "io/yaml_writer.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/error.h"
#include "io/text.h"

namespace planarvo::io {

namespace {

constexpr int kIndent = 3;         // CV_YML_INDENT
constexpr size_t kWrapColumn = 71;  // FileStorage's wrap margin for flow collections
constexpr size_t kMaxString = 4096;  // CV_FS_MAX_LEN: OpenCV refuses longer strings

bool is_alnum(char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
// OpenCV's cv_isprint: every byte from ' ' up, the UTF-8 bytes of other scripts included.
bool is_print(char c) { return static_cast<unsigned char>(c) >= static_cast<unsigned char>(' '); }

void check_string(const std::string& s, const std::string& what) {
  if (s.size() > kMaxString)
    throw_invalid_argument(what + " is " + std::to_string(s.size()) + " bytes long; at most " +
                           std::to_string(kMaxString) + " can be written");
  if (s.find('\0') != std::string::npos) throw_invalid_argument(what + " holds a NUL byte");
}

}  // namespace

std::string format_real(double v) {
  // fs::doubleToString: cvRound(v) == v prints "%d.", so integral values in int's range.
  if (std::isfinite(v) && v == std::trunc(v) && v >= std::numeric_limits<int>::min() &&
      v <= std::numeric_limits<int>::max())
    return std::to_string(static_cast<int>(v)) + ".";
  if (std::isnan(v)) return ".Nan";
  if (std::isinf(v)) return v < 0 ? "-.Inf" : ".Inf";
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific, 16);
  return std::string(buf, r.ptr);
}

std::string quote_string(const std::string& s) {
  // A string that starts and ends with the same quote character is written as it is.
  if (!s.empty() && s.front() == s.back() && (s.front() == '"' || s.front() == '\'')) return s;
  bool need_quote = s.empty() || s.front() == ' ';
  std::string body;
  for (const char c : s) {
    if (!need_quote && !is_alnum(c) && c != '_' && c != ' ' && c != '-' && c != '(' && c != ')' &&
        c != '/' && c != '+' && c != ';')
      need_quote = true;
    if (!is_alnum(c) && (!is_print(c) || c == '\\' || c == '\'' || c == '"')) {
      body += '\\';
      if (is_print(c)) {
        body += c;
      } else if (c == '\n') {
        body += 'n';
      } else if (c == '\r') {
        body += 'r';
      } else if (c == '\t') {
        body += 't';
      } else {
        char hex[8];
        std::snprintf(hex, sizeof hex, "x%02x", static_cast<unsigned>(static_cast<unsigned char>(c)));
        body += hex;
      }
    } else {
      body += c;
    }
  }
  if (!need_quote && (is_digit(s.front()) || s.front() == '+' || s.front() == '-' || s.front() == '.'))
    need_quote = true;
  return need_quote ? '"' + body + '"' : body;
}

YamlWriter::YamlWriter() : text_("%YAML:1.0\n---\n") { levels_.push_back({0, true, false, true}); }

void YamlWriter::flush() {
  if (line_.size() > line_indent_) text_ += line_ + '\n';
  line_indent_ = static_cast<size_t>(levels_.back().indent);
  line_.assign(line_indent_, ' ');
}

void YamlWriter::scalar(const char* key, const char* data) {
  Level& level = levels_.back();
  const std::string key_text = key ? key : "";
  const std::string data_text = data ? data : "";
  if (level.flow) {
    if (!level.empty) line_ += ',';
    const size_t end = line_.size() + key_text.size() + data_text.size();
    if (end > kWrapColumn && end - static_cast<size_t>(level.indent) > 10) {
      flush();
    } else {
      line_ += ' ';
    }
  } else {
    flush();
    if (!level.map) line_ += data ? "- " : "-";
  }
  if (key) {
    line_ += key_text + ':';
    if (!level.flow && data) line_ += ' ';
  }
  line_ += data_text;
  level.empty = false;
}

void YamlWriter::begin(const char* key, bool map, bool flow, const char* tag) {
  std::string opening;
  if (flow) opening = map ? "{" : "[";
  if (tag) opening += (opening.empty() ? "" : " ") + std::string("!!") + tag;
  scalar(key, opening.empty() ? nullptr : opening.c_str());
  const Level& parent = levels_.back();
  const int indent = parent.flow ? parent.indent : parent.indent + kIndent + (flow ? 1 : 0);
  levels_.push_back({indent, map, flow, true});
}

void YamlWriter::end() {
  const Level level = levels_.back();
  if (level.flow) {
    if (line_.size() > static_cast<size_t>(level.indent) && !level.empty) line_ += ' ';
    line_ += level.map ? '}' : ']';
  } else if (level.empty) {
    flush();
    line_ += level.map ? "{}" : "[]";
  }
  levels_.pop_back();
}

void YamlWriter::write(const char* key, int value) { scalar(key, std::to_string(value).c_str()); }

void YamlWriter::write(const char* key, double value) { scalar(key, format_real(value).c_str()); }

void YamlWriter::write(const char* key, const std::string& value, const std::string& what) {
  check_string(value, what);
  scalar(key, quote_string(value).c_str());
}

void YamlWriter::write_matrix(const char* key, int rows, int cols, const double* data) {
  begin(key, true, false, "opencv-matrix");
  write("rows", rows);
  write("cols", cols);
  scalar("dt", "d");
  begin("data", false, true, nullptr);
  for (int i = 0; i < rows * cols; ++i) scalar(nullptr, format_real(data[i]).c_str());
  end();
  end();
}

void YamlWriter::write_flow(const char* key, const std::vector<int>& values) {
  begin(key, false, true, nullptr);
  for (const int v : values) scalar(nullptr, std::to_string(v).c_str());
  end();
}

void YamlWriter::write_flow(const char* key, const std::vector<double>& values) {
  begin(key, false, true, nullptr);
  for (const double v : values) scalar(nullptr, format_real(v).c_str());
  end();
}

void YamlWriter::write_block(const char* key, const std::vector<std::string>& values, const std::string& what) {
  begin(key, false, false, nullptr);
  for (const std::string& v : values) {
    check_string(v, what);
    scalar(nullptr, quote_string(v).c_str());
  }
  end();
}

std::string YamlWriter::finish() {
  flush();
  return std::move(text_);
}

void YamlWriter::save(const std::string& path) {
  detail::TextWriter w(path);
  w.write(finish());
  w.close();
}

}  // namespace planarvo::io
