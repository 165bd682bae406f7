// Reading the OpenCV FileStorage YAML formats of formats.h, the camera calibration and the
// extrinsics (docs/formats.md), with cv::FileStorage, so that a file reads as OpenCV reads it.
// Their writers, which need no OpenCV, are in io/formats_yaml.cpp.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "core/error.h"
#include "io/formats.h"
#include "io/text.h"

namespace planarvo::io {

namespace {


// A T_robot_camera that differs from the matrix of the six values by more than this (in any
// entry: metres, or rotation-matrix units ~ radians) is an error: well above the ~1e-16 rounding
// of the written numbers, well below any real disagreement.
constexpr double kMatrixAgreement = 1e-6;

[[noreturn]] void fail(const std::string& path, const std::string& message) {
  throw_invalid_input(path + ": " + message);
}

// Limits checked before OpenCV's parser sees a file. Its YAML parser recurses once per level of
// nesting (flow brackets, block indentation, inline "- - -" sequences) and overflows the stack at a
// few ten thousand levels (a crash, found by fuzzing); our files nest 2 or 3 levels deep. The size
// limit is far above any camera or extrinsics file, OpenCV's calibration sample's extra keys
// (per-view extrinsics, image points) included.
constexpr int kMaxYamlNesting = 128;
constexpr std::uintmax_t kMaxYamlBytes = 16u << 20;

// The nesting a YAML line can reach: its indentation, its leading "- " sequence entries, and the
// open flow collections ('[' '{' outside quotes and comments; flow_depth carries over lines).
int line_nesting(std::string_view line, int& flow_depth) {
  size_t i = 0;
  while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
  int depth = static_cast<int>(std::min<size_t>(i, kMaxYamlNesting + 1));
  while (i < line.size() && line[i] == '-' &&
         (i + 1 == line.size() || line[i + 1] == ' ' || line[i + 1] == '\t')) {
    ++depth;
    i += 2;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
  }
  int deepest = flow_depth;
  char quote = 0;
  for (; i < line.size(); ++i) {
    const char c = line[i];
    if (quote) {
      if (c == '\\' && quote == '"') ++i;
      else if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t')) {
      break;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++flow_depth);
    } else if ((c == ']' || c == '}') && flow_depth > 0) {
      --flow_depth;
    }
  }
  return depth + deepest;
}

// A document marker ("---" or "...") followed by more than blanks or a comment. OpenCV's parser
// loops forever on a key after "---" followed by another key ("---a : 1\ny: 2"), and on text after
// "..." ("x: 1\n...-"), both found by fuzzing; our files have "---" alone.
bool has_content_after_document_marker(std::string_view line) {
  if (line.substr(0, 3) != "---" && line.substr(0, 3) != "...") return false;
  const size_t next = line.find_first_not_of(" \t\r", 3);
  return next != std::string_view::npos && line[next] != '#';
}

// A block sequence entry ('-' first on a line outside brackets, a "---" marker aside).
enum class DashEntry { None, Value, Bare, Glued };
DashEntry dash_entry(std::string_view line, int flow_depth) {
  if (flow_depth > 0) return DashEntry::None;  // in brackets a line may start with a negative number
  const size_t first = line.find_first_not_of(" \t");
  if (first == std::string_view::npos || line[first] != '-') return DashEntry::None;
  if (first == 0 && line.substr(0, 3) == "---") return DashEntry::None;
  if (first + 1 < line.size() && line[first + 1] != ' ' && line[first + 1] != '\t' &&
      line[first + 1] != '\r')
    return DashEntry::Glued;
  return line.find_first_not_of(" \t\r", first + 1) == std::string_view::npos ? DashEntry::Bare
                                                                               : DashEntry::Value;
}

// The indentation of a content line outside brackets (not a directive, marker or comment), or
// npos.
size_t block_indent(std::string_view line, int flow_depth) {
  if (flow_depth > 0 || line.empty() || line[0] == '%' || line.substr(0, 3) == "---" ||
      line.substr(0, 3) == "...")
    return std::string_view::npos;
  const size_t indent = line.find_first_not_of(" \t");
  if (indent == std::string_view::npos || line[indent] == '#' || line[indent] == '\r')
    return std::string_view::npos;
  return indent;
}

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// A value's tag, if it has one, must be one of OpenCV's: "!!name" ("!!opencv-matrix").
bool is_opencv_tag_or_untagged(std::string_view value) {
  if (value.empty() || value[0] != '!') return true;
  size_t i = 2;
  if (value.size() < 3 || value[1] != '!') return false;
  while (i < value.size() && (std::isalnum(static_cast<unsigned char>(value[i])) || value[i] == '-' ||
                              value[i] == '_'))
    ++i;
  return i > 2 && (i == value.size() || is_blank(value[i]) || value[i] == '#');
}

// What may follow a block line's indentation and '- ' entries, as OpenCV writes and reads it:
// "name: value" or "name:" (name: a letter or '_', then letters, digits, '_', '-'; OpenCV's writer
// allows no other keys), a bracketed, quoted or tagged value under its key, and in a sequence
// entry any value. Tags only as OpenCV's. The
// parser loops forever on a tagged key line ("!f x:1" then "y: -"; found by fuzzing
// extrinsics.yaml). Returns the problem, or empty.
std::string block_content_problem(std::string_view rest, bool sequence_entry) {
  while (!rest.empty() && is_blank(rest.back())) rest.remove_suffix(1);
  if (rest.empty() || rest[0] == '#') return {};
  size_t i = 0;
  if (std::isalpha(static_cast<unsigned char>(rest[0])) || rest[0] == '_') {
    while (i < rest.size() && (std::isalnum(static_cast<unsigned char>(rest[i])) || rest[i] == '_' ||
                               rest[i] == '-'))
      ++i;
    size_t colon = i;
    while (colon < rest.size() && (rest[colon] == ' ' || rest[colon] == '\t')) ++colon;
    if (colon < rest.size() && rest[colon] == ':') {
      std::string_view value = rest.substr(colon + 1);
      while (!value.empty() && is_blank(value.front())) value.remove_prefix(1);
      return is_opencv_tag_or_untagged(value) ? std::string()
                                              : "a tag other than OpenCV's '!!name' is not supported";
    }
  }
  // A value on the lines after its key ("estimated:" then "   []", as OpenCV writes an empty
  // sequence): brackets, quotes or a tag; any value in a sequence entry.
  const char c = rest[0];
  if (!sequence_entry && c != '[' && c != '{' && c != '"' && c != '\'' && c != '!')
    return "expected 'name: value' (a name of letters, digits, '_' and '-')";
  return is_opencv_tag_or_untagged(rest) ? std::string()
                                         : "a tag other than OpenCV's '!!name' is not supported";
}

// The block structure OpenCV's parser loops forever on (hangs found by fuzzing both YAML
// readers), checked line by line:
// - a '-' entry glued to its value ("   -x" then "--x-");
// - a bare '-' (OpenCV writes one before a nested map or sequence) whose next line is not
//   indented deeper ("   - x" then "-" at the end);
// - a line indented less than the lines it belongs to but not as much as any line above it
//   (" x: 1" then "y: -1"), which YAML does not allow either;
// - what block_content_problem refuses.
class BlockShape {
 public:
  // The message for a line that breaks a rule, empty if none; line numbers from 1.
  std::string check(std::string_view line, int number, int flow_depth) {
    const DashEntry dash = dash_entry(line, flow_depth);
    if (dash == DashEntry::Glued) return "a '-' sequence entry must be '- value'";
    const size_t indent = block_indent(line, flow_depth);
    if (indent == std::string_view::npos) return {};
    if (bare_line_ > 0 && indent <= bare_indent_) return bare_dash_message();
    bare_line_ = dash == DashEntry::Bare ? number : 0;
    bare_indent_ = indent;
    size_t p = indent;  // past the '- ' entries
    bool entry = false;
    while (p < line.size() && line[p] == '-' && (p + 1 == line.size() || is_blank(line[p + 1]))) {
      entry = true;
      ++p;
      while (p < line.size() && (line[p] == ' ' || line[p] == '\t')) ++p;
    }
    std::string problem = block_content_problem(line.substr(p), entry);
    if (!problem.empty()) return problem;
    if (levels_.empty() || indent > levels_.back()) {
      levels_.push_back(indent);
      return {};
    }
    while (!levels_.empty() && levels_.back() > indent) levels_.pop_back();
    if (levels_.empty() || levels_.back() != indent)
      return "indented less than the lines it belongs to, but not as much as any line above it";
    return {};
  }
  // At the end of the file: the line of a bare '-' with nothing under it (else 0).
  int dangling_bare_dash() const { return bare_line_; }
  static std::string bare_dash_message() {
    return "a bare '-' sequence entry must have its value on the lines below, indented deeper";
  }

 private:
  std::vector<size_t> levels_;  // the open block indentations
  int bare_line_ = 0;           // a bare '-' waiting for its value, and its indentation
  size_t bare_indent_ = 0;
};

// A directive line: only OpenCV's "%YAML:1.x" (or "%YAML 1.x"), on the first line. OpenCV reads
// the rest of a longer first line as part of the document ("%YAML:1.[" opened a bracket that
// hid every following line from the checks; found by fuzzing camera.yaml).
bool is_yaml_directive(std::string_view line) {
  if (line.size() < 9 || line.substr(0, 5) != "%YAML" || (line[5] != ':' && line[5] != ' ') ||
      line.substr(6, 2) != "1.")
    return false;
  size_t i = 8;
  while (i < line.size() && std::isdigit(static_cast<unsigned char>(line[i]))) ++i;
  while (i < line.size() && is_blank(line[i])) ++i;
  return i == line.size() || line[i] == '#';
}

// Brackets as OpenCV writes them ("[ 1., 2. ]", "{ a: 1 }", "[]"), followed over lines: each
// closes the kind it opened, none is left open at a document marker or the end of the file, an
// entry inside them is not a bare '-', and a key inside braces is not empty ("{:" looped
// OpenCV's parser forever with a bare '-' after it; found by fuzzing extrinsics.yaml).
class FlowShape {
 public:
  std::string check(std::string_view line) {
    if (!open_.empty() && (line.substr(0, 3) == "---" || line.substr(0, 3) == "..."))
      return "a '" + std::string(1, open_.back()) + "' is not closed before the document marker";
    char quote = 0;
    for (size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quote) {
        if (c == '\\' && quote == '"') ++i;
        else if (c == quote) quote = 0;
        continue;
      }
      if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '#' && (i == 0 || is_blank(line[i - 1]))) {
        break;
      } else if (c == '[' || c == '{') {
        open_.push_back(c);
        item_start_ = true;
        continue;
      } else if (c == ']' || c == '}') {
        if (open_.empty()) return std::string("a '") + c + "' closes nothing";
        if ((c == ']') != (open_.back() == '['))
          return std::string("a '") + c + "' closes a '" + open_.back() + "'";
        open_.pop_back();
      } else if (!open_.empty() && item_start_ && c == ':' && open_.back() == '{') {
        return "an empty key inside braces";
      } else if (!open_.empty() && item_start_ && c == '-' &&
                 (i + 1 == line.size() || is_blank(line[i + 1]))) {
        return "a '-' entry inside brackets";
      }
      if (c == ',') item_start_ = true;
      else if (!is_blank(c)) item_start_ = false;
    }
    return {};
  }
  // At the end of the file: the bracket left open, or 0.
  char unclosed() const { return open_.empty() ? 0 : open_.back(); }

 private:
  std::string open_;         // the open brackets, innermost last
  bool item_start_ = false;  // at the start of an item inside brackets
};

// Refuses what OpenCV's parser cannot take safely: more than kMaxYamlBytes, nesting deeper than
// kMaxYamlNesting, and the shapes above on which it loops (reported with the line).
void check_yaml_limits(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot be read (" + ec.message() + ")");
  if (bytes > kMaxYamlBytes)
    fail(path, "is " + std::to_string(bytes) + " bytes, more than a camera or extrinsics file can be (" +
                   std::to_string(kMaxYamlBytes) + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot be opened");
  std::string line;
  int flow_depth = 0;
  BlockShape shape;
  FlowShape flow;
  int number = 1;
  for (; std::getline(in, line); ++number) {
    if (!line.empty() && line[0] == '%') {
      if (number == 1 && is_yaml_directive(line)) continue;
      fail(detail::where(path, number), "a directive other than '%YAML:1.0' on the first line");
    }
    const std::string wrong_flow = flow.check(line);
    if (!wrong_flow.empty()) fail(detail::where(path, number), wrong_flow);
    const std::string wrong = shape.check(line, number, flow_depth);
    if (!wrong.empty()) {
      // A bare '-' is reported at its own line.
      const bool bare = wrong == BlockShape::bare_dash_message();
      fail(detail::where(path, bare ? shape.dangling_bare_dash() : number), wrong);
    }
    if (line_nesting(line, flow_depth) > kMaxYamlNesting)
      fail(detail::where(path, number), "nests deeper than " + std::to_string(kMaxYamlNesting) +
                                            " levels (indentation, '-' entries and brackets)");
    if (has_content_after_document_marker(line))
      fail(detail::where(path, number), "text after a '---' or '...' document marker is not supported");
  }
  if (shape.dangling_bare_dash() > 0)
    fail(detail::where(path, shape.dangling_bare_dash()), BlockShape::bare_dash_message());
  if (flow.unclosed())
    fail(path, std::string("a '") + flow.unclosed() + "' is not closed at the end of the file");
}

// Opens path for reading, with our own message for a missing file (OpenCV's is a log line).
void open_for_reading(cv::FileStorage& fs, const std::string& path) {
  if (const std::string problem = detail::input_file_problem(path); !problem.empty()) fail(path, problem);
  check_yaml_limits(path);
  try {
    if (!fs.open(path, cv::FileStorage::READ)) fail(path, "cannot be opened as OpenCV YAML");
  } catch (const std::logic_error& e) {
    // OpenCV's parser builds a string of negative length from an empty key at the end of the file
    // ("%YAML:1.0\n   t:f\n   :", found by fuzzing): std::length_error, not a cv::Exception.
    fail(path, std::string("not a valid OpenCV FileStorage YAML file (") + e.what() + ")");
  }
}

// Runs body, turning OpenCV's parse errors into InvalidInput naming the file.
template <typename F>
auto with_parse_errors(const std::string& path, F&& body) {
  try {
    return body();
  } catch (const cv::Exception& e) {
    fail(path, "not a valid OpenCV FileStorage YAML file (" + e.err + ")");
  }
}

cv::FileNode required(const cv::FileStorage& fs, const std::string& path, const char* key) {
  cv::FileNode n = fs[key];
  if (n.empty() || n.isNone()) fail(path, std::string("missing key '") + key + "'");
  return n;
}

double read_real(const cv::FileNode& n, const std::string& path, const char* key) {
  if (!n.isReal() && !n.isInt()) fail(path, std::string("'") + key + "' is not a number");
  const double v = n.real();
  if (!std::isfinite(v)) fail(path, std::string("'") + key + "' is not finite (NaN or inf)");
  return v;
}

int read_int(const cv::FileNode& n, const std::string& path, const char* key) {
  if (n.isInt()) return n;
  // Accept 640.0, which some writers produce, but not 640.5.
  const double v = read_real(n, path, key);
  if (v != std::floor(v) || std::abs(v) > 1e9)
    fail(path, std::string("'") + key + "' is not an integer");
  return static_cast<int>(v);
}

// The largest matrix any of our files holds is 6x6 (covariance) or 14x1 (distortion).
constexpr int kMaxMatrixSide = 16;

cv::Mat read_matrix(const cv::FileNode& n, const std::string& path, const char* key) {
  cv::Mat m;
  if (!n.isMap()) fail(path, std::string("'") + key + "' is not an opencv-matrix");
  // Checked before OpenCV reads it: OpenCV allocates rows x cols before it compares that with the
  // data (a 100000x100000 header is an 80 GB allocation), and takes "sizes" (an n-d matrix).
  const cv::FileNode rows = n["rows"], cols = n["cols"], data = n["data"];
  if (!rows.isInt() || !cols.isInt() || !data.isSeq())
    fail(path, std::string("'") + key + "' is not an opencv-matrix with rows, cols and data");
  const int nr = rows, nc = cols;
  const std::string shape = std::to_string(nr) + "x" + std::to_string(nc);
  if (nr < 1 || nc < 1 || nr > kMaxMatrixSide || nc > kMaxMatrixSide)
    fail(path, std::string("'") + key + "' is " + shape + ", outside 1.." + std::to_string(kMaxMatrixSide) +
                   " per side");
  if (data.size() != static_cast<size_t>(nr) * static_cast<size_t>(nc))
    fail(path, std::string("'") + key + "' has " + std::to_string(data.size()) + " values for " + shape);
  n >> m;
  if (m.empty() || m.channels() != 1) fail(path, std::string("'") + key + "' is not a matrix");
  m.convertTo(m, CV_64F);
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c)
      if (!std::isfinite(m.at<double>(r, c)))
        fail(path, std::string("'") + key + "' contains NaN or inf");
  return m;
}

std::string read_string(const cv::FileNode& n, const std::string& path, const char* key) {
  if (!n.isString()) fail(path, std::string("'") + key + "' is not a string");
  return n.string();
}

std::string size_text(const cv::Mat& m) {
  return std::to_string(m.rows) + "x" + std::to_string(m.cols);
}

}  // namespace

CameraModel read_camera_yaml(const std::string& path, bool* readout_given) {
  return with_parse_errors(path, [&] {
    cv::FileStorage fs;
    open_for_reading(fs, path);
    CameraModel cam;
    cam.width = read_int(required(fs, path, "image_width"), path, "image_width");
    cam.height = read_int(required(fs, path, "image_height"), path, "image_height");

    const cv::Mat K = read_matrix(required(fs, path, "camera_matrix"), path, "camera_matrix");
    if (K.rows != 3 || K.cols != 3)
      fail(path, "'camera_matrix' is " + size_text(K) + ", expected 3x3");
    cam.fx = K.at<double>(0, 0);
    cam.fy = K.at<double>(1, 1);
    cam.cx = K.at<double>(0, 2);
    cam.cy = K.at<double>(1, 2);
    if (std::abs(K.at<double>(0, 1)) > 1e-9 * std::abs(cam.fx))
      fail(path, "'camera_matrix' has a skew term K(0,1) != 0, which is not supported");
    if (K.at<double>(1, 0) != 0 || K.at<double>(2, 0) != 0 || K.at<double>(2, 1) != 0 ||
        std::abs(K.at<double>(2, 2) - 1.0) > 1e-12)
      fail(path, "'camera_matrix' is not of the form [fx 0 cx; 0 fy cy; 0 0 1]");

    const cv::Mat D = read_matrix(required(fs, path, "distortion_coefficients"), path,
                                  "distortion_coefficients");
    const int n = static_cast<int>(D.total());
    // OpenCV's rational and thin-prism models have 8, 12 or 14 coefficients; with the extra
    // ones zero they are the 5-coefficient model, which is what calibrateCamera returns with
    // those flags unset but an 8x1 output array.
    const bool known_count = n == 4 || n == 5 || n == 8 || n == 12 || n == 14;
    if ((D.rows != 1 && D.cols != 1) || !known_count)
      fail(path, "'distortion_coefficients' is " + size_text(D) +
                     ", expected 1x4, 1x5, 4x1 or 5x1 (k1 k2 p1 p2 [k3])");
    const double* d = D.ptr<double>();
    for (int i = 5; i < n; ++i)
      if (d[i] != 0.0)
        fail(path, "'distortion_coefficients' uses OpenCV's rational or thin-prism model "
                   "(coefficient " + std::to_string(i + 1) + " is not zero), which is not supported");
    cam.k1 = d[0];
    cam.k2 = d[1];
    cam.p1 = d[2];
    cam.p2 = d[3];
    cam.k3 = n >= 5 ? d[4] : 0.0;
    const cv::FileNode roi = fs["region_of_interest"];
    if (!roi.empty() && !roi.isNone()) {
      if (!roi.isSeq() || roi.size() != 4)
        fail(path, "'region_of_interest' is not a list of four integers [x, y, width, height]");
      int v[4];
      for (int i = 0; i < 4; ++i) v[i] = read_int(roi[i], path, "region_of_interest");
      cam.roi = PixelRegion{v[0], v[1], v[2], v[3]};
      if (cam.roi.empty())
        fail(path, "'region_of_interest' has no pixels (width and height must be positive)");
    }
    // planarvo's own, optional: absent is a global shutter. Range checked by validate().
    const cv::FileNode readout = fs["rolling_shutter_readout"];
    const bool given = !readout.empty() && !readout.isNone();
    if (given) cam.rolling_shutter_readout = read_real(readout, path, "rolling_shutter_readout");
    if (readout_given) *readout_given = given;
    const cv::FileNode exposure = fs["exposure_time"];
    if (!exposure.empty() && !exposure.isNone()) cam.exposure_time = read_real(exposure, path, "exposure_time");
    cam.validate(path.c_str());
    return cam;
  });
}

ExtrinsicsEstimate read_extrinsics_yaml(const std::string& path) {
  return with_parse_errors(path, [&] {
    cv::FileStorage fs;
    open_for_reading(fs, path);
    ExtrinsicsEstimate out;
    double* values[6] = {&out.value.x,    &out.value.y,     &out.value.z,
                         &out.value.roll, &out.value.pitch, &out.value.yaw};
    for (size_t i = 0; i < 6; ++i)
      *values[i] = read_real(required(fs, path, kExtrinsicsNames[i]), path, kExtrinsicsNames[i]);

    const cv::FileNode tn = fs["T_robot_camera"];
    if (!tn.empty() && !tn.isNone()) {
      const cv::Mat T = read_matrix(tn, path, "T_robot_camera");
      if (T.rows != 4 || T.cols != 4)
        fail(path, "'T_robot_camera' is " + size_text(T) + ", expected 4x4");
      const Eigen::Matrix4d expected = out.value.T_vc();
      double worst = 0.0;
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
          worst = std::max(worst, std::abs(T.at<double>(r, c) - expected(r, c)));
      if (worst > kMatrixAgreement)
        fail(path, "'T_robot_camera' disagrees with x y z roll pitch yaw (largest difference " +
                       detail::format_exact(worst) + ")");
    }

    const cv::FileNode cn = fs["covariance"];
    if (!cn.empty() && !cn.isNone()) {
      const cv::Mat C = read_matrix(cn, path, "covariance");
      if (C.rows != 6 || C.cols != 6)
        fail(path, "'covariance' is " + size_text(C) + ", expected 6x6");
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) out.covariance(r, c) = C.at<double>(r, c);
    }

    const cv::FileNode en = fs["estimated"];
    if (!en.empty() && !en.isNone()) {
      if (!en.isSeq()) fail(path, "'estimated' is not a sequence such as [x, yaw]");
      for (const cv::FileNode& item : en) {
        if (!item.isString()) fail(path, "'estimated' holds something that is not a name");
        const std::string name = item.string();
        const int k = extrinsics_index(name);
        if (k < 0) fail(path, "'estimated' names '" + name + "', not one of x y z roll pitch yaw");
        if (out.estimated[static_cast<size_t>(k)]) fail(path, "'estimated' names '" + name + "' twice");
        out.estimated[static_cast<size_t>(k)] = true;
      }
    }

    const cv::FileNode mn = fs["method"];
    if (!mn.empty() && !mn.isNone()) out.method = read_string(mn, path, "method");
    const cv::FileNode nn = fs["notes"];
    if (!nn.empty() && !nn.isNone()) out.notes = read_string(nn, path, "notes");
    return out;
  });
}

}  // namespace planarvo::io
