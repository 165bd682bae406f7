// The simulator's camera response: slow smooth gain and offset changes, additive Gaussian
// noise, 8-bit quantisation. Deterministic for a seed on every platform.
#include <array>
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
