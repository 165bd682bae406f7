// The simulator's camera response: smooth bounded gain and offset, Gaussian noise of the
// requested size, rounding and clamping, determinism.
#include <cmath>

#include <gtest/gtest.h>

#include "sim/simulator.h"

namespace planarvo::sim {
namespace {

TEST(SimCamera, ExposureIsSmoothAndBounded) {
  Options o;
  o.gain_variation = 0.05;
  std::vector<double> t;
  for (int k = 0; k < 3000; ++k) t.push_back(k / 30.0);
  const std::vector<Exposure> e = exposure_series(o, t);
  ASSERT_EQ(e.size(), t.size());
  double gmin = 2, gmax = 0;
  for (size_t k = 0; k < e.size(); ++k) {
    EXPECT_LE(std::abs(e[k].gain - 1.0), 0.05 + 1e-12);
    EXPECT_LE(std::abs(e[k].offset), 3.0 + 1e-12);
    if (k > 0) {
      // Periods of at least 3 s: at most 2 pi / 3 * amplitude per second.
      EXPECT_LE(std::abs(e[k].gain - e[k - 1].gain), 0.05 * 2 * M_PI / 3 / 30 + 1e-12);
      EXPECT_LE(std::abs(e[k].offset - e[k - 1].offset), 3.0 * 2 * M_PI / 3 / 30 + 1e-12);
    }
    gmin = std::min(gmin, e[k].gain);
    gmax = std::max(gmax, e[k].gain);
  }
  EXPECT_GT(gmax - gmin, 0.02);  // it does change over 100 s
  o.gain_variation = 0;
  for (const Exposure& x : exposure_series(o, t)) {
    EXPECT_EQ(x.gain, 1.0);
    EXPECT_EQ(x.offset, 0.0);
  }
  // Deterministic for a seed, different for another.
  o.gain_variation = 0.05;
  EXPECT_EQ(exposure_series(o, t)[100].gain, e[100].gain);
  o.seed = 2;
  EXPECT_NE(exposure_series(o, t)[100].gain, e[100].gain);
}

TEST(SimCamera, NoiseHasTheRequestedSizeAndNoBias) {
  const cv::Mat clean(200, 300, CV_32FC1, cv::Scalar(100.25));
  const cv::Mat img = apply_camera(clean, Exposure{1.1, -2.0}, 3.0, 17);
  ASSERT_EQ(img.type(), CV_8UC1);
  cv::Mat f;
  img.convertTo(f, CV_64F);
  cv::Scalar mean, sd;
  cv::meanStdDev(f, mean, sd);
  // 1.1 * 100.25 - 2 = 108.275; rounding adds 1/12 to the variance.
  EXPECT_NEAR(mean[0], 108.275, 0.05);
  EXPECT_NEAR(sd[0], std::sqrt(9.0 + 1.0 / 12), 0.05);
  // Same seed, same image; another seed, another.
  EXPECT_EQ(cv::norm(img, apply_camera(clean, Exposure{1.1, -2.0}, 3.0, 17), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(img, apply_camera(clean, Exposure{1.1, -2.0}, 3.0, 18), cv::NORM_INF), 0.0);
}

TEST(SimCamera, RoundsAndClamps) {
  cv::Mat clean(1, 6, CV_32FC1);
  const float v[] = {-20.f, 0.49f, 0.51f, 127.5f, 254.6f, 400.f};
  for (int i = 0; i < 6; ++i) clean.at<float>(0, i) = v[i];
  const cv::Mat img = apply_camera(clean, Exposure{}, 0.0, 1);
  const int want[] = {0, 0, 1, 128, 255, 255};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(img.at<uint8_t>(0, i), want[i]) << i;
}

}  // namespace
}  // namespace planarvo::sim
