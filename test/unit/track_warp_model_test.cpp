// The tracker's motion model (track/warp_model.h) against independent computations: the
// analytic derivatives of the homography against central differences of ground_homography,
// the reference-side generators against the composition of planar motions, and the homography
// of a motion against projecting ground points with the camera.
#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/body_attitude.h"
#include "core/extrinsics.h"
#include "core/se2.h"
#include "sim/simulator.h"
#include "track/warp_model.h"

namespace planarvo::track {
namespace {

constexpr double kDeg = M_PI / 180.0;

Extrinsics config1() { return {0.2441, -0.0185, 0.1787, 12.4 * kDeg, 17.6 * kDeg, -9.2 * kDeg}; }

Eigen::Matrix3d camera_matrix(double f, double cx, double cy) {
  Eigen::Matrix3d K;
  K << f, 0, cx, 0, f * 1.01, cy, 0, 0, 1;
  return K;
}

TEST(TrackWarpModel, HomographyIsGroundHomography) {
  const Eigen::Matrix3d K = camera_matrix(380, 321.3, 238.7);
  const SE2 m(0.021, -0.004, 0.03);
  const MotionHomography mh = motion_homography(K, config1(), m);
  EXPECT_LT((mh.H - ground_homography(K, config1(), m.matrix3d())).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(mh.H(2, 2), 1.0);
}

TEST(TrackWarpModel, DerivativesMatchCentralDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    Extrinsics e{0.3 * u(rng), 0.1 * u(rng), 0.15 + 0.3 * (u(rng) + 1), 25 * kDeg * u(rng),
                 25 * kDeg * u(rng), M_PI * u(rng)};
    const Eigen::Matrix3d K = camera_matrix(200 + 300 * (u(rng) + 1), 320 + 10 * u(rng), 240 + 10 * u(rng));
    const SE2 m(0.05 * u(rng), 0.05 * u(rng), 0.3 * u(rng));
    const MotionHomography mh = motion_homography(K, e, m);
    for (int i = 0; i < 3; ++i) {
      const double h = 1e-6;
      Eigen::Vector3d dx = Eigen::Vector3d::Zero();
      dx(i) = h;
      const Eigen::Matrix3d Hp = ground_homography(K, e, (m * SE2::exp(dx)).matrix3d());
      const Eigen::Matrix3d Hm = ground_homography(K, e, (m * SE2::exp(-dx)).matrix3d());
      const Eigen::Matrix3d numeric = (Hp - Hm) / (2 * h);
      const Eigen::Matrix3d& analytic = mh.dH[static_cast<size_t>(i)];
      EXPECT_LT((numeric - analytic).norm(), 1e-6 * (1.0 + analytic.norm()))
          << "parameter " << i << "\nnumeric\n" << numeric << "\nanalytic\n" << analytic;
      EXPECT_LT((mh.H * mh.G[static_cast<size_t>(i)] - analytic).norm(), 1e-9 * (1.0 + analytic.norm()));
    }
  }
}

TEST(TrackWarpModel, OrientationDerivativesMatchCentralDifferences) {
  // Section 5.1's tilt parameters (eqs. 21-24) against central differences of ground_homography
  // with the orientation update of eq. 20; the motion's derivatives are unchanged by them.
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    Extrinsics e{0.3 * u(rng), 0.1 * u(rng), 0.15 + 0.3 * (u(rng) + 1), 30 * kDeg * u(rng),
                 30 * kDeg * u(rng), M_PI * u(rng)};
    if (trial % 2 == 0) e = Extrinsics{0, 0, 1, e.roll, e.pitch, 0};  // the estimator's own frame
    const Eigen::Matrix3d K = camera_matrix(200 + 300 * (u(rng) + 1), 320 + 10 * u(rng), 240 + 10 * u(rng));
    const SE2 m(0.05 * u(rng), 0.05 * u(rng), 0.3 * u(rng));
    const MotionHomography plain = motion_homography(K, e, m);
    const MotionHomography mh = motion_homography(K, e, m, true);
    ASSERT_EQ(mh.nparam, 5);
    EXPECT_LT((mh.H - plain.H).norm(), 1e-12);
    for (size_t i = 0; i < 3; ++i) EXPECT_LT((mh.dH[i] - plain.dH[i]).norm(), 1e-12);
    for (int i = 0; i < 2; ++i) {
      const double h = 1e-6;
      Eigen::Vector2d dy = Eigen::Vector2d::Zero();
      dy(i) = h;
      const Eigen::Matrix3d Hp = ground_homography(K, rotate_orientation(e, dy), m.matrix3d());
      const Eigen::Matrix3d Hm = ground_homography(K, rotate_orientation(e, -dy), m.matrix3d());
      const Eigen::Matrix3d numeric = (Hp - Hm) / (2 * h);
      const Eigen::Matrix3d& analytic = mh.dH[static_cast<size_t>(3 + i)];
      EXPECT_LT((numeric - analytic).norm(), 1e-6 * (1.0 + analytic.norm()))
          << "tilt " << i << "\nnumeric\n" << numeric << "\nanalytic\n" << analytic;
      EXPECT_LT((mh.H * mh.G[static_cast<size_t>(3 + i)] - analytic).norm(), 1e-9 * (1.0 + analytic.norm()));
    }
  }
}

TEST(TrackWarpModel, OrientationUpdateTiltsTheGroundNormal) {
  // exp([y1, y2, 0]_x) R_vc: the camera centre stays, the ground normal in camera coordinates
  // turns by |y| (about an axis perpendicular to it), and a pure tilt about the robot's x axis of
  // a camera with zero yaw is a change of roll.
  const Extrinsics e = config1();
  const Eigen::Vector2d y(0.03, -0.02);
  const Extrinsics r = rotate_orientation(e, y);
  EXPECT_DOUBLE_EQ(r.x, e.x);
  EXPECT_DOUBLE_EQ(r.z, e.z);
  const double angle = std::acos(std::clamp(r.plane_normal_camera().dot(e.plane_normal_camera()), -1.0, 1.0));
  EXPECT_NEAR(angle, y.norm(), 1e-12);
  const Extrinsics level{0, 0, 1, 0.1, 0.0, 0.0};
  const Extrinsics rolled = rotate_orientation(level, Eigen::Vector2d(0.05, 0.0));
  EXPECT_NEAR(rolled.roll, 0.15, 1e-12);
  EXPECT_NEAR(rolled.pitch, 0.0, 1e-12);
  EXPECT_NEAR(rolled.yaw, 0.0, 1e-12);
}

TEST(TrackWarpModel, IncrementActsOnTheReferenceSideInExponentialCoordinates) {
  // H(T exp(x)) = H(T) * H(exp(Ad_T x)): the increment is a planar motion of the reference
  // frame, so the reference-side generators are the derivatives of H(exp(Ad_T x)).
  const Eigen::Matrix3d K = camera_matrix(400, 320, 240);
  const Extrinsics e = config1();
  const SE2 T(0.03, 0.01, 0.2);
  const Eigen::Vector3d x(0.004, -0.002, 0.01);
  Eigen::Matrix3d Ad;  // SE(2) adjoint: Ad_T (vx, vy, w) = (R v + w (y, -x), w)
  Ad << std::cos(T.theta), -std::sin(T.theta), T.y, std::sin(T.theta), std::cos(T.theta), -T.x, 0, 0, 1;
  Eigen::Matrix3d lhs = ground_homography(K, e, (T * SE2::exp(x)).matrix3d());
  Eigen::Matrix3d rhs = ground_homography(K, e, T.matrix3d()) *
                        ground_homography(K, e, SE2::exp(Ad * x).matrix3d());
  lhs /= lhs(2, 2);
  rhs /= rhs(2, 2);
  EXPECT_LT((lhs - rhs).norm(), 1e-10);
}

TEST(TrackWarpModel, HomographyMovesProjectedGroundPoints) {
  // A ground point seen by the reference camera at pixel p is seen by the live camera at H p,
  // with the live robot pose T in the reference robot frame.
  CameraModel cam = sim::default_camera(640, 480);
  cam.k1 = cam.k2 = 0;
  const Extrinsics e = config1();
  const SE2 T(0.025, -0.006, 0.04);
  const MotionHomography mh = motion_homography(cam.K(), e, T);
  const Eigen::Matrix4d T_vc = e.T_vc();
  for (double gx : {0.3, 0.4, 0.5})
    for (double gy : {-0.1, 0.0, 0.08}) {
      const Eigen::Vector4d X_ref_robot(gx, gy, 0, 1);
      const Eigen::Vector4d Xc_ref = T_vc.inverse() * X_ref_robot;
      const Eigen::Vector4d Xc_live = T_vc.inverse() * T.matrix3d().inverse() * X_ref_robot;
      const Eigen::Vector2d p_ref = cam.project(Xc_ref.head<3>());
      const Eigen::Vector2d p_live = cam.project(Xc_live.head<3>());
      const Eigen::Vector3d q = mh.H * p_ref.homogeneous();
      EXPECT_LT((q.hnormalized() - p_live).norm(), 1e-9);
    }
}

// The local plane (section 6.4): cameras on a body that rolls and pitches about the robot's
// origin, each frame at its own attitude. Body rotations written out by hand.
Eigen::Matrix4d body(double roll, double pitch) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch);
  Eigen::Matrix3d Rx, Ry;
  Rx << 1, 0, 0, 0, cr, -sr, 0, sr, cr;
  Ry << cp, 0, sp, 0, 1, 0, -sp, 0, cp;
  Eigen::Matrix4d B = Eigen::Matrix4d::Identity();
  B.topLeftCorner<3, 3>() = Rx * Ry;
  return B;
}

TEST(TrackWarpModel, LocalPlaneHomographyMovesProjectedGroundPoints) {
  // A camera 1 m behind the axle, 0.9 m up; the reference body rolled and pitched, the live one
  // otherwise: a ground point seen by the reference camera at p is seen by the live one at H p.
  CameraModel cam = sim::default_camera(640, 480, 60.0);
  cam.k1 = cam.k2 = 0;
  const Extrinsics e{-1.0, 0.05, 0.9, 2 * kDeg, 40 * kDeg, M_PI};
  const SE2 T(-0.08, 0.01, 0.02);
  const BodyAttitude ar{0.03, -0.05}, al{-0.02, 0.08};
  const Eigen::Matrix4d E_r = body(ar.roll, ar.pitch) * e.T_vc(), E_l = body(al.roll, al.pitch) * e.T_vc();
  const MotionHomography mh = local_plane_homography(cam.K(), e, T, ar, al);
  EXPECT_LT((mh.H - ground_homography(cam.K(), on_plane(e, ar), on_plane(e, al), T.matrix3d())).norm(), 1e-9);
  int seen = 0;
  for (double gx : {-0.05, -0.3, -0.6})  // the camera looks at about x = -0.24
    for (double gy : {-0.4, 0.0, 0.5}) {
      const Eigen::Vector4d X(gx, gy, 0, 1);  // on the ground, in the reference robot's frame
      const Eigen::Vector4d Xc_ref = E_r.inverse() * X;
      const Eigen::Vector4d Xc_live = E_l.inverse() * T.matrix3d().inverse() * X;
      ASSERT_GT(Xc_ref.z(), 0);
      ASSERT_GT(Xc_live.z(), 0);
      const Eigen::Vector3d q = mh.H * cam.project(Xc_ref.head<3>()).homogeneous();
      EXPECT_LT((q.hnormalized() - cam.project(Xc_live.head<3>())).norm(), 1e-8);
      ++seen;
    }
  EXPECT_EQ(seen, 9);
  // Equal attitudes of zero: the rigid camera's homography.
  EXPECT_LT((local_plane_homography(cam.K(), e, T, {}, {}).H - motion_homography(cam.K(), e, T).H).norm(), 1e-12);
  EXPECT_LT((ground_homography(cam.K(), e, e, T.matrix3d()) - ground_homography(cam.K(), e, T.matrix3d())).norm(),
            1e-12);
}

TEST(TrackWarpModel, LocalPlaneDerivativesMatchCentralDifferences) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const Extrinsics e{0.8 * u(rng), 0.2 * u(rng), 0.15 + 0.5 * (u(rng) + 1), 25 * kDeg * u(rng),
                       40 * kDeg * u(rng), M_PI * u(rng)};
    const Eigen::Matrix3d K = camera_matrix(200 + 300 * (u(rng) + 1), 320 + 10 * u(rng), 240 + 10 * u(rng));
    const SE2 m(0.1 * u(rng), 0.05 * u(rng), 0.3 * u(rng));
    const BodyAttitude ar{0.1 * u(rng), 0.15 * u(rng)}, al{0.1 * u(rng), 0.15 * u(rng)};
    const MotionHomography mh = local_plane_homography(K, e, m, ar, al);
    ASSERT_EQ(mh.nparam, 7);
    const auto H_of = [&](const Eigen::Vector3d& x, const Eigen::Vector4d& y) {
      const BodyAttitude r{ar.roll + y(0), ar.pitch + y(1)}, l{al.roll + y(2), al.pitch + y(3)};
      return ground_homography(K, on_plane(e, r), on_plane(e, l), (m * SE2::exp(x)).matrix3d());
    };
    const double h = 1e-6;
    for (int i = 0; i < 7; ++i) {
      Eigen::Vector3d dx = Eigen::Vector3d::Zero();
      Eigen::Vector4d dy = Eigen::Vector4d::Zero();
      if (i < 3) dx(i) = h; else dy(i - 3) = h;
      const Eigen::Matrix3d numeric = (H_of(dx, dy) - H_of(-dx, -dy)) / (2 * h);
      const Eigen::Matrix3d& analytic = mh.dH[static_cast<size_t>(i)];
      EXPECT_LT((numeric - analytic).norm(), 1e-6 * (1.0 + analytic.norm()))
          << "trial " << trial << " parameter " << i << "\nnumeric\n" << numeric << "\nanalytic\n" << analytic;
      EXPECT_LT((mh.H * mh.G[static_cast<size_t>(i)] - analytic).norm(), 1e-9 * (1.0 + analytic.norm()));
    }
  }
}

TEST(TrackWarpModel, PixelDisplacementOfASmallStep) {
  const Eigen::Matrix3d K = camera_matrix(400, 320, 240);
  const Extrinsics e = config1();
  const SE2 a(0.02, 0.0, 0.0);
  EXPECT_EQ(max_pixel_displacement(K, e, a, a, 640, 480), 0.0);
  // 1 mm forward at ~0.2 m depth and f = 400 is about 2 pixels.
  const double d = max_pixel_displacement(K, e, a, a * SE2(0.001, 0, 0), 640, 480);
  EXPECT_GT(d, 1.0);
  EXPECT_LT(d, 5.0);
}

}  // namespace
}  // namespace planarvo::track
