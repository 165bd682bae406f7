// Known and saved flat fields (image/photometric.h): reading a flat-field file (its refusals and
// its normalisation, against the pixel values written), writing one, and a known gain in
// distorted camera pixels through the undistorted model and back, against the gain itself.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "core/error.h"
#include "image/photometric.h"
#include "image/undistort.h"
#include "sim/simulator.h"

namespace planarvo {
namespace {

using test::ScratchDir;

// The message of the InvalidInput that f throws ("" and a failure when it throws none or another).
template <class F>
std::string invalid_input(F f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidInput) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no exception";
  return "";
}

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(FlatField, ReadRefusesAnotherSizeZeroAndUnreadableFiles) {
  ScratchDir d;
  cv::Mat img(10, 20, CV_8UC1, cv::Scalar(200));
  const std::string small = (d / "small.png").string();
  ASSERT_TRUE(cv::imwrite(small, img));
  std::string m = invalid_input([&] { read_flat_field(small, 30, 10); });
  EXPECT_TRUE(has(m, small) && has(m, "20x10") && has(m, "30x10")) << m;

  img.at<uint8_t>(4, 3) = 0;  // row 4, column 3: pixel (3, 4)
  const std::string zero = (d / "zero.png").string();
  ASSERT_TRUE(cv::imwrite(zero, img));
  m = invalid_input([&] { read_flat_field(zero, 20, 10); });
  EXPECT_TRUE(has(m, zero) && has(m, "(3, 4)")) << m;

  const std::string missing = (d / "missing.png").string();
  m = invalid_input([&] { read_flat_field(missing, 20, 10); });
  EXPECT_TRUE(has(m, missing)) << m;
  const std::string text = (d / "text.png").string();
  std::ofstream(text) << "not an image\n";
  m = invalid_input([&] { read_flat_field(text, 20, 10); });
  EXPECT_TRUE(has(m, text)) << m;
}

TEST(FlatField, ReadRefusesANonFinitePixel) {
  ScratchDir d;
  cv::Mat img(10, 20, CV_32FC1, cv::Scalar(0.5f));
  img.at<float>(2, 5) = std::numeric_limits<float>::quiet_NaN();
  const std::string nan = (d / "nan.tiff").string();
  bool written = false;
  try {
    written = cv::imwrite(nan, img);
  } catch (const cv::Exception&) {
  }
  if (!written) GTEST_SKIP() << "this OpenCV writes no float TIFF";
  const cv::Mat back = cv::imread(nan, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH);
  if (back.type() != CV_32FC1) GTEST_SKIP() << "this OpenCV reads the float TIFF back as another type";
  const std::string m = invalid_input([&] { read_flat_field(nan, 20, 10); });
  EXPECT_TRUE(has(m, nan) && has(m, "(5, 2)")) << m;
}

TEST(FlatField, ReadNormalisesEightAndSixteenBitFilesToTheirMaximum) {
  ScratchDir d;
  cv::Mat u8(7, 9, CV_8UC1), u16(7, 9, CV_16UC1);
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 9; ++x) {
      u8.at<uint8_t>(y, x) = static_cast<uint8_t>(20 + 3 * x + 11 * y);       // max 20 + 24 + 66 = 110
      u16.at<uint16_t>(y, x) = static_cast<uint16_t>(900 + 500 * x + 97 * y);  // max 900 + 4000 + 582
    }
  const std::string p8 = (d / "g8.png").string(), p16 = (d / "g16.png").string();
  ASSERT_TRUE(cv::imwrite(p8, u8));
  ASSERT_TRUE(cv::imwrite(p16, u16));
  const cv::Mat g8 = read_flat_field(p8, 9, 7), g16 = read_flat_field(p16, 9, 7);
  ASSERT_EQ(g8.type(), CV_32FC1);
  ASSERT_EQ(g16.type(), CV_32FC1);
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 9; ++x) {
      EXPECT_NEAR(g8.at<float>(y, x), (20.0 + 3 * x + 11 * y) / 110.0, 1e-6) << x << "," << y;
      EXPECT_NEAR(g16.at<float>(y, x), (900.0 + 500 * x + 97 * y) / 5482.0, 1e-6) << x << "," << y;
    }
}

TEST(FlatField, WrittenAsASixteenBitPngThatReadsBack) {
  ScratchDir d;
  cv::Mat g(12, 16, CV_32FC1);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 16; ++x) g.at<float>(y, x) = static_cast<float>(1.0 - 0.04 * x - 0.03 * y);
  const std::string path = (d / "ff.png").string();
  write_flat_field(path, g);
  EXPECT_EQ(test::partial_files(path), 0);
  const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(raw.type(), CV_16UC1);
  EXPECT_EQ(raw.at<uint16_t>(0, 0), 65535);
  EXPECT_EQ(raw.at<uint16_t>(11, 15), std::lround((1.0 - 0.6 - 0.33) * 65535.0));
  const cv::Mat back = read_flat_field(path, 16, 12);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 16; ++x) EXPECT_NEAR(back.at<float>(y, x), g.at<float>(y, x), 1e-5);
  // A folder that does not exist: Io naming the file.
  const std::string bad = (d / "no" / "ff.png").string();
  try {
    write_flat_field(bad, g);
    ADD_FAILURE() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Io);
    EXPECT_TRUE(has(e.what(), bad)) << e.what();
  }
}

TEST(FlatField, FillGivesEachHoleTheNearestValue) {
  cv::Mat g(20, 20, CV_32FC1);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) g.at<float>(y, x) = static_cast<float>(x + 1) / 20.0f;  // constant along columns
  cv::Mat holed = g.clone();
  holed.rowRange(8, 11).setTo(0.0f);  // rows 8..10: the nearest value lies up or down the column
  const cv::Mat f = fill_flat_field(holed);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) EXPECT_EQ(f.at<float>(y, x), g.at<float>(y, x)) << x << "," << y;
  try {
    fill_flat_field(cv::Mat(5, 5, CV_32FC1, cv::Scalar(0.0f)));
    ADD_FAILURE() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Failed);
  }
}

// A lamp's smooth falloff in distorted camera pixels, its brightest point inside the image.
double lamp(int x, int y, int w, int h) {
  const double dx = x - 0.58 * w, dy = y - 0.42 * h, s = 0.9 * w;
  return std::pow(1.0 + (dx * dx + dy * dy) / (s * s), -1.5);
}

TEST(FlatField, ThroughTheUndistortedModelAndBack) {
  const CameraModel camera = sim::default_camera(320, 240);
  ASSERT_TRUE(camera.has_distortion());
  const int w = camera.width, h = camera.height;
  cv::Mat gain(h, w, CV_32FC1);
  double top = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) top = std::max(top, lamp(x, y, w, h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) gain.at<float>(y, x) = static_cast<float>(lamp(x, y, w, h) / top);
  const UndistortMap map = compute_undistort_map(camera);
  const cv::Mat valid = cv::Mat(h, w, CV_8UC1, const_cast<uint8_t*>(map.valid.data())).clone();
  const cv::Mat undistorted = flat_field_to_undistorted(gain, map);
  // The undistorted gain is the distorted one at the map's source (independently: the lamp there).
  for (int y = 0; y < h; y += 7)
    for (int x = 0; x < w; x += 7) {
      const size_t i = static_cast<size_t>(y) * w + x;
      if (!map.valid[i]) {
        EXPECT_EQ(undistorted.at<float>(y, x), 0.0f);
        continue;
      }
      const double sx = map.map_x[i], sy = map.map_y[i];
      const double dx = sx - 0.58 * w, dy = sy - 0.42 * h, s = 0.9 * w;
      EXPECT_NEAR(undistorted.at<float>(y, x), std::pow(1.0 + (dx * dx + dy * dy) / (s * s), -1.5) / top, 1e-4);
    }
  const PhotometricFit fit = flat_field_photometric(undistorted, valid, PhotometricOptions{});
  const cv::Mat back = flat_field_to_distorted(fit, camera);
  ASSERT_EQ(back.type(), CV_32FC1);
  ASSERT_EQ(back.size(), gain.size());
  int compared = 0, interior = 0;
  double worst = 0;
  for (int y = 10; y < h - 10; ++y)
    for (int x = 10; x < w - 10; ++x) {
      ++interior;
      const float b = back.at<float>(y, x);
      if (b == 0.0f) continue;  // no undistorted source
      ++compared;
      worst = std::max(worst, std::abs(b - static_cast<double>(gain.at<float>(y, x))));
    }
  EXPECT_LT(worst, 1e-3);
  EXPECT_GT(compared, 0.9 * interior);
}

}  // namespace
}  // namespace planarvo
