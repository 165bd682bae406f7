// The noise's share in the gradients (src/image/gradient_noise.h), checked by Monte Carlo through
// the device pipeline: frames of pure noise under a known flat field whose corrected noise
// variance grows exponentially along u (so d log sigma^2 / du is the same everywhere). Over the
// frames, the level's noise n and its plain central-difference gradient (recomputed here from the
// level's intensities) correlate as E[n grad_u n] / E[n^2] = c_l d log sigma^2/du, the
// coefficient gradient_noise_coefficient derives from the filter chain; the pipeline's
// gradients, with the share taken out, do not correlate. Also: the kernel against its plain C++
// reference, and the coefficient's known values.
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "image/gradient_noise.h"
#include "image/photometric.h"
#include "image/pipeline.h"
#include "ocl/runtime.h"

namespace planarvo {
namespace {

TEST(GradientNoise, CoefficientOfTheFilterChain) {
  // Level 0 with the 3-tap prefilter: E[n grad n] = (1/8)(3/8) dsigma^2, E[n^2] = (3/8)^2 sigma^2
  // (worked by hand in gradient_noise.h's terms): 1/3. Unsmoothed, the central difference does
  // not see its own pixel: 0.
  EXPECT_NEAR(gradient_noise_coefficient(0, true), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(gradient_noise_coefficient(0, false), 0.0, 1e-12);
  // Each level's pixel spans twice the last's: the coefficient (per level-0 pixel) about doubles.
  for (int l = 1; l < 5; ++l) {
    const double r = gradient_noise_coefficient(l, true) / gradient_noise_coefficient(l - 1, true);
    EXPECT_GT(r, 1.7) << "level " << l;
    EXPECT_LT(r, 2.1) << "level " << l;
  }
  EXPECT_THROW(gradient_noise_coefficient(-1, true), Error);
}

TEST(GradientNoise, BetaFollowsTheLogOfTheVariance) {
  // sigma^2 = exp(k u): beta_u = c_l k everywhere (level pixels' central differences of the
  // area-averaged log, exact for a linear log), beta_v = 0.
  const int w = 96, h = 64;
  const double k = 0.01;
  cv::Mat shape(h, w, CV_32FC1);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) shape.at<float>(v, u) = static_cast<float>(std::exp(k * u));
  shape.at<float>(10, 10) = 0.0f;  // no value: takes a neighbour's
  const std::vector<cv::Mat> beta = gradient_noise_beta(shape, 3, true);
  ASSERT_EQ(beta.size(), 3u);
  for (int l = 0; l < 3; ++l) {
    ASSERT_EQ(beta[l].cols, level_size(w, l));
    ASSERT_EQ(beta[l].rows, level_size(h, l));
    const cv::Vec2f b = beta[l].at<cv::Vec2f>(beta[l].rows / 2, beta[l].cols / 2);
    EXPECT_NEAR(b[0], gradient_noise_coefficient(l, true) * k, 1e-6) << "level " << l;
    EXPECT_NEAR(b[1], 0.0, 1e-6) << "level " << l;
  }
  EXPECT_THROW(gradient_noise_beta(cv::Mat(4, 4, CV_32FC1, cv::Scalar(0.0f)), 1, true), Error);
  EXPECT_THROW(gradient_noise_beta(shape, 0, true), Error);
}

TEST(GradientNoise, KernelMatchesReference) {
  ocl::Runtime rt;
  const ImagePipelineOptions options;
  PipelineKernels kernels(rt, options);
  const int w = 83, h = 37;  // not a multiple of the 8 pixels a work-item makes
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> value(0.0f, 255.0f), small(-0.05f, 0.05f);
  cv::Mat level(h, w, CV_32FC1), beta(h, w, CV_32FC2);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      level.at<float>(v, u) = (u * 7 + v * 3) % 41 == 0 ? kInvalidIntensity : value(rng);
      beta.at<cv::Vec2f>(v, u) = cv::Vec2f(small(rng), small(rng));
    }
  const float mean = 117.0f;
  cl::Buffer src(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, level.total() * sizeof(float), level.ptr());
  cl::Buffer b(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, beta.total() * 2 * sizeof(float), beta.ptr());
  std::vector<float> poison(4 * level.total() + 64, -77777.0f);
  cl::Buffer dst(rt.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, poison.size() * sizeof(float), poison.data());
  kernels.gradient_decorrelated(src, w, h, b, mean, dst);
  std::vector<float> out(poison.size());
  rt.queue().enqueueReadBuffer(dst, CL_TRUE, 0, out.size() * sizeof(float), out.data());
  const cv::Mat ref = decorrelated_gradient_reference(level, beta, mean);
  size_t off = 0;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u)
      for (int c = 0; c < 4; ++c) {
        const float a = out[4 * (static_cast<size_t>(v) * w + u) + c], r = ref.at<cv::Vec4f>(v, u)[c];
        off += !(std::abs(a - r) <= 1e-3f);
      }
  EXPECT_EQ(off, 0u);
  for (size_t i = 4 * level.total(); i < out.size(); ++i) ASSERT_EQ(out[i], -77777.0f) << "written past the end";
  // Some valid pixel was changed by beta (the reference is not the plain gradient).
  EXPECT_GT(cv::norm(ref, gradient_reference(level), cv::NORM_INF), 0.01);
}

// Sums over frames and pixels of n grad n and n^2 per level, n the level's intensity less its
// (known) mean, for the plain central difference and for the pipeline's gradient.
struct Correlation {
  double plain = 0, pipeline = 0, square = 0;
  long count = 0;
};

TEST(GradientNoise, PipelineGradientsNoLongerCorrelateWithTheNoise) {
  ocl::Runtime rt;
  const int w = 192, h = 144, levels = 3, frames = 600;
  CameraModel cam;
  cam.width = w;
  cam.height = h;
  cam.fx = cam.fy = 150.0;
  cam.cx = 0.5 * (w - 1);
  cam.cy = 0.5 * (h - 1);
  ImagePipelineOptions options;
  options.photometric.enabled = true;
  options.photometric.learn = false;
  ImagePipeline pipe(rt, cam, levels, options);
  // The light falls off exponentially along u, from 1 to 0.35 (above the model's min_contrast,
  // so every pixel has a value): the corrected noise's variance grows as exp(k u),
  // k = 2 ln(1 / 0.35) / (w - 1).
  const double k = 2.0 * std::log(1.0 / 0.35) / (w - 1);
  cv::Mat gain(h, w, CV_32FC1), valid(h, w, CV_8UC1, cv::Scalar(255));
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) gain.at<float>(v, u) = static_cast<float>(std::exp(-0.5 * k * u));
  pipe.photometric()->set(flat_field_photometric(gain, valid, options.photometric));
  const double mean_level = 110.0, sigma = 6.0;  // raw grey levels: far from 0 and white
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<Correlation> corr(levels);
  Pyramid out;
  for (int f = 0; f < frames; ++f) {
    cv::Mat raw(h, w, CV_8UC1);
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u)
        raw.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(std::lround(mean_level * gain.at<float>(v, u) + noise(rng)));
    pipe.process(raw, out);
    const std::vector<cv::Mat> lv = download_pyramid(rt, out);
    for (int l = 0; l < levels; ++l) {
      const cv::Mat& m = lv[static_cast<size_t>(l)];
      // The corrected mean is the flat field's reference level times the raw mean.
      const double mu = mean_level;
      for (int v = 2; v < m.rows - 2; ++v)
        for (int u = 2; u < m.cols - 2; ++u) {
          const cv::Vec4f p = m.at<cv::Vec4f>(v, u);
          // The level's layout zeroes a pixel whose own neighbours are not all valid: the plain
          // difference needs both of its neighbours' intensities.
          if (p[3] == 0.0f || m.at<cv::Vec4f>(v, u + 1)[3] == 0.0f || m.at<cv::Vec4f>(v, u - 1)[3] == 0.0f) continue;
          const double n = p[0] - mu;
          const double plain = 0.5 * (m.at<cv::Vec4f>(v, u + 1)[0] - m.at<cv::Vec4f>(v, u - 1)[0]);
          corr[static_cast<size_t>(l)].plain += n * plain;
          corr[static_cast<size_t>(l)].pipeline += n * p[1];
          corr[static_cast<size_t>(l)].square += n * n;
          ++corr[static_cast<size_t>(l)].count;
        }
    }
  }
  for (int l = 0; l < levels; ++l) {
    const Correlation& c = corr[static_cast<size_t>(l)];
    // The coefficient is per unit of d log sigma^2 over a level-0 pixel; the gradient is the
    // level's central difference.
    const double predicted = gradient_noise_coefficient(l, true) * k;
    const double plain = c.plain / c.square, taken_out = c.pipeline / c.square;
    // The ratio's sampling error: n grad n has a standard deviation of about 0.4 E[n^2] per
    // sample, and a level's samples are correlated over about 3 x 3 pixels (the smoothing): about
    // 1.2 / sqrt(N) for the ratio; the bound is 2 / sqrt(N), plus 12 % of the prediction (the
    // coefficient is first order in the variance's slope).
    const double tol = 2.0 / std::sqrt(static_cast<double>(c.count));
    EXPECT_NEAR(plain, predicted, 0.12 * predicted + tol) << "level " << l;
    EXPECT_NEAR(taken_out, 0.0, 0.12 * predicted + tol) << "level " << l;
    EXPECT_GT(predicted, 3.0 * tol) << "level " << l << ": the test cannot tell the two apart";
    std::printf("level %d: E[n grad n]/E[n^2] plain %.5f (predicted %.5f), taken out %.5f, +- %.5f\n", l, plain,
                predicted, taken_out, tol);
  }
}

}  // namespace
}  // namespace planarvo
