// The honest-status check's measure (track/texture_residual.h): against OpenCV's filtering of the
// same images (an independent computation: filter2D with Immerkaer's mask, the valid mask eroded
// by 3 x 3), and its properties on synthetic images with known statistics: pure noise gives 1,
// matched texture leaves only the noise, unrelated textures give 1, a shifted texture (an alignment
// held while the floor moved) gives about 1, and what is smooth in the residual (a lamp's falloff
// left in it) does not count.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "track/texture_residual.h"

namespace planarvo::track {
namespace {

constexpr int kW = 160, kH = 120;

// A random texture with a correlation length of about `blur` pixels, standard deviation `sigma`.
cv::Mat texture(cv::RNG& rng, double sigma, double blur, int w = kW, int h = kH) {
  cv::Mat t(h, w, CV_64F);
  rng.fill(t, cv::RNG::NORMAL, 0.0, 1.0);
  if (blur > 0) cv::GaussianBlur(t, t, cv::Size(0, 0), blur);
  cv::Scalar mean, stddev;
  cv::meanStdDev(t, mean, stddev);
  return (t - mean[0]) * (sigma / stddev[0]);
}

cv::Mat noise(cv::RNG& rng, double sigma) {
  cv::Mat n(kH, kW, CV_64F);
  rng.fill(n, cv::RNG::NORMAL, 0.0, sigma);
  return n;
}

// The residual image r = live - ref (gain 1, bias 0), every pixel valid but those of `invalid`.
ResidualImage image(const cv::Mat& ref, const cv::Mat& live, const cv::Mat& invalid = cv::Mat()) {
  ResidualImage im;
  im.width = ref.cols;
  im.height = ref.rows;
  const size_t n = static_cast<size_t>(ref.cols) * static_cast<size_t>(ref.rows);
  im.residual.resize(n);
  im.weight.resize(n);
  im.intensity.resize(n);
  for (int y = 0; y < ref.rows; ++y)
    for (int x = 0; x < ref.cols; ++x) {
      const size_t i = static_cast<size_t>(y) * static_cast<size_t>(ref.cols) + static_cast<size_t>(x);
      const bool bad = !invalid.empty() && invalid.at<uchar>(y, x) != 0;
      im.residual[i] = bad ? 0.0f : static_cast<float>(live.at<double>(y, x) - ref.at<double>(y, x));
      im.weight[i] = bad ? 0.0f : 1.0f;
      im.intensity[i] = bad ? NAN : static_cast<float>(ref.at<double>(y, x));
    }
  return im;
}

// The reference: OpenCV's filter2D of the float images with the mask, means over the pixels whose
// 3 x 3 neighbourhood is valid (the valid mask eroded, the border excluded).
double reference(const ResidualImage& im) {
  cv::Mat r(im.height, im.width, CV_64F), i(im.height, im.width, CV_64F), valid(im.height, im.width, CV_8U);
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const size_t q = static_cast<size_t>(y) * static_cast<size_t>(im.width) + static_cast<size_t>(x);
      const bool v = im.weight[q] > 0.0f;
      r.at<double>(y, x) = im.residual[q];
      i.at<double>(y, x) = v ? im.intensity[q] : 0.0;
      valid.at<uchar>(y, x) = v ? 255 : 0;
    }
  const cv::Mat mask = (cv::Mat_<double>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat nr, ni, inner;
  cv::filter2D(r, nr, CV_64F, mask, cv::Point(-1, -1), 0, cv::BORDER_CONSTANT);
  cv::filter2D(i, ni, CV_64F, mask, cv::Point(-1, -1), 0, cv::BORDER_CONSTANT);
  cv::erode(valid, inner, cv::Mat::ones(3, 3, CV_8U), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  const cv::Rect border(1, 1, im.width - 2, im.height - 2);
  cv::Mat keep = cv::Mat::zeros(im.height, im.width, CV_8U);
  inner(border).copyTo(keep(border));
  return cv::mean(cv::abs(nr), keep)[0] / (std::sqrt(2.0) * cv::mean(cv::abs(ni), keep)[0]);
}

TEST(TextureResidual, MatchesOpenCvFilteringWithInvalidPixels) {
  cv::RNG rng(7);
  const cv::Mat ref = texture(rng, 20.0, 1.5) + 128.0;
  const cv::Mat live = ref + noise(rng, 2.0);
  cv::Mat invalid = cv::Mat::zeros(kH, kW, CV_8U);
  cv::circle(invalid, cv::Point(60, 50), 17, cv::Scalar(255), cv::FILLED);  // a saturated spot
  invalid.rowRange(100, kH).setTo(255);                                       // outside the overlap
  invalid.at<uchar>(10, 140) = 255;                                           // one bad pixel
  const ResidualImage im = image(ref, live, invalid);
  const double expected = reference(im);
  EXPECT_NEAR(texture_residual(im), expected, 1e-6 * expected);
  EXPECT_GT(expected, 0.0);
}

TEST(TextureResidual, PureNoiseIsOneAndMatchedTextureLeavesOnlyTheNoise) {
  cv::RNG rng(11);
  // Two frames of noise alone: r = n_l - n_r has sqrt(2) times the N response of either.
  EXPECT_NEAR(texture_residual(image(noise(rng, 3.0) + 100.0, noise(rng, 3.0) + 100.0)), 1.0, 0.03);
  // Matched texture with noise of standard deviation 1: the residual's N response is the noise's,
  // the keyframe's that of texture and noise together (independent: their N responses' mean
  // absolute values are those of Gaussians, which add in quadrature).
  const cv::Mat t = texture(rng, 10.0, 0.5);
  const cv::Mat n_ref = noise(rng, 1.0);
  const ResidualImage matched = image(t + n_ref + 100.0, t + noise(rng, 1.0) + 100.0);
  const ResidualImage noise_only = image(n_ref + 100.0, noise(rng, 1.0) + 100.0);
  // texture_residual(noise_only), about 1, times the noise's share of the keyframe's N response.
  const cv::Mat mask = (cv::Mat_<double>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat nt, nn;
  cv::filter2D(t, nt, CV_64F, mask);
  cv::filter2D(n_ref, nn, CV_64F, mask);
  const cv::Rect in(1, 1, kW - 2, kH - 2);
  cv::Scalar m, st, m2, sn;
  cv::meanStdDev(nt(in), m, st);
  cv::meanStdDev(nn(in), m2, sn);
  const double expected = texture_residual(noise_only) * sn[0] / std::hypot(st[0], sn[0]);
  EXPECT_NEAR(texture_residual(matched), expected, 0.05 * expected);
  EXPECT_LT(texture_residual(matched), 0.3);
}

TEST(TextureResidual, UnrelatedOrShiftedTextureIsAboutOne) {
  cv::RNG rng(13);
  const cv::Mat a = texture(rng, 15.0, 0.5) + 120.0, b = texture(rng, 15.0, 0.5) + 120.0;
  EXPECT_NEAR(texture_residual(image(a, b)), 1.0, 0.05);
  // The floor moved by 4 pixels while the alignment held at no motion: the live frame is the
  // keyframe's texture shifted (further than its correlation length).
  const cv::Mat wide = texture(rng, 15.0, 0.5, kW + 4, kH) + 120.0;
  const cv::Mat ref = wide.colRange(0, kW).clone(), live = wide.colRange(4, kW + 4).clone();
  const double held = texture_residual(image(ref, live + noise(rng, 1.0)));
  EXPECT_GT(held, 0.85);
  EXPECT_LT(held, 1.15);
}

TEST(TextureResidual, SmoothLightInTheResidualDoesNotCount) {
  cv::RNG rng(17);
  const cv::Mat t = texture(rng, 10.0, 1.0) + 100.0;
  const cv::Mat live = t + noise(rng, 1.0);
  // A falloff of the form f(x) + g(y) + c x y (N annihilates each) added to the live frame only:
  // what a lamp's falloff leaves when the frames are aligned on the floor.
  cv::Mat light(kH, kW, CV_64F);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      light.at<double>(y, x) = -40.0 * std::pow((x - 80.0) / 80.0, 2) - 30.0 * std::pow((y - 60.0) / 60.0, 2) +
                               0.01 * (x - 80.0) * (y - 60.0) + 5.0;
  EXPECT_NEAR(texture_residual(image(t, live + light)), texture_residual(image(t, live)), 1e-4);
}

TEST(TextureResidual, TooFewPixelsOrNoTextureIsNaN) {
  cv::RNG rng(19);
  const cv::Mat t = texture(rng, 10.0, 1.0) + 100.0;
  cv::Mat invalid(kH, kW, CV_8U, cv::Scalar(255));
  invalid(cv::Rect(20, 20, 5, 5)).setTo(0);  // 3 x 3 = 9 pixels with a valid neighbourhood
  EXPECT_TRUE(std::isnan(texture_residual(image(t, t, invalid))));
  const cv::Mat flat(kH, kW, CV_64F, cv::Scalar(90.0));
  EXPECT_TRUE(std::isnan(texture_residual(image(flat, flat + 1.0))));
}

}  // namespace
}  // namespace planarvo::track
