// The band-pass of a pyramid level (image/band_pass.h) against what it is defined to do, computed
// independently: a smooth field is taken out, a fine texture kept, the mean taken over valid
// pixels only, gradients the central differences of its own output.
#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "image/band_pass.h"

namespace planarvo {
namespace {

constexpr int kW = 96, kH = 80;
constexpr double kSigma = 2.5;
constexpr double kPi = 3.14159265358979323846;

// A level (pyramid.h's layout) of intensity f(x, y), every pixel valid, gradients left 0 (the
// band-pass computes its own).
template <class F>
cv::Mat level_of(F f) {
  cv::Mat m(kH, kW, CV_32FC4);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) m.at<cv::Vec4f>(y, x) = cv::Vec4f(static_cast<float>(f(x, y)), 0, 0, 1);
  return m;
}

// Pixels at least 4 sigma from the border (where the Gaussian's support is whole).
bool interior(int x, int y) {
  const int b = static_cast<int>(std::ceil(4 * kSigma));
  return x >= b && y >= b && x < kW - b && y < kH - b;
}

double texture(int x, int y) { return 12.0 * std::sin(2 * kPi * x / 4.0) + 9.0 * std::cos(2 * kPi * y / 4.0); }

TEST(BandPass, TakesOutASmoothFieldAndKeepsAFineTexture) {
  // A linear light ramp plus the floor's mean level: the symmetric mean reproduces it exactly.
  const cv::Mat ramp = band_pass_level(level_of([](int x, int y) { return 100.0 + 0.9 * x - 0.6 * y; }), kSigma);
  // A texture of period 4 pixels: a Gaussian of sigma 2.5 keeps exp(-2 pi^2 sigma^2 / 16) = 5e-4
  // of it in the mean, so it passes with that fraction lost.
  const cv::Mat tex = band_pass_level(level_of([](int x, int y) { return 100.0 + texture(x, y); }), kSigma);
  // Both together: the ramp gone, the texture left.
  const cv::Mat both =
      band_pass_level(level_of([](int x, int y) { return 100.0 + 0.9 * x - 0.6 * y + texture(x, y); }), kSigma);
  int checked = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if (!interior(x, y)) continue;
      ++checked;
      ASSERT_EQ(ramp.at<cv::Vec4f>(y, x)[3], 1.0f);
      EXPECT_NEAR(ramp.at<cv::Vec4f>(y, x)[0], 128.0, 1e-3) << x << "," << y;
      EXPECT_NEAR(ramp.at<cv::Vec4f>(y, x)[1], 0.0, 1e-3);
      EXPECT_NEAR(ramp.at<cv::Vec4f>(y, x)[2], 0.0, 1e-3);
      EXPECT_NEAR(tex.at<cv::Vec4f>(y, x)[0], 128.0 + texture(x, y), 0.02) << x << "," << y;
      EXPECT_NEAR(both.at<cv::Vec4f>(y, x)[0], 128.0 + texture(x, y), 0.02) << x << "," << y;
    }
  EXPECT_GT(checked, 1000);
}

TEST(BandPass, GradientsAreCentralDifferencesOfItsOutput) {
  const cv::Mat out = band_pass_level(
      level_of([](int x, int y) { return 80.0 + 0.01 * x * y + texture(x, y) * std::cos(0.05 * x); }), kSigma);
  // (Pixels one in from the border are valid but their outer neighbour is not, and holds 0.)
  for (int y = 2; y + 2 < kH; ++y)
    for (int x = 2; x + 2 < kW; ++x) {
      const cv::Vec4f p = out.at<cv::Vec4f>(y, x);
      ASSERT_EQ(p[3], 1.0f) << x << "," << y;
      EXPECT_NEAR(p[1], 0.5 * (out.at<cv::Vec4f>(y, x + 1)[0] - out.at<cv::Vec4f>(y, x - 1)[0]), 1e-4);
      EXPECT_NEAR(p[2], 0.5 * (out.at<cv::Vec4f>(y + 1, x)[0] - out.at<cv::Vec4f>(y - 1, x)[0]), 1e-4);
    }
  // The outermost pixels have no central difference: not valid.
  EXPECT_EQ(out.at<cv::Vec4f>(1, 1)[3], 1.0f);
  EXPECT_EQ(out.at<cv::Vec4f>(0, 10)[3], 0.0f);
  EXPECT_EQ(out.at<cv::Vec4f>(10, kW - 1)[3], 0.0f);
}

TEST(BandPass, TheMeanIsOverValidPixelsOnly) {
  // A constant floor with a hole whose (invalid) pixels hold garbage: the normalised mean of a
  // constant is the constant wherever a valid pixel is, so the output is 128 there; the hole and
  // its gradient neighbours are not valid.
  cv::Mat in = level_of([](int, int) { return 90.0; });
  for (int y = 30; y < 40; ++y)
    for (int x = 40; x < 52; ++x) in.at<cv::Vec4f>(y, x) = cv::Vec4f(1000.0f, 50.0f, -50.0f, 0.0f);
  const cv::Mat out = band_pass_level(in, kSigma);
  for (int y = 1; y + 1 < kH; ++y)
    for (int x = 1; x + 1 < kW; ++x) {
      const bool hole = y >= 30 && y < 40 && x >= 40 && x < 52;
      const bool beside = y >= 29 && y < 41 && x >= 39 && x < 53;
      const cv::Vec4f p = out.at<cv::Vec4f>(y, x);
      if (hole) {
        EXPECT_EQ(p, cv::Vec4f(0, 0, 0, 0)) << x << "," << y;
      } else if (!beside) {
        ASSERT_EQ(p[3], 1.0f) << x << "," << y;
        EXPECT_NEAR(p[0], 128.0, 1e-3) << x << "," << y;
      }
    }
  EXPECT_EQ(out.at<cv::Vec4f>(35, 39)[3], 0.0f);  // its right neighbour is in the hole
  EXPECT_EQ(out.at<cv::Vec4f>(41, 45)[3], 1.0f);  // diagonal neighbours do not count
}

TEST(BandPass, SigmaPerLevelAndBadInput) {
  EXPECT_DOUBLE_EQ(band_pass_sigma(2.5, 0), 2.5);
  EXPECT_DOUBLE_EQ(band_pass_sigma(2.5, 1), 1.5);  // never below 1.5 level pixels
  EXPECT_DOUBLE_EQ(band_pass_sigma(8.0, 2), 2.0);
  EXPECT_THROW(band_pass_level(cv::Mat(4, 4, CV_32FC1), 2.0), Error);
  EXPECT_THROW(band_pass_level(cv::Mat(4, 4, CV_32FC4), 0.0), Error);
  EXPECT_THROW(band_pass_level(cv::Mat(4, 4, CV_32FC4), NAN), Error);
}

}  // namespace
}  // namespace planarvo
