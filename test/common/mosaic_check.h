// The floor mosaic checked against the simulator's ground, independently of the mosaic's code: the
// map_server YAML parsed on its own, the texture mirror-tiled over the plane as src/sim/SIMULATOR.md
// defines it, and the normalised cross-correlation of the seen pixels with it. For tests and
// benchmarks (no gtest).
#pragma once
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <locale>
#include <sstream>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace planarvo::test {

struct MapYaml {
  std::string image;
  double resolution = 0, x = 0, y = 0, yaw = 0;
  bool ok = false;  // every key found
};

// The value after "\nkey:" on its line, trimmed ("" when absent). (No std::regex: GCC 12 warns
// inside it under the sanitizers' -O3, and warnings are errors.)
inline std::string yaml_value(const std::string& text, const std::string& key) {
  const size_t at = text.find("\n" + key + ":");
  if (at == std::string::npos) return "";
  const size_t begin = at + key.size() + 2;
  const size_t stop = text.find('\n', begin);
  std::string v = text.substr(begin, stop == std::string::npos ? std::string::npos : stop - begin);
  const size_t a = v.find_first_not_of(" \t\r\"");
  const size_t b = v.find_last_not_of(" \t\r\"");
  return a == std::string::npos ? "" : v.substr(a, b - a + 1);
}

// The keys map_server reads.
inline MapYaml read_map_yaml(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  const std::string s = "\n" + std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  MapYaml m;
  m.image = yaml_value(s, "image");
  const std::string res = yaml_value(s, "resolution"), origin = yaml_value(s, "origin");
  if (m.image.empty() || res.empty() || origin.size() < 2 || origin.front() != '[' || origin.back() != ']') return m;
  try {
    m.resolution = std::stod(res);
    std::string list = origin.substr(1, origin.size() - 2);
    for (char& c : list)
      if (c == ',') c = ' ';
    std::istringstream values(list);
    values.imbue(std::locale::classic());
    if (!(values >> m.x >> m.y >> m.yaw)) return m;
  } catch (const std::exception&) {
    return m;
  }
  m.ok = true;
  return m;
}

// The simulator's ground: the texture mirror-tiled over the plane, world (X, Y) at texel
// (X, Y) / texel, smoothed by a Gaussian of 0.3 mosaic pixels (the mosaic's pixels are point
// samples of frames that already carry the camera's blur; 0.3 gave the highest correlation on the
// default drive, against 0.93 at 0.5 and 0.89 at 0.1).
class Ground {
 public:
  Ground(const std::string& texture, double texel, double resolution) : texel_(texel) {
    cv::Mat t = cv::imread(texture, cv::IMREAD_GRAYSCALE);
    if (t.empty()) return;
    t.convertTo(t, CV_32F);
    cv::Mat fx, fy, fxy, top, bottom, period;
    cv::flip(t, fx, 1);
    cv::flip(t, fy, 0);
    cv::flip(t, fxy, -1);
    cv::hconcat(t, fx, top);
    cv::hconcat(fy, fxy, bottom);
    cv::vconcat(top, bottom, period);  // one whole mirror period: the plane tiles it by wrapping
    const double sigma = 0.3 * resolution / texel;
    const int pad = static_cast<int>(std::ceil(4 * sigma)) + 1;
    cv::Mat padded, blurred;
    cv::copyMakeBorder(period, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
    cv::GaussianBlur(padded, blurred, cv::Size(0, 0), sigma);
    period_ = blurred(cv::Rect(pad, pad, period.cols, period.rows)).clone();
  }
  bool empty() const { return period_.empty(); }
  double at(double X, double Y) const {
    const double u = X / texel_, v = Y / texel_;
    const double u0 = std::floor(u), v0 = std::floor(v);
    const double fu = u - u0, fv = v - v0;
    const auto px = [&](double a, double b) {
      const int c = static_cast<int>(std::fmod(std::fmod(a, period_.cols) + period_.cols, period_.cols));
      const int r = static_cast<int>(std::fmod(std::fmod(b, period_.rows) + period_.rows, period_.rows));
      return static_cast<double>(period_.at<float>(r, c));
    };
    const double top = px(u0, v0) + fu * (px(u0 + 1, v0) - px(u0, v0));
    const double bottom = px(u0, v0 + 1) + fu * (px(u0 + 1, v0 + 1) - px(u0, v0 + 1));
    return top + fv * (bottom - top);
  }

 private:
  double texel_;
  cv::Mat period_;
};

// NCC of a mosaic's seen pixels (non-zero) against the ground at the place its YAML gives, the
// trajectory's frame mapped to the world by the pose (x, y, theta) of its origin there (the true
// first pose for a trajectory from `track`). *seen: the pixels compared. 0 for an unreadable file.
inline double ncc_against_ground(const std::filesystem::path& image_path, const Ground& ground, double x0, double y0,
                                 double theta0, int64_t* seen = nullptr) {
  const MapYaml y = read_map_yaml(std::filesystem::path(image_path).replace_extension(".yaml"));
  const cv::Mat m = cv::imread(image_path.string(), cv::IMREAD_UNCHANGED);
  if (seen) *seen = 0;
  if (!y.ok || m.empty() || m.type() != CV_8UC1) return 0;
  const double c = std::cos(theta0), s = std::sin(theta0);
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  int64_t n = 0;
  for (int row = 0; row < m.rows; ++row)
    for (int col = 0; col < m.cols; ++col) {
      const uint8_t v = m.at<uint8_t>(row, col);
      if (v == 0) continue;
      // map_server: the lower-left corner of the lower-left pixel at the origin, row 0 at the top.
      const double x = y.x + (col + 0.5) * y.resolution;
      const double yy = y.y + (m.rows - row - 0.5) * y.resolution;
      const double a = v, b = ground.at(x0 + c * x - s * yy, y0 + s * x + c * yy);
      sa += a;
      sb += b;
      saa += a * a;
      sbb += b * b;
      sab += a * b;
      ++n;
    }
  if (seen) *seen = n;
  if (n < 2) return 0;
  const double nn = static_cast<double>(n);
  const double cov = sab - sa * sb / nn, va = saa - sa * sa / nn, vb = sbb - sb * sb / nn;
  return cov / std::sqrt(va * vb);
}

}  // namespace planarvo::test
