// The image pipeline's plain C++ reference (the definition the kernels are tested against)
// against independent computations: OpenCV's separable filter on a replicate-padded image for
// the pyramid step, exact answers for a linear ramp (pixel-centre geometry of pyramid.h, slopes
// of the gradients), and the validity rules.
#include <cmath>
#include <random>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <gtest/gtest.h>

#include "core/error.h"
#include "image/pipeline.h"

namespace planarvo {
namespace {

// Random intensities 0..255 with invalid blobs and isolated invalid pixels.
cv::Mat random_level(int w, int h, uint32_t seed, double invalid_fraction = 0.02) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(0.0f, 255.0f);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  cv::Mat m(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      m.at<float>(y, x) = unit(rng) < invalid_fraction ? kInvalidIntensity : value(rng);
  const int blobs = 1 + (w * h) / 4000;
  for (int b = 0; b < blobs; ++b) {
    const cv::Point c(static_cast<int>(unit(rng) * w), static_cast<int>(unit(rng) * h));
    cv::circle(m, c, 1 + static_cast<int>(unit(rng) * 6), cv::Scalar(kInvalidIntensity), cv::FILLED);
  }
  return m;
}

CameraModel pinhole(int w, int h) {
  CameraModel c;
  c.width = w;
  c.height = h;
  c.fx = c.fy = 0.8 * w;
  c.cx = 0.5 * w - 0.5;
  c.cy = 0.5 * h - 0.5;
  return c;
}

TEST(ImagePipelineReference, UndistortIsRemapWithInvalidMarked) {
  CameraModel cam = pinhole(97, 61);
  cam.k1 = 0.2;  // pincushion: the corners have no source
  const UndistortMap map = compute_undistort_map(cam);
  cv::Mat gray(61, 97, CV_8UC1);
  cv::randu(gray, 0, 256);
  const cv::Mat out = undistort_reference(gray, map), remap = remap_bilinear(gray, map);
  ASSERT_EQ(out.type(), CV_32FC1);
  size_t invalid = 0;
  for (int v = 0; v < 61; ++v)
    for (int u = 0; u < 97; ++u) {
      if (map.valid[static_cast<size_t>(v) * 97 + static_cast<size_t>(u)]) {
        EXPECT_EQ(out.at<float>(v, u), remap.at<float>(v, u));
      } else {
        EXPECT_EQ(out.at<float>(v, u), kInvalidIntensity);
        ++invalid;
      }
    }
  EXPECT_GT(invalid, 50u);
}

// The pyramid step: OpenCV's separable [1 5 10 10 5 1] / 32 filter, in double, on the image
// padded by replication (which is what clamping the taps means), sampled at (2u - 2, 2v - 2) of
// the unpadded image; validity by a dilation of the invalid mask over the same window.
TEST(ImagePipelineReference, DownsampleMatchesOpenCVFilterOnAReplicatedBorder) {
  const int sizes[][2] = {{1, 1}, {2, 3}, {5, 4}, {17, 9}, {64, 48}, {97, 61}};
  uint32_t seed = 1;
  for (const auto& s : sizes) {
    SCOPED_TRACE(std::to_string(s[0]) + "x" + std::to_string(s[1]));
    const cv::Mat level = random_level(s[0], s[1], seed++, 0.005);
    const cv::Mat out = downsample_reference(level);
    ASSERT_EQ(out.cols, (s[0] + 1) / 2);
    ASSERT_EQ(out.rows, (s[1] + 1) / 2);

    const int pad = 3;
    cv::Mat values, invalid, padded_values, padded_invalid;
    level.convertTo(values, CV_64F);
    invalid = level < 0.0f;  // 255 where invalid
    invalid.convertTo(invalid, CV_64F);
    cv::copyMakeBorder(values, padded_values, pad, pad, pad, pad, cv::BORDER_REPLICATE);
    cv::copyMakeBorder(invalid, padded_invalid, pad, pad, pad, pad, cv::BORDER_REPLICATE);
    const cv::Mat k = (cv::Mat_<double>(6, 1) << 1, 5, 10, 10, 5, 1) / 32.0;
    const cv::Mat ones = cv::Mat::ones(6, 1, CV_64F);
    cv::Mat filtered, any_invalid;
    // Anchor (0, 0): filtered(y, x) = sum over i, j of k(i) k(j) padded(y + i, x + j).
    cv::sepFilter2D(padded_values, filtered, CV_64F, k, k, cv::Point(0, 0), 0, cv::BORDER_CONSTANT);
    cv::sepFilter2D(padded_invalid, any_invalid, CV_64F, ones, ones, cv::Point(0, 0), 0,
                    cv::BORDER_CONSTANT);
    int invalid_outputs = 0;
    for (int v = 0; v < out.rows; ++v)
      for (int u = 0; u < out.cols; ++u) {
        const int y = 2 * v - 2 + pad, x = 2 * u - 2 + pad;
        const float o = out.at<float>(v, u);
        if (any_invalid.at<double>(y, x) > 0.5) {
          EXPECT_EQ(o, kInvalidIntensity) << u << "," << v;
          ++invalid_outputs;
        } else {
          EXPECT_NEAR(o, filtered.at<double>(y, x), 1e-4) << u << "," << v;
        }
      }
    if (s[0] * s[1] > 1000) {
      EXPECT_GT(invalid_outputs, 0);
    }
  }
}

// The prefilter: OpenCV's cv::GaussianBlur with a 3 x 3 kernel and sigma 0 (OpenCV's fixed
// [1 2 1] / 4 kernel for that size), in double, border replicated (clamped taps); validity by a
// 3 x 3 dilation of the invalid mask. It also damps pixel noise as a [1 2 1] / 4 binomial must:
// independent noise's variance falls to (6/16)^2 of its value.
TEST(ImagePipelineReference, SmoothMatchesOpenCVGaussianOnAReplicatedBorder) {
  const int sizes[][2] = {{1, 1}, {2, 3}, {5, 4}, {17, 9}, {64, 48}, {97, 61}};
  uint32_t seed = 31;
  for (const auto& s : sizes) {
    SCOPED_TRACE(std::to_string(s[0]) + "x" + std::to_string(s[1]));
    const cv::Mat level = random_level(s[0], s[1], seed++, 0.005);
    const cv::Mat out = smooth_reference(level);
    ASSERT_EQ(out.size(), level.size());
    cv::Mat values, invalid, blurred, any_invalid;
    level.convertTo(values, CV_64F);
    invalid = level < 0.0f;
    invalid.convertTo(invalid, CV_64F);
    cv::GaussianBlur(values, blurred, cv::Size(3, 3), 0, 0, cv::BORDER_REPLICATE);
    cv::dilate(invalid, any_invalid, cv::Mat::ones(3, 3, CV_8U), cv::Point(-1, -1), 1,
               cv::BORDER_REPLICATE);
    int invalid_outputs = 0;
    for (int v = 0; v < out.rows; ++v)
      for (int u = 0; u < out.cols; ++u) {
        const float o = out.at<float>(v, u);
        if (any_invalid.at<double>(v, u) > 0.5) {
          EXPECT_EQ(o, kInvalidIntensity) << u << "," << v;
          ++invalid_outputs;
        } else {
          EXPECT_NEAR(o, blurred.at<double>(v, u), 1e-4) << u << "," << v;
        }
      }
    if (s[0] * s[1] > 1000) {
      EXPECT_GT(invalid_outputs, 0);
    }
  }
  cv::Mat noise(200, 200, CV_32FC1);
  cv::RNG(5).fill(noise, cv::RNG::NORMAL, 100.0, 10.0);
  cv::Scalar mean, sd_in, sd_out;
  cv::meanStdDev(noise, mean, sd_in);
  cv::meanStdDev(smooth_reference(noise)(cv::Rect(1, 1, 198, 198)), mean, sd_out);
  EXPECT_NEAR(sd_out[0] / sd_in[0], 6.0 / 16.0, 0.02);
}

// A linear ramp stays linear through the pyramid, with its value at the pixel centres of
// pyramid.h: level-l pixel (u, v) at level-0 (2^l (u + 0.5) - 0.5, ...); and the gradients are
// the slope, 2^l grey levels per level-l pixel per level-0 slope. Exactly, away from the borders:
// the slopes and offset are dyadic, so every sum is exact in float.
TEST(ImagePipelineReference, LinearRampKeepsPixelCentresAndSlopes) {
  const int w = 200, h = 150, levels = 4;
  const double a = 0.5, b = 0.75, c = 3.0;  // at most 3 + 99.5 + 111.75 grey levels
  cv::Mat intensity(h, w, CV_32FC1);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) intensity.at<float>(v, u) = static_cast<float>(a * u + b * v + c);
  for (int l = 0; l < levels; ++l) {
    SCOPED_TRACE("level " + std::to_string(l));
    if (l > 0) intensity = downsample_reference(intensity);
    const cv::Mat m = gradient_reference(intensity);
    ASSERT_EQ(m.type(), CV_32FC4);
    ASSERT_EQ(m.cols, level_size(w, l));
    ASSERT_EQ(m.rows, level_size(h, l));
    const double s = 1 << l;
    // Clamped taps bend the ramp within 1, 2, 2 pixels of the borders of levels 1, 2, 3 (here);
    // the gradient needs one pixel more.
    const int margin = l == 0 ? 1 : 3;
    int checked = 0;
    for (int v = margin; v < m.rows - margin; ++v)
      for (int u = margin; u < m.cols - margin; ++u) {
        const cv::Vec4f p = m.at<cv::Vec4f>(v, u);
        const double u0 = s * (u + 0.5) - 0.5, v0 = s * (v + 0.5) - 0.5;
        ASSERT_EQ(p[0], static_cast<float>(a * u0 + b * v0 + c)) << u << "," << v;
        ASSERT_EQ(p[1], static_cast<float>(a * s)) << u << "," << v;
        ASSERT_EQ(p[2], static_cast<float>(b * s)) << u << "," << v;
        ASSERT_EQ(p[3], 1.0f);
        ++checked;
      }
    EXPECT_GT(checked, 100);
  }
}

TEST(ImagePipelineReference, GradientValidityAndBorders) {
  cv::Mat level(5, 6, CV_32FC1);
  for (int v = 0; v < 5; ++v)
    for (int u = 0; u < 6; ++u) level.at<float>(v, u) = static_cast<float>(u * u + 10 * v);
  level.at<float>(2, 3) = kInvalidIntensity;
  const cv::Mat g = gradient_reference(level);
  for (int v = 0; v < 5; ++v)
    for (int u = 0; u < 6; ++u) {
      const cv::Vec4f p = g.at<cv::Vec4f>(v, u);
      const bool border = u == 0 || v == 0 || u == 5 || v == 4;
      const bool near_hole = std::abs(u - 3) + std::abs(v - 2) <= 1;
      if (border || near_hole) {
        EXPECT_EQ(p, cv::Vec4f(0, 0, 0, 0)) << u << "," << v;
      } else {
        EXPECT_EQ(p[0], level.at<float>(v, u));
        EXPECT_EQ(p[1], static_cast<float>(((u + 1) * (u + 1) - (u - 1) * (u - 1)) / 2.0));
        EXPECT_EQ(p[2], 10.0f);
        EXPECT_EQ(p[3], 1.0f);
      }
    }
  // A diagonal neighbour does not count: (2, 1) and (4, 3) touch the hole only diagonally.
  EXPECT_EQ(g.at<cv::Vec4f>(1, 2)[3], 1.0f);
  EXPECT_EQ(g.at<cv::Vec4f>(3, 4)[3], 1.0f);
}

TEST(ImagePipelineReference, LevelSizesRoundUp) {
  const UndistortMap map = compute_undistort_map(pinhole(643, 479));
  const cv::Mat gray(479, 643, CV_8UC1, cv::Scalar(100));
  const std::vector<cv::Mat> pyr = pipeline_reference(gray, map, 4);
  const int expected[][2] = {{643, 479}, {322, 240}, {161, 120}, {81, 60}};
  for (size_t l = 0; l < 4; ++l) {
    EXPECT_EQ(pyr[l].cols, expected[l][0]);
    EXPECT_EQ(pyr[l].rows, expected[l][1]);
  }
}

TEST(ImagePipelineReference, RejectsBadArguments) {
  const UndistortMap map = compute_undistort_map(pinhole(16, 12));
  EXPECT_THROW(pipeline_reference(cv::Mat(12, 16, CV_8UC1, cv::Scalar(0)), map, 0), Error);
  EXPECT_THROW(pipeline_reference(cv::Mat(12, 16, CV_32FC1, cv::Scalar(0)), map, 2), Error);
  EXPECT_THROW(pipeline_reference(cv::Mat(12, 17, CV_8UC1, cv::Scalar(0)), map, 2), Error);
  EXPECT_THROW(downsample_reference(cv::Mat(12, 16, CV_8UC1)), Error);
  EXPECT_THROW(gradient_reference(cv::Mat()), Error);
}

}  // namespace
}  // namespace planarvo
