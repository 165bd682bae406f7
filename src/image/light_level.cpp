#include "image/light_level.h"

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace planarvo {

namespace {

void check(const cv::Mat& m, const cv::Mat& support, int r) {
  if (m.type() != CV_32FC1 || support.type() != CV_8UC1 || m.size() != support.size())
    throw_invalid_argument("light level: the level (CV_32FC1) and the support (CV_8UC1) of one size");
  if (r < 1) throw_invalid_argument("light level: the box's half-width must be >= 1");
}

// local_plane_level's fit. The moments of the support are the same for every image fitted
// (settled_light_level fits two), so they are made once.
class LocalPlane {
 public:
  LocalPlane(const cv::Mat& support, int r) : k_(2 * r + 1, 2 * r + 1), r_(r) {
    const int w = support.cols, h = support.rows;
    support.convertTo(v_, CV_64F);
    cv::threshold(v_, v_, 0.5, 1.0, cv::THRESH_BINARY);
    x_.create(h, w, CV_64FC1);
    y_.create(h, w, CV_64FC1);
    for (int y = 0; y < h; ++y) {
      double* xr = x_.ptr<double>(y);
      double* yr = y_.ptr<double>(y);
      for (int x = 0; x < w; ++x) {
        xr[x] = x;
        yr[x] = y;
      }
    }
    const cv::Mat vx = v_.mul(x_), vy = v_.mul(y_);
    s0_ = box(v_);
    sx_ = box(vx);
    sy_ = box(vy);
    sxx_ = box(vx.mul(x_));
    syy_ = box(vy.mul(y_));
    sxy_ = box(vx.mul(y_));
  }

  // The fitted level at every pixel whose box holds a supported pixel; 0 elsewhere.
  cv::Mat fit(const cv::Mat& m) const {
    cv::Mat M;
    m.convertTo(M, CV_64F);
    M = M.mul(v_);
    const cv::Mat t0 = box(M), tx = box(M.mul(x_)), ty = box(M.mul(y_));
    const double full = r_ * (r_ + 1) / 3.0;  // the full box's variance along each axis
    cv::Mat out(m.size(), CV_32FC1, cv::Scalar(0.0f));
    for (int y = 0; y < m.rows; ++y) {
      const double *n0 = s0_.ptr<double>(y), *nx = sx_.ptr<double>(y), *ny = sy_.ptr<double>(y),
                   *nxx = sxx_.ptr<double>(y), *nyy = syy_.ptr<double>(y), *nxy = sxy_.ptr<double>(y),
                   *m0 = t0.ptr<double>(y), *mx = tx.ptr<double>(y), *my = ty.ptr<double>(y);
      float* o = out.ptr<float>(y);
      for (int x = 0; x < m.cols; ++x) {
        const double n = n0[x];
        if (!(n > 0.5)) continue;
        const double cx = nx[x] / n, cy = ny[x] / n;  // the support's centroid
        const double cuu = nxx[x] / n - cx * cx, cvv = nyy[x] / n - cy * cy, cuv = nxy[x] / n - cx * cy;
        const double mean = m0[x] / n;
        const double du = mx[x] / n - mean * cx, dv = my[x] / n - mean * cy;
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

 private:
  cv::Mat box(const cv::Mat& a) const {
    cv::Mat out;
    cv::boxFilter(a, out, CV_64F, k_, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    return out;
  }
  cv::Size k_;
  int r_;
  cv::Mat v_, x_, y_, s0_, sx_, sy_, sxx_, syy_, sxy_;
};

}  // namespace

cv::Mat local_plane_level(const cv::Mat& m, const cv::Mat& support, int r) {
  check(m, support, r);
  return LocalPlane(support, r).fit(m);
}

// The box (half-width r) blurs the level by r (r + 1) / 6 times its Laplacian: the simulator's
// reflection (sigma 45 pixels, 150 grey levels) 6-7 grey levels too faint at its peak, the
// lamp's falloff too flat at its centre. After the step only the fourth-order term is left
// inside the image, the second-order one at its border.
cv::Mat settled_light_level(const cv::Mat& mean, const cv::Mat& support, int r) {
  check(mean, support, r);
  const LocalPlane plane(support, r);
  const cv::Mat p = plane.fit(mean);
  const cv::Mat pp = plane.fit(p);
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
