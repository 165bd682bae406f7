// YAML written the way cv::FileStorage writes it (OpenCV 4's YAML emitter), without OpenCV, so
// that the base library writes camera.yaml and extrinsics.yaml byte for byte as before without
// loading the vision module. formats_yaml.cpp writes the two formats with it, the simulator its
// simulation.yaml.
//
// The layout it reproduces, which test/unit/yaml_writer_test.cpp checks against cv::FileStorage:
// "%YAML:1.0" and "---" lines, then one "key: value" line per top-level entry; a block
// collection's entries on their own lines indented 3 spaces more than its parent; a flow
// collection "[ a, b ]" whose line wraps before an entry that would end past column 71, the
// continuation indented 3 + 1 spaces more than its parent; a matrix as the map "!!opencv-matrix"
// of rows, cols, dt and a flow sequence data. Reals as OpenCV prints them: an integral value
// that fits an int as "%d." ("0.", "-3."), any other "%.16e"; strings quoted and escaped by
// OpenCV's rules (quote_string below).
#pragma once
#include <string>
#include <vector>

namespace planarvo::io {

class YamlWriter {
 public:
  YamlWriter();
  // Top-level entries. Keys are the caller's constants (letters, digits, '_').
  void write(const char* key, int value);
  void write(const char* key, double value);
  // Throws InvalidArgument for a string OpenCV's writer refuses or cuts (over 4096 bytes, or
  // holding a NUL byte); `what` names it in the message.
  void write(const char* key, const std::string& value, const std::string& what);
  // A rows x cols matrix of doubles, row-major, as cv::write of a CV_64F cv::Mat.
  void write_matrix(const char* key, int rows, int cols, const double* data);
  // fs << key << "[:" << v... << "]": a flow sequence of integers; of reals as cv::write of a
  // std::vector<double>.
  void write_flow(const char* key, const std::vector<int>& values);
  void write_flow(const char* key, const std::vector<double>& values);
  // fs << key << "[" << s... << "]": a block sequence of strings (written "[]" when empty).
  void write_block(const char* key, const std::vector<std::string>& values, const std::string& what);
  // The document, every line ended by '\n'. The writer is spent afterwards.
  std::string finish();
  // finish() written to path, complete or not at all; Error(Io) naming the file on failure.
  void save(const std::string& path);

 private:
  struct Level {
    int indent;
    bool map, flow, empty;
  };
  void begin(const char* key, bool map, bool flow, const char* tag);
  void end();
  // An entry of the innermost collection: "key: data" in a map, "- data" in a block sequence,
  // "data" in a flow one; key null inside sequences, data null for a collection's opening line.
  void scalar(const char* key, const char* data);
  void flush();

  std::vector<Level> levels_;
  std::string text_;
  std::string line_;
  size_t line_indent_ = 0;
};

// OpenCV's text of a real (fs::doubleToString) and of a string value (YAMLEmitter::write).
std::string format_real(double v);
std::string quote_string(const std::string& s);

}  // namespace planarvo::io
