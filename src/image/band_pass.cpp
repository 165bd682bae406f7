#include "image/band_pass.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "ocl/runtime.h"

namespace planarvo {

namespace {
// A pixel whose Gaussian window holds less valid weight than this has no mean worth taking out
// (an image corner holds a quarter).
constexpr float kMinValidWeight = 0.05f;
}  // namespace

double band_pass_sigma(double sigma0, int level) { return std::max(1.5, sigma0 / static_cast<double>(1 << level)); }

cv::Mat band_pass_level(const cv::Mat& level, double sigma) {
  if (level.type() != CV_32FC4) throw_invalid_argument("band_pass_level: the level must be CV_32FC4");
  if (!(sigma > 0.0) || !std::isfinite(sigma)) throw_invalid_argument("band_pass_level: sigma must be positive");
  const int w = level.cols, h = level.rows;
  cv::Mat I(h, w, CV_32FC1), V(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y) {
    const cv::Vec4f* s = level.ptr<cv::Vec4f>(y);
    float* i = I.ptr<float>(y);
    float* v = V.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      v[x] = s[x][3] > 0.0f ? 1.0f : 0.0f;
      i[x] = s[x][3] > 0.0f ? s[x][0] : 0.0f;
    }
  }
  cv::Mat mi, mv;
  cv::GaussianBlur(I, mi, cv::Size(0, 0), sigma, sigma, cv::BORDER_CONSTANT);
  cv::GaussianBlur(V, mv, cv::Size(0, 0), sigma, sigma, cv::BORDER_CONSTANT);
  cv::Mat B(h, w, CV_32FC1, cv::Scalar(0.0f)), ok(h, w, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (V.at<float>(y, x) > 0.0f && mv.at<float>(y, x) > kMinValidWeight) {
        B.at<float>(y, x) = I.at<float>(y, x) - mi.at<float>(y, x) / mv.at<float>(y, x) + 128.0f;
        ok.at<uint8_t>(y, x) = 1;
      }
  cv::Mat out(h, w, CV_32FC4, cv::Scalar::all(0.0));
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      if (!ok.at<uint8_t>(y, x) || !ok.at<uint8_t>(y, x - 1) || !ok.at<uint8_t>(y, x + 1) ||
          !ok.at<uint8_t>(y - 1, x) || !ok.at<uint8_t>(y + 1, x))
        continue;
      out.at<cv::Vec4f>(y, x) = cv::Vec4f(B.at<float>(y, x), 0.5f * (B.at<float>(y, x + 1) - B.at<float>(y, x - 1)),
                                          0.5f * (B.at<float>(y + 1, x) - B.at<float>(y - 1, x)), 1.0f);
    }
  return out;
}

void band_pass(ocl::Runtime& runtime, Pyramid& pyramid, double sigma0) {
  for (int l = 0; l < pyramid.num_levels(); ++l) {
    PyramidLevel& L = pyramid.levels[static_cast<size_t>(l)];
    cv::Mat level(L.height, L.width, CV_32FC4);
    const size_t bytes = level.total() * level.elemSize();
    runtime.queue().enqueueReadBuffer(L.data, CL_TRUE, 0, bytes, level.data);
    const cv::Mat out = band_pass_level(level, band_pass_sigma(sigma0, l));
    runtime.queue().enqueueWriteBuffer(L.data, CL_TRUE, 0, bytes, out.data);
  }
}

}  // namespace planarvo
