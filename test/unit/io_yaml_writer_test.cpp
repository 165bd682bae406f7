// io/yaml_writer.h against cv::FileStorage itself, the reference it reproduces: random documents
// of every kind of entry the writer has, and camera.yaml and extrinsics.yaml as the OpenCV
// writers that were replaced wrote them (the reference writers below), byte for byte.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "common/test_util.h"
#include "core/error.h"
#include "io/formats.h"
#include "io/yaml_writer.h"
#include "unit/io_test_helpers.h"

namespace planarvo {
namespace {

using io::YamlWriter;

cv::FileStorage opencv_writer() {
  return cv::FileStorage(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
}

// Doubles of every shape OpenCV prints differently: integral in and out of int's range, the
// range's ends, negative zero, tiny and huge magnitudes, and random bit patterns.
double random_real(std::mt19937_64& rng) {
  static const double special[] = {0.0,
                                   -0.0,
                                   1.0,
                                   -3.0,
                                   0.5,
                                   2147483647.0,
                                   -2147483648.0,
                                   2147483648.0,
                                   -2147483649.0,
                                   1e300,
                                   -1e-300,
                                   std::numeric_limits<double>::denorm_min(),
                                   std::numeric_limits<double>::max(),
                                   0.1,
                                   1e16,
                                   123456789.5};
  switch (rng() % 4) {
    case 0:
      return special[rng() % (sizeof special / sizeof special[0])];
    case 1:
      return static_cast<double>(static_cast<int64_t>(rng() % 20000001) - 10000000);
    case 2: {
      double v;
      uint64_t bits;
      do {
        bits = rng();
        std::memcpy(&v, &bits, sizeof v);
      } while (!std::isfinite(v));
      return v;
    }
    default:
      return std::uniform_real_distribution<double>(-1000.0, 1000.0)(rng);
  }
}

// Strings that reach every quoting rule: empty, leading blank, leading digit or sign, quotes at
// both ends, escapes, control and UTF-8 bytes, YAML indicators, long ones that wrap a flow line.
std::string random_string(std::mt19937_64& rng) {
  static const char* const special[] = {"", " lead", "\"both\"", "'both'", "'mixed\"", "1abc", "-x", "+x", ".x",
                                        "null", "true", "~", "plain words", "semi;slash/(p)+", "x=1,y"};
  if (rng() % 3 == 0) return special[rng() % (sizeof special / sizeof special[0])];
  static const std::string alphabet = "abcXYZ019 _-()/+;.,:#[]{}\"'\\\t\n\r\x01\x1f\x7f\xc3\xa9";
  std::string s;
  const size_t n = rng() % (rng() % 5 == 0 ? 120 : 12);
  for (size_t i = 0; i < n; ++i) {
    const uint64_t pick = rng() % 50;
    s += pick < alphabet.size() ? alphabet[pick] : static_cast<char>(1 + rng() % 255);
  }
  return s;
}

TEST(YamlWriter, RandomDocumentsAreWhatFileStorageWrites) {
  std::mt19937_64 rng(20261129);
  for (int doc = 0; doc < 300; ++doc) {
    YamlWriter ours;
    cv::FileStorage theirs = opencv_writer();
    const int entries = 1 + static_cast<int>(rng() % 12);
    for (int i = 0; i < entries; ++i) {
      // Keys of 1 to 24 characters: a short one puts a block collection's first line under the
      // key's own width.
      std::string key = "k" + std::to_string(i);
      key += std::string(rng() % 23, 'a' + static_cast<char>(rng() % 26));
      switch (rng() % 6) {
        case 0: {
          const int v = static_cast<int>(rng());
          ours.write(key.c_str(), v);
          theirs << key << v;
          break;
        }
        case 1: {
          const double v = random_real(rng);
          ours.write(key.c_str(), v);
          theirs << key << v;
          break;
        }
        case 2: {
          const std::string v = random_string(rng);
          ours.write(key.c_str(), v, "value");
          cv::write(theirs, key, v);
          break;
        }
        case 3: {
          const int rows = 1 + static_cast<int>(rng() % 7), cols = 1 + static_cast<int>(rng() % 7);
          cv::Mat m(rows, cols, CV_64F);
          for (int k = 0; k < rows * cols; ++k) m.at<double>(k) = random_real(rng);
          ours.write_matrix(key.c_str(), rows, cols, m.ptr<double>());
          theirs << key << m;
          break;
        }
        case 4: {
          if (rng() % 2) {
            std::vector<double> v(rng() % 12);
            for (double& x : v) x = random_real(rng);
            theirs << key << v;
            ours.write_flow(key.c_str(), v);
            break;
          }
          std::vector<int> v(rng() % 30);
          theirs << key << "[:";
          for (int& x : v) {
            x = static_cast<int>(rng() % 3 == 0 ? rng() : rng() % 100);
            theirs << x;
          }
          theirs << "]";
          ours.write_flow(key.c_str(), v);
          break;
        }
        default: {
          std::vector<std::string> v(rng() % 4);
          theirs << key << "[";
          for (std::string& x : v) {
            x = random_string(rng);
            theirs.write("", x);  // not <<, which reads a leading '[' or '{' as structure
          }
          theirs << "]";
          ours.write_block(key.c_str(), v, "value");
          break;
        }
      }
    }
    const std::string expected = theirs.releaseAndGetString();
    ASSERT_EQ(ours.finish(), expected) << "document " << doc;
  }
}

TEST(YamlWriter, RefusesWhatFileStorageRefusesOrCuts) {
  YamlWriter w;
  EXPECT_THROW(w.write("notes", std::string(4097, 'a'), "notes"), Error);
  EXPECT_THROW(w.write("notes", std::string("a\0b", 3), "notes"), Error);
  // The longest string OpenCV writes is written.
  cv::FileStorage theirs = opencv_writer();
  cv::write(theirs, "notes", std::string(4096, 'a'));
  YamlWriter ours;
  ours.write("notes", std::string(4096, 'a'), "notes");
  EXPECT_EQ(ours.finish(), theirs.releaseAndGetString());
}

// The writers the YAML writer replaced, kept here as the reference: they wrote the files with
// cv::FileStorage.
std::string reference_camera_yaml(const CameraModel& camera) {
  cv::FileStorage fs = opencv_writer();
  fs << "image_width" << camera.width;
  fs << "image_height" << camera.height;
  cv::Mat K = (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  fs << "camera_matrix" << K;
  cv::Mat D = (cv::Mat_<double>(5, 1) << camera.k1, camera.k2, camera.p1, camera.p2, camera.k3);
  fs << "distortion_coefficients" << D;
  if (!camera.roi.empty())
    fs << "region_of_interest" << "[:" << camera.roi.x << camera.roi.y << camera.roi.width << camera.roi.height << "]";
  if (camera.rolling_shutter_readout != 0) fs << "rolling_shutter_readout" << camera.rolling_shutter_readout;
  if (camera.exposure_time != 0) fs << "exposure_time" << camera.exposure_time;
  return fs.releaseAndGetString();
}

std::string reference_extrinsics_yaml(const ExtrinsicsEstimate& e) {
  cv::FileStorage fs = opencv_writer();
  const std::array<double, 6> values = extrinsics_values(e.value);
  for (size_t i = 0; i < 6; ++i) fs << kExtrinsicsNames[i] << values[i];
  const Eigen::Matrix4d T = e.value.T_vc();
  cv::Mat Tm(4, 4, CV_64F), Cm(6, 6, CV_64F);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) Tm.at<double>(r, c) = T(r, c);
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) Cm.at<double>(r, c) = e.covariance(r, c);
  fs << "T_robot_camera" << Tm;
  fs << "covariance" << Cm;
  fs << "estimated" << "[";
  for (size_t i = 0; i < 6; ++i)
    if (e.estimated[i]) fs << kExtrinsicsNames[i];
  fs << "]";
  cv::write(fs, "method", e.method);
  cv::write(fs, "notes", e.notes);
  return fs.releaseAndGetString();
}

TEST(YamlWriter, CameraAndExtrinsicsFilesAreWhatOpenCVWrote) {
  test::ScratchDir dir;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    CameraModel c;
    c.width = 320 + static_cast<int>(rng() % 1600);
    c.height = 240 + static_cast<int>(rng() % 1200);
    c.fx = 300 + 500 * std::abs(u(rng));
    c.fy = trial % 3 == 0 ? c.fx : 300 + 500 * std::abs(u(rng));
    c.cx = trial % 4 == 0 ? c.width / 2 : c.width * (0.5 + 0.1 * u(rng));
    c.cy = c.height * (0.5 + 0.1 * u(rng));
    c.k1 = 0.3 * u(rng);
    c.k2 = trial % 2 ? 0.0 : 0.1 * u(rng);
    c.p1 = 1e-3 * u(rng);
    c.p2 = trial % 5 ? 1e-3 * u(rng) : 0.0;
    c.k3 = trial % 3 ? 0.0 : 0.01 * u(rng);
    if (trial % 2) c.roi = PixelRegion{static_cast<int>(rng() % 20), static_cast<int>(rng() % 20), c.width / 2, c.height / 2};
    if (trial % 3 == 1) c.rolling_shutter_readout = 0.03 * std::abs(u(rng)) + 1e-4;
    if (trial % 4 == 1) c.exposure_time = 0.01 * std::abs(u(rng)) + 1e-4;
    const std::string camera_path = (dir.path() / "camera.yaml").string();
    io::write_camera_yaml(camera_path, c);
    ASSERT_EQ(test::read_text(camera_path), reference_camera_yaml(c)) << "trial " << trial;

    ExtrinsicsEstimate e;
    e.value = {0.5 * u(rng), 0.5 * u(rng), 0.1 + 0.5 * std::abs(u(rng)), u(rng), u(rng), 3 * u(rng)};
    if (trial % 4 == 0) e.value.x = 0.0;
    Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Random();
    if (trial % 3) e.covariance = 1e-6 * a * a.transpose();
    for (size_t i = 0; i < 6; ++i) e.estimated[i] = (rng() % 2) != 0;
    e.method = trial % 2 ? "odometry (section 5.2)" : random_string(rng);
    e.notes = random_string(rng);
    const std::string extrinsics_path = (dir.path() / "extrinsics.yaml").string();
    io::write_extrinsics_yaml(extrinsics_path, e);
    ASSERT_EQ(test::read_text(extrinsics_path), reference_extrinsics_yaml(e)) << "trial " << trial;
  }
}

}  // namespace
}  // namespace planarvo
