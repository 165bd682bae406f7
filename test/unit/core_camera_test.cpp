// The camera model against OpenCV, which defines it (conventions.md): the forward model against
// cv::projectPoints, the inverse against cv::undistortPoints run to convergence, and the inverse
// as an inverse (distort(undistort(x)) == x).
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <gtest/gtest.h>

#include "core/camera.h"

namespace planarvo {
namespace {

struct DistortionCase {
  const char* name;
  double k1, k2, p1, p2, k3;
};

// Barrel, pincushion, tangential, with k3, and a strong barrel. With the camera below the image
// corners are at a distorted radius of ~0.8 (normalised), where every case is still invertible
// (the radial map r -> r (1 + k1 r^2 + k2 r^4 + k3 r^6) rises past 0.8 before it turns back):
// a real lens's calibration has that property over its image.
const DistortionCase kCases[] = {
    {"barrel", -0.28, 0.07, 0.0, 0.0, 0.0},
    {"pincushion", 0.15, 0.02, 0.0, 0.0, 0.0},
    {"tangential", -0.05, 0.01, 0.002, -0.0015, 0.0},
    {"with_k3", -0.3, 0.12, 0.0008, 0.0005, -0.025},
    {"strong_barrel", -0.38, 0.16, 0.001, -0.001, -0.03},
};

CameraModel make_camera(const DistortionCase& d) {
  CameraModel c;
  c.width = 640;
  c.height = 480;
  c.fx = 500.0;
  c.fy = 502.5;
  c.cx = 318.4;
  c.cy = 243.7;
  c.k1 = d.k1;
  c.k2 = d.k2;
  c.p1 = d.p1;
  c.p2 = d.p2;
  c.k3 = d.k3;
  return c;
}

cv::Mat K_of(const CameraModel& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}
cv::Mat D_of(const CameraModel& c) {
  return (cv::Mat_<double>(1, 5) << c.k1, c.k2, c.p1, c.p2, c.k3);
}

TEST(ImageCamera, ProjectMatchesCvProjectPoints) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(0.2, 5.0);
  for (const DistortionCase& d : kCases) {
    SCOPED_TRACE(d.name);
    const CameraModel cam = make_camera(d);
    std::vector<cv::Point3d> points;
    for (int i = 0; i < 500; ++i) {
      const double z = depth(rng);
      // Rays within about +-45 degrees: the field of view the cases are realistic for.
      points.emplace_back(u(rng) * z * 0.9, u(rng) * z * 0.7, z);
    }
    std::vector<cv::Point2d> cv_pixels;
    cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K_of(cam), D_of(cam), cv_pixels);
    double worst = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector2d p = cam.project(Eigen::Vector3d(points[i].x, points[i].y, points[i].z));
      worst = std::max({worst, std::abs(p.x() - cv_pixels[i].x), std::abs(p.y() - cv_pixels[i].y)});
    }
    EXPECT_LT(worst, 1e-9) << "pixels";
  }
}

// Distorted pixels over the whole image, on a grid.
std::vector<cv::Point2d> image_grid(const CameraModel& cam, int step) {
  std::vector<cv::Point2d> px;
  for (int v = 0; v < cam.height; v += step)
    for (int u = 0; u < cam.width; u += step) px.emplace_back(u + 0.25, v + 0.75);
  px.emplace_back(cam.width - 1.0, cam.height - 1.0);
  px.emplace_back(0.0, 0.0);
  return px;
}

TEST(ImageCamera, UndistortIsTheInverseOfDistort) {
  for (const DistortionCase& d : kCases) {
    SCOPED_TRACE(d.name);
    const CameraModel cam = make_camera(d);
    double worst = 0.0;
    for (const cv::Point2d& p : image_grid(cam, 8)) {
      const Eigen::Vector2d xd((p.x - cam.cx) / cam.fx, (p.y - cam.cy) / cam.fy);
      const Eigen::Vector2d xu = cam.undistort(xd);
      worst = std::max(worst, (cam.distort(xu) - xd).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst, 1e-10) << "normalised units";
  }
}

// cv::undistortPoints by default stops after 5 fixed-point iterations, which leaves errors of
// up to pixels in the corners with strong distortion: not a reference. Given an iteration
// budget it converges (linearly, by a factor of roughly |d distortion / d x| < 1 per step) to
// the same solution; with 200 iterations and a 1e-14 pixel criterion both are at machine
// precision (they agree to ~4e-16 here), so 1e-12 normalised units (5e-10 px) leaves room for
// rounding only, not for a different model.
TEST(ImageCamera, UnprojectMatchesCvUndistortPointsRunToConvergence) {
  for (const DistortionCase& d : kCases) {
    SCOPED_TRACE(d.name);
    const CameraModel cam = make_camera(d);
    const std::vector<cv::Point2d> pixels = image_grid(cam, 16);
    std::vector<cv::Point2d> cv_norm;
    cv::undistortPoints(pixels, cv_norm, K_of(cam), D_of(cam), cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-14));
    double worst = 0.0;
    for (size_t i = 0; i < pixels.size(); ++i) {
      const Eigen::Vector2d n = cam.unproject(Eigen::Vector2d(pixels[i].x, pixels[i].y));
      worst = std::max({worst, std::abs(n.x() - cv_norm[i].x), std::abs(n.y() - cv_norm[i].y)});
    }
    EXPECT_LT(worst, 1e-12) << "normalised units";
  }
}

TEST(ImageCamera, ProjectOfUnprojectIsIdentity) {
  for (const DistortionCase& d : kCases) {
    SCOPED_TRACE(d.name);
    const CameraModel cam = make_camera(d);
    double worst = 0.0;
    for (const cv::Point2d& p : image_grid(cam, 20)) {
      const Eigen::Vector2d n = cam.unproject(Eigen::Vector2d(p.x, p.y));
      const Eigen::Vector2d back = cam.project(Eigen::Vector3d(n.x() * 2.0, n.y() * 2.0, 2.0));
      worst = std::max({worst, std::abs(back.x() - p.x), std::abs(back.y() - p.y)});
    }
    EXPECT_LT(worst, 1e-8) << "pixels";
  }
}

}  // namespace
}  // namespace planarvo
