// The light's level (image/light_level.h) against fields whose level is known: a plane is
// reproduced exactly at the image's border and beside holes, where a box's mean is off by the
// slope times the valid pixels' offset; a quadratic is reproduced inside the image to the
// fourth-order term, where a box's mean is off by its variance times the curvature.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "image/light_level.h"

namespace planarvo {
namespace {

constexpr int kW = 200, kH = 150, kR = 8;

cv::Mat field(double c, double gx, double gy, double gxx, double gyy) {
  cv::Mat f(kH, kW, CV_32FC1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double u = x - 0.5 * kW, v = y - 0.5 * kH;
      f.at<float>(y, x) = static_cast<float>(c + gx * u + gy * v + gxx * u * u + gyy * v * v);
    }
  return f;
}

// A support with a hole (a disc) and a missing strip along the left border.
cv::Mat holed_support() {
  cv::Mat s(kH, kW, CV_8UC1, cv::Scalar(1));
  cv::circle(s, cv::Point(120, 70), 12, cv::Scalar(0), cv::FILLED);
  s(cv::Rect(0, 0, 5, kH)).setTo(0);
  return s;
}

// The box's mean over the supported pixels (what the model's young level is).
cv::Mat box_mean(const cv::Mat& m, const cv::Mat& support, int r) {
  cv::Mat v, num, den;
  support.convertTo(v, CV_32F);
  cv::boxFilter(m.mul(v), num, CV_32F, cv::Size(2 * r + 1, 2 * r + 1), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  cv::boxFilter(v, den, CV_32F, cv::Size(2 * r + 1, 2 * r + 1), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  return num / den;
}

// Largest |a - truth| over the supported pixels.
double worst(const cv::Mat& a, const cv::Mat& truth, const cv::Mat& support) {
  double w = 0.0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (support.at<uint8_t>(y, x)) w = std::max(w, std::abs(static_cast<double>(a.at<float>(y, x)) - truth.at<float>(y, x)));
  return w;
}

TEST(LightLevel, APlaneIsExactAtTheBorderAndBesideHoles) {
  const cv::Mat truth = field(100.0, 0.3, -0.2, 0.0, 0.0);
  const cv::Mat support = holed_support();
  const cv::Mat p = local_plane_level(truth, support, kR);
  EXPECT_LT(worst(p, truth, support), 1e-3);
  // Unsupported pixels whose box holds supported ones get the plane too (they are only left out
  // of the fit); the hole's centre, whose box holds none, gets 0.
  EXPECT_NEAR(p.at<float>(70, 130), truth.at<float>(70, 130), 1e-3);
  EXPECT_EQ(p.at<float>(70, 120), 0.0f);
  // The box's mean: off by the slope times up to half the box at the border.
  EXPECT_GT(worst(box_mean(truth, support, kR), truth, support), 0.3 * kR / 2.0);
  EXPECT_LT(worst(settled_light_level(truth, support, kR), truth, support), 1e-3);
}

TEST(LightLevel, ACurvedLevelIsSharpenedInside) {
  // The lamp's falloff near its centre: a paraboloid falling by 30 % from the centre to the
  // image's edge.
  const cv::Mat truth = field(200.0, 0.0, 0.0, -0.006, -0.006);
  const cv::Mat support(kH, kW, CV_8UC1, cv::Scalar(1));
  cv::Mat inside = cv::Mat::zeros(kH, kW, CV_8UC1);
  inside(cv::Rect(2 * kR, 2 * kR, kW - 4 * kR, kH - 4 * kR)).setTo(1);
  // The box's mean is off by its variance r (r + 1) / 3 times the curvature along each axis:
  // 0.29 grey levels.
  const double box_error = worst(box_mean(truth, support, kR), truth, inside);
  EXPECT_NEAR(box_error, 2.0 * kR * (kR + 1) / 3.0 * 0.006, 0.01);
  // A quadratic's fourth derivatives vanish: the sharpened level is exact inside.
  EXPECT_LT(worst(settled_light_level(truth, support, kR), truth, inside), 0.01 * box_error);
  // ... and at the border the plane's second-order term is left, less than the box's.
  EXPECT_LT(worst(settled_light_level(truth, support, kR), truth, support), box_error);
}

// The least-squares plane over each box, summed pixel by pixel in double (centred moments): the
// reference for local_plane_level's running sums, on a level with no structure (every pixel
// its own value), a support with holes and borders, and boxes wider than the image.
cv::Mat brute_force_plane(const cv::Mat& m, const cv::Mat& support, int r) {
  cv::Mat out(m.size(), CV_32FC1, cv::Scalar(0.0f));
  const double full = r * (r + 1) / 3.0;
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x) {
      double n = 0, sx = 0, sy = 0, sm = 0;
      auto each = [&](auto f) {
        for (int v = std::max(0, y - r); v <= std::min(m.rows - 1, y + r); ++v)
          for (int u = std::max(0, x - r); u <= std::min(m.cols - 1, x + r); ++u)
            if (support.at<uint8_t>(v, u)) f(u, v, static_cast<double>(m.at<float>(v, u)));
      };
      each([&](int u, int v, double a) {
        n += 1;
        sx += u;
        sy += v;
        sm += a;
      });
      if (n < 0.5) continue;
      const double cx = sx / n, cy = sy / n, mean = sm / n;
      double cuu = 0, cvv = 0, cuv = 0, du = 0, dv = 0;
      each([&](int u, int v, double a) {
        cuu += (u - cx) * (u - cx) / n;
        cvv += (v - cy) * (v - cy) / n;
        cuv += (u - cx) * (v - cy) / n;
        du += (a - mean) * (u - cx) / n;
        dv += (a - mean) * (v - cy) / n;
      });
      const double det = cuu * cvv - cuv * cuv;
      double value = mean;
      if (det > 0.01 * full * full && cuu > 0.01 * full && cvv > 0.01 * full)
        value = mean + ((cvv * du - cuv * dv) * (x - cx) + (cuu * dv - cuv * du) * (y - cy)) / det;
      out.at<float>(y, x) = static_cast<float>(value);
    }
  return out;
}

TEST(LightLevel, TheRunningSumsAreTheLeastSquaresPlaneOfEachBox) {
  cv::RNG rng(5);
  for (const int r : {1, 3, 8, 40}) {
    cv::Mat m(37, 29, CV_32FC1);
    rng.fill(m, cv::RNG::UNIFORM, 0.0, 255.0);
    cv::Mat support(m.size(), CV_8UC1);
    rng.fill(support, cv::RNG::UNIFORM, 0, 4);  // a quarter of the pixels left out
    support(cv::Rect(0, 0, 29, 3)).setTo(0);  // no support along the top
    const cv::Mat ref = brute_force_plane(m, support, r);
    EXPECT_LT(cv::norm(local_plane_level(m, support, r), ref, cv::NORM_INF), 1e-3) << "r " << r;
  }
}

TEST(LightLevel, BadInputIsRefused) {
  const cv::Mat m(10, 10, CV_32FC1, cv::Scalar(1.0f));
  EXPECT_THROW(local_plane_level(m, cv::Mat(10, 10, CV_32FC1), 2), Error);
  EXPECT_THROW(local_plane_level(m, cv::Mat(9, 10, CV_8UC1), 2), Error);
  EXPECT_THROW(settled_light_level(m, cv::Mat(10, 10, CV_8UC1, cv::Scalar(1)), 0), Error);
}

}  // namespace
}  // namespace planarvo
