// The noise's share in a level's gradient (gradient_noise.h).
#include "image/gradient_noise.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "image/photometric.h"
#include "image/pipeline.h"
#include "image/pyramid.h"

namespace planarvo {

namespace {

// A 1-D kernel over level-0 pixel offsets.
using Kernel1 = std::map<int, double>;

double at(const Kernel1& a, int k) {
  const auto it = a.find(k);
  return it == a.end() ? 0.0 : it->second;
}

// The kernel of a level-`level` pixel at the origin: the prefilter (or none), then per level the
// downsampling's taps j = -2 .. 3 at level-(l) pixels 2u + j (kernels/image/pyramid.cl).
Kernel1 chain_kernel(int level, bool prefilter) {
  Kernel1 a = prefilter ? Kernel1{{-1, 0.25}, {0, 0.5}, {1, 0.25}} : Kernel1{{0, 1.0}};
  static const double d[6] = {1 / 32.0, 5 / 32.0, 10 / 32.0, 10 / 32.0, 5 / 32.0, 1 / 32.0};
  for (int l = 0; l < level; ++l) {
    Kernel1 next;
    for (int j = -2; j <= 3; ++j)
      for (const auto& [k, v] : a) next[k + j * (1 << l)] += d[j + 2] * v;
    a = std::move(next);
  }
  return a;
}

}  // namespace

double gradient_noise_coefficient(int level, bool prefilter) {
  if (level < 0 || level >= kMaxPyramidLevels)
    throw_invalid_argument("gradient_noise_coefficient: level must be 0.." + std::to_string(kMaxPyramidLevels - 1));
  const Kernel1 a = chain_kernel(level, prefilter);
  const int s = 1 << level;
  // E[L(u) (L(u+1) - L(u-1)) / 2] = sum_k a(k) (a(k - s) - a(k + s)) sigma^2(k) / 2: with
  // sigma^2(k) = sigma^2 + k dsigma^2, the constant part sums to 0 (the kernel's symmetry of
  // shifts), the slope's is the coefficient; over E[L^2] = sum_k a(k)^2 sigma^2. The other
  // axis's factor, sum a^2, is in both and cancels.
  double num = 0.0, den = 0.0;
  for (const auto& [k, v] : a) {
    num += 0.5 * k * v * (at(a, k - s) - at(a, k + s));
    den += v * v;
  }
  return num / den;
}

cv::Mat corrected_noise_shape(const cv::Mat& scale) {
  if (scale.type() != CV_32FC1) throw_invalid_argument("corrected_noise_shape: the scale must be CV_32FC1");
  return scale.mul(scale);  // 0 where the scale is: gradient_noise_beta fills it
}

std::vector<cv::Mat> gradient_noise_beta(const cv::Mat& variance_shape, int levels, bool prefilter) {
  if (variance_shape.type() != CV_32FC1 || variance_shape.empty())
    throw_invalid_argument("gradient_noise_beta: the variance's shape must be a non-empty CV_32FC1 image");
  if (levels < 1 || levels > kMaxPyramidLevels)
    throw_invalid_argument("gradient_noise_beta: levels must be 1.." + std::to_string(kMaxPyramidLevels));
  cv::Mat shape = variance_shape.clone();
  shape.setTo(0.0f, ~(shape > 0.0f));  // NaN and negatives have no value either
  if (cv::countNonZero(shape) == 0)
    throw_invalid_argument("gradient_noise_beta: the variance's shape has no positive pixel");
  cv::Mat log_var;
  cv::log(fill_flat_field(shape), log_var);
  const int w0 = shape.cols, h0 = shape.rows;
  std::vector<cv::Mat> out;
  cv::Mat lv = log_var;
  for (int l = 0; l < levels; ++l) {
    const int w = level_size(w0, l), h = level_size(h0, l);
    // The level's pixel is the mean of the finer level's 2 x 2 block (the downsampling's centre).
    if (l > 0) cv::resize(lv, lv, cv::Size(w, h), 0, 0, cv::INTER_AREA);
    // d log sigma^2 per level-0 pixel: central differences in level pixels (one-sided at the
    // border), over 2^l.
    const double c = gradient_noise_coefficient(l, prefilter) / static_cast<double>(1 << l);
    cv::Mat beta(h, w, CV_32FC2);
    for (int v = 0; v < h; ++v) {
      const float* row = lv.ptr<float>(v);
      const float* up = lv.ptr<float>(std::max(v - 1, 0));
      const float* down = lv.ptr<float>(std::min(v + 1, h - 1));
      const double dv = std::min(v + 1, h - 1) - std::max(v - 1, 0);
      cv::Vec2f* b = beta.ptr<cv::Vec2f>(v);
      for (int u = 0; u < w; ++u) {
        const int ul = std::max(u - 1, 0), ur = std::min(u + 1, w - 1);
        const double gu = ur > ul ? (row[ur] - row[ul]) / static_cast<double>(ur - ul) : 0.0;
        const double gv = dv > 0 ? (down[u] - up[u]) / dv : 0.0;
        b[u] = cv::Vec2f(static_cast<float>(c * gu), static_cast<float>(c * gv));
      }
    }
    out.push_back(beta);
  }
  return out;
}

cv::Mat decorrelated_gradient_reference(const cv::Mat& level, const cv::Mat& beta, float mean) {
  if (beta.type() != CV_32FC2 || beta.size() != level.size())
    throw_invalid_argument("decorrelated_gradient_reference: beta must be CV_32FC2 of the level's size");
  cv::Mat out = gradient_reference(level);
  for (int v = 0; v < out.rows; ++v) {
    cv::Vec4f* o = out.ptr<cv::Vec4f>(v);
    const cv::Vec2f* b = beta.ptr<cv::Vec2f>(v);
    for (int u = 0; u < out.cols; ++u) {
      if (o[u][3] == 0.0f) continue;
      const float d = o[u][0] - mean;
      o[u][1] -= b[u][0] * d;
      o[u][2] -= b[u][1] * d;
    }
  }
  return out;
}

}  // namespace planarvo
