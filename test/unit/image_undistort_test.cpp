// The undistortion map against cv::initUndistortRectifyMap, and remap_bilinear (the future
// OpenCL kernel's reference) against exact answers: bilinear interpolation reproduces an affine
// image exactly, and undistorting a synthetic distorted rendering gives back the scene.
#include <cmath>
#include <random>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <gtest/gtest.h>

#include "core/error.h"
#include "image/undistort.h"

namespace planarvo {
namespace {

struct DistortionCase {
  const char* name;
  double k1, k2, p1, p2, k3;
};

const DistortionCase kCases[] = {
    {"none", 0, 0, 0, 0, 0},
    {"barrel", -0.28, 0.07, 0.0, 0.0, 0.0},
    {"pincushion", 0.15, 0.02, 0.0, 0.0, 0.0},
    {"tangential", -0.05, 0.01, 0.002, -0.0015, 0.0},
    {"with_k3", -0.3, 0.12, 0.0008, 0.0005, -0.025},
};

CameraModel make_camera(const DistortionCase& d, int width = 640, int height = 480) {
  CameraModel c;
  c.width = width;
  c.height = height;
  c.fx = 0.625 * width;
  c.fy = 0.63 * width;
  c.cx = 0.5 * width - 1.6;
  c.cy = 0.5 * height + 3.7;
  c.k1 = d.k1;
  c.k2 = d.k2;
  c.p1 = d.p1;
  c.p2 = d.p2;
  c.k3 = d.k3;
  return c;
}

TEST(ImageUndistortMap, MatchesInitUndistortRectifyMap) {
  for (const DistortionCase& d : kCases) {
    SCOPED_TRACE(d.name);
    const CameraModel cam = make_camera(d);
    const UndistortMap m = compute_undistort_map(cam);
    ASSERT_EQ(m.width, 640);
    ASSERT_EQ(m.height, 480);
    ASSERT_EQ(m.map_x.size(), 640u * 480u);

    const cv::Mat K = (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
    const cv::Mat D = (cv::Mat_<double>(1, 5) << cam.k1, cam.k2, cam.p1, cam.p2, cam.k3);
    cv::Mat cv_x, cv_y;
    cv::initUndistortRectifyMap(K, D, cv::Mat::eye(3, 3, CV_64F), K, cv::Size(640, 480), CV_32FC1,
                                cv_x, cv_y);
    double worst = 0.0;
    size_t valid_disagreements = 0;
    const auto near_border = [](double c, double last) {
      return std::abs(c) < 1e-3 || std::abs(c - last) < 1e-3;
    };
    for (int v = 0; v < 480; ++v)
      for (int u = 0; u < 640; ++u) {
        const size_t i = static_cast<size_t>(v) * 640 + static_cast<size_t>(u);
        const float ox = cv_x.at<float>(v, u), oy = cv_y.at<float>(v, u);
        worst = std::max({worst, std::abs(double(m.map_x[i]) - ox), std::abs(double(m.map_y[i]) - oy)});
        const bool cv_valid = ox >= 0 && ox <= 639 && oy >= 0 && oy <= 479;
        // OpenCV inverts K numerically, so a coordinate that is exactly on the border here can
        // be a rounding error outside it there: only disagreements away from it count.
        if (cv_valid != (m.valid[i] != 0) && !near_border(ox, 639) && !near_border(oy, 479))
          ++valid_disagreements;
      }
    EXPECT_LT(worst, 0.01) << "pixels";
    EXPECT_EQ(valid_disagreements, 0u);
  }
}

TEST(ImageUndistortMap, ValidMeansAllFourNeighboursInside) {
  // Pincushion: the undistorted image's corners look beyond the sensor's (with barrel
  // distortion, the other way round, every output pixel is valid and the periphery is lost).
  const CameraModel cam = make_camera(kCases[2]);
  const UndistortMap m = compute_undistort_map(cam);
  size_t valid = 0, invalid = 0;
  for (size_t i = 0; i < m.valid.size(); ++i) {
    const bool inside = m.map_x[i] >= 0.0f && m.map_x[i] <= 639.0f && m.map_y[i] >= 0.0f &&
                        m.map_y[i] <= 479.0f;
    EXPECT_EQ(m.valid[i] != 0, inside) << i;
    (inside ? valid : invalid)++;
  }
  EXPECT_GT(invalid, 1000u);
  EXPECT_GT(valid, 200000u);
  EXPECT_EQ(m.valid_count(), valid);
  // The centre is valid, a corner is not.
  EXPECT_EQ(m.valid[240 * 640 + 320], 1);
  EXPECT_EQ(m.valid[0], 0);
}

TEST(ImageUndistortMap, WithoutDistortionIsTheIdentity) {
  const UndistortMap m = compute_undistort_map(make_camera(kCases[0], 64, 48));
  for (int v = 0; v < 48; ++v)
    for (int u = 0; u < 64; ++u) {
      const size_t i = static_cast<size_t>(v) * 64 + static_cast<size_t>(u);
      EXPECT_NEAR(m.map_x[i], u, 2e-5);
      EXPECT_NEAR(m.map_y[i], v, 2e-5);
    }
  // Only the far column/row could round past the border.
  EXPECT_GE(m.valid_count(), 62u * 46u);
}

TEST(ImageUndistortMap, RejectsAnInvalidCamera) {
  CameraModel c = make_camera(kCases[0]);
  c.fx = std::nan("");
  EXPECT_THROW(compute_undistort_map(c), Error);
}

TEST(ImageRemapBilinear, ReproducesAnAffineImageExactly) {
  const CameraModel cam = make_camera(kCases[4], 160, 120);
  const UndistortMap m = compute_undistort_map(cam);
  cv::Mat src(120, 160, CV_32FC1);
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 160; ++x) src.at<float>(y, x) = 0.5f * x - 0.75f * y + 100.0f;
  const cv::Mat out = remap_bilinear(src, m);
  ASSERT_EQ(out.type(), CV_32FC1);
  ASSERT_EQ(out.size(), src.size());
  double worst = 0.0;
  for (int v = 0; v < 120; ++v)
    for (int u = 0; u < 160; ++u) {
      const size_t i = static_cast<size_t>(v) * 160 + static_cast<size_t>(u);
      if (!m.valid[i]) {
        EXPECT_EQ(out.at<float>(v, u), 0.0f);
        continue;
      }
      const double expected = 0.5 * m.map_x[i] - 0.75 * m.map_y[i] + 100.0;
      worst = std::max(worst, std::abs(out.at<float>(v, u) - expected));
    }
  EXPECT_LT(worst, 1e-3);  // float arithmetic on values ~100
}

TEST(ImageRemapBilinear, EightBitAndFloatSourcesAgree) {
  const UndistortMap m = compute_undistort_map(make_camera(kCases[3], 160, 120));
  cv::Mat src8(120, 160, CV_8UC1);
  cv::randu(src8, 0, 256);
  cv::Mat src32;
  src8.convertTo(src32, CV_32F);
  const cv::Mat a = remap_bilinear(src8, m), b = remap_bilinear(src32, m);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

TEST(ImageRemapBilinear, SamplesTheLastRowAndColumn) {
  // A map that points exactly at the far corner and edges must not read outside the image.
  UndistortMap m;
  m.width = 4;
  m.height = 3;
  m.map_x = {3.0f, 0.0f, 3.0f, 1.5f, 0, 0, 0, 0, 0, 0, 0, 0};
  m.map_y = {2.0f, 2.0f, 0.5f, 2.0f, 0, 0, 0, 0, 0, 0, 0, 0};
  m.valid.assign(12, 1);
  const cv::Mat src = (cv::Mat_<float>(3, 4) << 0, 1, 2, 3, 10, 11, 12, 13, 20, 21, 22, 23);
  const cv::Mat out = remap_bilinear(src, m);
  EXPECT_FLOAT_EQ(out.at<float>(0, 0), 23.0f);
  EXPECT_FLOAT_EQ(out.at<float>(0, 1), 20.0f);
  EXPECT_FLOAT_EQ(out.at<float>(0, 2), 8.0f);
  EXPECT_FLOAT_EQ(out.at<float>(0, 3), 21.5f);
  EXPECT_FLOAT_EQ(out.at<float>(1, 0), 0.0f);
}

// Render the distorted image of a known scene f(undistorted pixel), undistort it, and get f back.
TEST(ImageRemapBilinear, UndistortsASyntheticRendering) {
  const CameraModel cam = make_camera(kCases[1], 160, 120);
  const auto scene = [](double u, double v) {
    return 128.0 + 60.0 * std::sin(u / 15.0) * std::cos(v / 12.0) + 0.2 * u;
  };
  cv::Mat distorted(120, 160, CV_32FC1);
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 160; ++x) {
      const Eigen::Vector2d n = cam.unproject(Eigen::Vector2d(x, y));
      distorted.at<float>(y, x) = static_cast<float>(scene(cam.fx * n.x() + cam.cx, cam.fy * n.y() + cam.cy));
    }
  const UndistortMap m = compute_undistort_map(cam);
  const cv::Mat out = remap_bilinear(distorted, m);
  double worst = 0.0;
  for (int v = 0; v < 120; ++v)
    for (int u = 0; u < 160; ++u)
      if (m.valid[static_cast<size_t>(v) * 160 + static_cast<size_t>(u)])
        worst = std::max(worst, std::abs(out.at<float>(v, u) - scene(u, v)));
  // Bilinear interpolation errs by at most (|f_xx| + |f_yy|) / 8 for unit pixels: here
  // (60/15^2 + 60/12^2) / 8 = 0.086 grey levels in undistorted pixels, times up to ~3.8 where
  // the barrel compresses the scene by ~0.51 (radial derivative at the corners). A wrong map
  // (the inverse distortion, a swapped axis) is off by pixels, which here is tens of grey levels.
  EXPECT_LT(worst, 0.35);
}

TEST(ImageRemapBilinear, RejectsWrongTypeOrSize) {
  const UndistortMap m = compute_undistort_map(make_camera(kCases[0], 16, 12));
  EXPECT_THROW(remap_bilinear(cv::Mat(12, 16, CV_8UC3), m), Error);
  EXPECT_THROW(remap_bilinear(cv::Mat(12, 15, CV_8UC1), m), Error);
}

// The region of interest limits the map's valid pixels to those whose bilinear footprint lies
// in it. Without distortion the map is the identity, so exactly the region's pixels are valid;
// with distortion, a pixel is valid when it is in the whole image's map and its source lies in
// the region, which is checked against the source coordinates directly.
TEST(UndistortMap, RegionOfInterestLimitsTheValidPixels) {
  for (const DistortionCase& d : kCases) {
    SCOPED_TRACE(d.name);
    CameraModel c = make_camera(d);
    const UndistortMap whole = compute_undistort_map(c);
    c.roi = PixelRegion{37, 101, 200, 150};
    const UndistortMap m = compute_undistort_map(c);
    size_t valid = 0;
    for (int v = 0; v < c.height; ++v)
      for (int u = 0; u < c.width; ++u) {
        const size_t i = static_cast<size_t>(v) * static_cast<size_t>(c.width) + static_cast<size_t>(u);
        const float sx = m.map_x[i], sy = m.map_y[i];
        const bool inside = sx >= 37.0f && sx <= 236.0f && sy >= 101.0f && sy <= 250.0f;
        ASSERT_EQ(m.valid[i] != 0, inside && whole.valid[i] != 0) << u << "," << v;
        if (d.k1 == 0.0) {
          ASSERT_EQ(m.valid[i] != 0, u >= 37 && u <= 236 && v >= 101 && v <= 250) << u << "," << v;
        }
        valid += m.valid[i];
      }
    EXPECT_GT(valid, 150u * 150u);
  }
  CameraModel c = make_camera(kCases[0]);
  c.roi = PixelRegion{0, 0, 641, 100};
  EXPECT_THROW(compute_undistort_map(c), Error);
}

}  // namespace
}  // namespace planarvo
