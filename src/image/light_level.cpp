#include "image/light_level.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/error.h"

namespace planarvo {

namespace {

void check(const cv::Mat& m, const cv::Mat& support, int r) {
  if (m.type() != CV_32FC1 || support.type() != CV_8UC1 || m.size() != support.size())
    throw_invalid_argument("light level: the level (CV_32FC1) and the support (CV_8UC1) of one size");
  if (r < 1) throw_invalid_argument("light level: the box's half-width must be >= 1");
}

// local_plane_level's fit, streamed row by row: the box sums (half-width r, clipped at the
// image's border) are running sums, first along each row, then down the columns, where each row
// is added when the box reaches it and subtracted when it leaves. Over a row the weight x is
// the pixel's own and y the row's, so five row sums (support 1, x, x^2; level m, m x) give the
// nine moments. Nothing of the image's size is held but the output (no large temporaries: at
// 640x480 those were a third of the time, in page faults). The support's sums are integers,
// exact in double.
cv::Mat fit_local_plane(const cv::Mat& m, const cv::Mat& support, int r) {
  const int w = m.cols, h = m.rows;
  const size_t W = static_cast<size_t>(w);
  enum { kV, kVx, kVxx, kM, kMx, kRowSums };
  enum { kS0, kSx, kSxx, kSy, kSyy, kSxy, kT0, kTx, kTy, kColumnSums };
  std::vector<double> rows(kRowSums * W), acc(kColumnSums * W, 0.0), vm(2 * W);
  // The five row sums of image row y into `rows`.
  auto row_sums = [&](int y) {
    const uint8_t* s = support.ptr<uint8_t>(y);
    const float* a = m.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      vm[static_cast<size_t>(x)] = s[x] ? 1.0 : 0.0;
      vm[W + static_cast<size_t>(x)] = s[x] ? static_cast<double>(a[x]) : 0.0;
    }
    double v = 0, vx = 0, vxx = 0, mm = 0, mx = 0;
    auto step = [&](int x, double sign) {
      const double fx = x, sv = sign * vm[static_cast<size_t>(x)], sm = sign * vm[W + static_cast<size_t>(x)];
      v += sv;
      vx += sv * fx;
      vxx += sv * fx * fx;
      mm += sm;
      mx += sm * fx;
    };
    for (int x = 0; x < std::min(r, w); ++x) step(x, 1.0);
    for (int x = 0; x < w; ++x) {
      if (x + r < w) step(x + r, 1.0);
      if (x - r - 1 >= 0) step(x - r - 1, -1.0);
      const size_t i = static_cast<size_t>(x);
      rows[kV * W + i] = v;
      rows[kVx * W + i] = vx;
      rows[kVxx * W + i] = vxx;
      rows[kM * W + i] = mm;
      rows[kMx * W + i] = mx;
    }
  };
  // Row y entering (sign 1) or leaving (-1) the column sums.
  auto column_step = [&](int y, double sign) {
    row_sums(y);
    const double fy = y, fyy = fy * fy;
    for (size_t i = 0; i < W; ++i) {
      const double v = sign * rows[kV * W + i], vx = sign * rows[kVx * W + i], mm = sign * rows[kM * W + i];
      acc[kS0 * W + i] += v;
      acc[kSx * W + i] += vx;
      acc[kSxx * W + i] += sign * rows[kVxx * W + i];
      acc[kSy * W + i] += fy * v;
      acc[kSyy * W + i] += fyy * v;
      acc[kSxy * W + i] += fy * vx;
      acc[kT0 * W + i] += mm;
      acc[kTx * W + i] += sign * rows[kMx * W + i];
      acc[kTy * W + i] += fy * mm;
    }
  };
  const double full = r * (r + 1) / 3.0;  // the full box's variance along each axis
  cv::Mat out(m.size(), CV_32FC1, cv::Scalar(0.0f));
  for (int y = 0; y < std::min(r, h); ++y) column_step(y, 1.0);
  for (int y = 0; y < h; ++y) {
    if (y + r < h) column_step(y + r, 1.0);
    if (y - r - 1 >= 0) column_step(y - r - 1, -1.0);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(x);
      const double n = acc[kS0 * W + i];
      if (!(n > 0.5)) continue;
      const double in = 1.0 / n;
      const double cx = acc[kSx * W + i] * in, cy = acc[kSy * W + i] * in;  // the support's centroid
      const double cuu = acc[kSxx * W + i] * in - cx * cx, cvv = acc[kSyy * W + i] * in - cy * cy,
                   cuv = acc[kSxy * W + i] * in - cx * cy;
      const double mean = acc[kT0 * W + i] * in;
      const double du = acc[kTx * W + i] * in - mean * cx, dv = acc[kTy * W + i] * in - mean * cy;
      const double det = cuu * cvv - cuv * cuv;
      double value = mean;
      // A plane where the support spreads over at least a tenth of the box's extent each way.
      if (det > 0.01 * full * full && cuu > 0.01 * full && cvv > 0.01 * full) {
        const double gu = (cvv * du - cuv * dv) / det, gv = (cuu * dv - cuv * du) / det;
        value = mean + gu * (x - cx) + gv * (y - cy);
      }
      o[x] = static_cast<float>(value);
    }
  }
  return out;
}

}  // namespace

cv::Mat local_plane_level(const cv::Mat& m, const cv::Mat& support, int r) {
  check(m, support, r);
  return fit_local_plane(m, support, r);
}

// The box (half-width r) blurs the level by r (r + 1) / 6 times its Laplacian: the simulator's
// reflection (sigma 45 pixels, 150 grey levels) 6-7 grey levels too faint at its peak, the
// lamp's falloff too flat at its centre. After the step only the fourth-order term is left
// inside the image, the second-order one at its border.
cv::Mat settled_light_level(const cv::Mat& mean, const cv::Mat& support, int r) {
  check(mean, support, r);
  const cv::Mat p = fit_local_plane(mean, support, r);
  const cv::Mat pp = fit_local_plane(p, support, r);
  cv::Mat out = p.clone();
  for (int y = 0; y < mean.rows; ++y) {
    const float *a = p.ptr<float>(y), *b = pp.ptr<float>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < mean.cols; ++x) {
      const float s = 2.0f * a[x] - b[x];
      if (b[x] > 0 && s > 0.5f * a[x]) o[x] = s;
    }
  }
  return out;
}

}  // namespace planarvo
