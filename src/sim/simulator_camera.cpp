// The simulator's camera response: slow smooth gain and offset changes, additive Gaussian
// noise, 8-bit quantisation. Deterministic for a seed on every platform.
#include <array>
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "sim/simulator.h"

namespace planarvo::sim {

namespace {

// A smooth random curve in [-1, 1]: three slow sinusoids with random periods (3 to 20 s),
// phases and weights summing to one.
struct SmoothCurve {
  std::array<double, 3> weight{}, omega{}, phase{};
  explicit SmoothCurve(Random& rng) {
    double sum = 0.0;
    for (size_t i = 0; i < 3; ++i) {
      weight[i] = rng.uniform(0.2, 1.0);
      sum += weight[i];
      omega[i] = 2.0 * M_PI / rng.uniform(3.0, 20.0);
      phase[i] = rng.uniform(0.0, 2.0 * M_PI);
    }
    for (double& w : weight) w /= sum;
  }
  double operator()(double t) const {
    double s = 0.0;
    for (size_t i = 0; i < 3; ++i) s += weight[i] * std::sin(omega[i] * t + phase[i]);
    return s;
  }
};

}  // namespace

std::vector<Exposure> exposure_series(const Options& options, const std::vector<double>& t) {
  Random rng(derive_seed(options.seed, 3));
  const SmoothCurve gain(rng), offset(rng);
  const double a = options.gain_variation;
  std::vector<Exposure> out(t.size());
  for (size_t k = 0; k < t.size(); ++k) {
    out[k].gain = 1.0 + a * gain(t[k]);
    out[k].offset = 60.0 * a * offset(t[k]);
  }
  return out;
}

Lighting camera_lighting(const Options& options) {
  Lighting l;
  if (options.lamp_falloff == 0.0 && options.reflection == 0.0 && options.shadow == 0.0) return l;
  const int w = options.camera.width, h = options.camera.height;
  l.gain = cv::Mat(h, w, CV_32FC1, cv::Scalar(1.0f));
  l.add = cv::Mat(h, w, CV_32FC1, cv::Scalar(0.0f));
  // The lamp: (1 + rho^2)^(-3/2), rho = distance from the lamp's centre / s, s such that the
  // farthest corner gets 1 - f.
  const double lx = 0.58 * (w - 1), ly = 0.42 * (h - 1);
  double corner = 0.0;
  for (double cx : {0.0, w - 1.0})
    for (double cy : {0.0, h - 1.0}) corner = std::max(corner, std::hypot(cx - lx, cy - ly));
  const double f = options.lamp_falloff;
  // (1 + (corner/s)^2)^(-3/2) = 1 - f  <=>  (corner/s)^2 = (1 - f)^(-2/3) - 1.
  const double rho2_corner = f > 0.0 ? std::pow(1.0 - f, -2.0 / 3.0) - 1.0 : 0.0;
  const double inv_s2 = rho2_corner / (corner * corner);
  const double sx = 0.45 * (w - 1), sy = 0.62 * (h - 1), ss = 0.07 * w;
  // The shadow's edge: the line through (0, 0.75 h) and (w, 0.68 h); below it is shadowed.
  const double ex0 = 0.75 * h, ex1 = 0.68 * h, edge = 6.0;
  for (int r = 0; r < h; ++r) {
    float* g = l.gain.ptr<float>(r);
    float* a = l.add.ptr<float>(r);
    for (int c = 0; c < w; ++c) {
      const double d2 = (c - lx) * (c - lx) + (r - ly) * (r - ly);
      double gain = std::pow(1.0 + d2 * inv_s2, -1.5);
      if (options.shadow > 0.0) {
        const double line = ex0 + (ex1 - ex0) * c / w;
        const double below = 0.5 * (1.0 + std::tanh((r - line) / (0.5 * edge)));
        gain *= 1.0 - options.shadow * below;
      }
      g[c] = static_cast<float>(gain);
      if (options.reflection > 0.0) {
        const double q2 = ((c - sx) * (c - sx) + (r - sy) * (r - sy)) / (ss * ss);
        a[c] = static_cast<float>(options.reflection *
                                  (std::exp(-0.5 * q2) + std::exp(-0.5 * q2 / 9.0) / 3.0));
      }
    }
  }
  return l;
}

void apply_lighting(const Lighting& lighting, cv::Mat& image) {
  if (lighting.empty()) return;
  if (image.type() != CV_32FC1 || image.size() != lighting.gain.size())
    throw_invalid_argument("apply_lighting: needs a CV_32FC1 image of the lighting's size");
  cv::multiply(image, lighting.gain, image);
  image += lighting.add;
}

double farthest_ground_view(const CameraModel& camera, const Extrinsics& extrinsics, Eigen::Vector2d* pixel) {
  const Eigen::Matrix3d R = extrinsics.R_vc();
  double farthest = 0.0;
  Eigen::Vector2d at(0.0, 0.0);
  auto look = [&](double u, double v) {
    const Eigen::Vector2d xn = camera.unproject(Eigen::Vector2d(u, v));
    const Eigen::Vector3d d = R * Eigen::Vector3d(xn.x(), xn.y(), 1.0);
    // The ray meets the ground (z = 0, the camera at height z > 0) when it points down.
    const double reach = d.z() < 0.0 ? std::hypot(d.x(), d.y()) / -d.z() : HUGE_VAL;
    if (!(reach <= farthest)) {
      farthest = reach;
      at = {u, v};
    }
  };
  // The border of the region of interest (the whole image by default): a line of the ground is
  // a line of the undistorted image, so the farthest ground point and the horizon a rectangle of
  // pixels sees are on its border (up to the lens distortion's bending).
  for_each_border_pixel(camera.region(), 1, look);
  if (pixel) *pixel = at;
  return farthest;
}

cv::Mat apply_camera(const cv::Mat& image, const Exposure& exposure, double sigma,
                     uint64_t frame_seed) {
  if (image.type() != CV_32FC1) throw_invalid_argument("apply_camera: needs a CV_32FC1 image");
  cv::Mat out(image.size(), CV_8UC1);
  Random rng(frame_seed);
  for (int r = 0; r < image.rows; ++r) {
    const float* src = image.ptr<float>(r);
    uint8_t* dst = out.ptr<uint8_t>(r);
    for (int c = 0; c < image.cols; ++c) {
      double v = exposure.gain * src[c] + exposure.offset;
      if (sigma > 0) v += sigma * rng.normal();
      v = std::floor(v + 0.5);
      dst[c] = static_cast<uint8_t>(v < 0.0 ? 0.0 : (v > 255.0 ? 255.0 : v));
    }
  }
  return out;
}

}  // namespace planarvo::sim
