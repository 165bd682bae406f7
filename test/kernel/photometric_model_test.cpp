// The photometric model's refit in the background (PhotometricModel::start_refit, take_refit):
// the model it takes into use is fit_photometric of the statistics as they were when it started
// (not of what was learnt after), the same as the blocking refit(); the model in use does not
// change until it is taken; reset() drops it.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "image/photometric.h"
#include "ocl/runtime.h"

namespace planarvo {
namespace {

constexpr int kW = 160, kH = 120;

// A lamp's falloff over a texture: the per-pixel mean and mean square of `frames` frames.
struct Statistics {
  cv::Mat mean, square;
};

Statistics lamp_statistics(double strength, unsigned seed) {
  cv::Mat texture(kH, kW, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(texture, cv::RNG::UNIFORM, 60.0, 180.0);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);
  Statistics s;
  s.mean.create(kH, kW, CV_32FC1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double r2 = (std::pow(x - 0.5 * kW, 2) + std::pow(y - 0.5 * kH, 2)) / (0.25 * kW * kW);
      s.mean.at<float>(y, x) = static_cast<float>(texture.at<float>(y, x) * (1.0 - strength * r2 / (1.0 + r2)));
    }
  s.square = s.mean.mul(s.mean) + 30.0f;
  return s;
}

void write_statistics(ocl::Runtime& rt, PhotometricModel& model, const Statistics& s) {
  const size_t bytes = static_cast<size_t>(kW) * kH * sizeof(float);
  rt.queue().enqueueWriteBuffer(model.statistics(), CL_TRUE, 0, bytes, s.mean.ptr<float>());
  rt.queue().enqueueWriteBuffer(model.statistics(), CL_TRUE, bytes, bytes, s.square.ptr<float>());
}

double max_difference(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

TEST(PhotometricModel, ARefitInTheBackgroundFitsTheStatisticsOfItsStart) {
  ocl::Runtime rt;
  const cv::Mat valid(kH, kW, CV_8UC1, cv::Scalar(255));
  PhotometricModel model(rt, valid, PhotometricOptions());
  for (int k = 0; k < 2 * kPhotometricSettledFrames; ++k) model.next_alpha();
  const Statistics lamp = lamp_statistics(0.5, 7), other = lamp_statistics(0.2, 8);
  write_statistics(rt, model, lamp);
  ASSERT_TRUE(model.refit_due());
  const long revision = model.revision();
  model.start_refit();
  EXPECT_TRUE(model.refit_pending());
  EXPECT_FALSE(model.refit_due());  // a started refit counts as the last fit
  // What is learnt after the start does not enter it; the model in use is unchanged until taken.
  write_statistics(rt, model, other);
  EXPECT_TRUE(model.fit().identity);
  EXPECT_EQ(model.revision(), revision);
  EXPECT_TRUE(model.take_refit());
  EXPECT_FALSE(model.refit_pending());
  EXPECT_FALSE(model.take_refit());
  EXPECT_EQ(model.revision(), revision + 1);
  const PhotometricFit expected = fit_photometric(lamp.mean, lamp.square, valid, model.frames(), PhotometricOptions());
  ASSERT_FALSE(expected.identity);
  EXPECT_FALSE(model.fit().identity);
  EXPECT_EQ(max_difference(model.fit().scale, expected.scale), 0.0);
  EXPECT_EQ(max_difference(model.fit().offset, expected.offset), 0.0);
  // The blocking refit of the statistics now in the buffer: the other lamp's model.
  model.next_alpha();
  model.refit();
  const PhotometricFit now = fit_photometric(other.mean, other.square, valid, model.frames(), PhotometricOptions());
  EXPECT_EQ(max_difference(model.fit().scale, now.scale), 0.0);
}

TEST(PhotometricModel, ResetDropsARefitInTheBackground) {
  ocl::Runtime rt;
  const cv::Mat valid(kH, kW, CV_8UC1, cv::Scalar(255));
  PhotometricModel model(rt, valid, PhotometricOptions());
  for (int k = 0; k < 2 * kPhotometricSettledFrames; ++k) model.next_alpha();
  write_statistics(rt, model, lamp_statistics(0.5, 9));
  model.start_refit();
  model.reset();
  EXPECT_FALSE(model.refit_pending());
  EXPECT_FALSE(model.take_refit());
  EXPECT_TRUE(model.fit().identity);
  EXPECT_EQ(model.frames(), 0);
  // A model destroyed with a refit pending waits for it (nothing left running on freed memory:
  // AddressSanitizer's run of this test would say).
  for (int k = 0; k < 2 * kPhotometricSettledFrames; ++k) model.next_alpha();
  model.start_refit();
}

}  // namespace
}  // namespace planarvo
