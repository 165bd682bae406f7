// The tracker on pairs of simulator renders at known poses: the recovered motion against the
// truth on noise-free renders and with camera noise and a gain change; the kernel's Jacobian
// against a numeric derivative of the cost; convergence from a poor initial guess.
#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "image/undistort.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"
#include "track/aligner.h"
#include "track/tracker.h"
#include "track/warp_model.h"
#include "unit/track_test_pyramid.h"

namespace planarvo::track {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct Scene {
  sim::Options options;
  std::unique_ptr<sim::Renderer> renderer;
};

class TrackEsm : public ::testing::Test {
 protected:
  void make_scene(const std::string& texture, int w, int h, bool distortion = false) {
    scene_.options.texture = test::texture(texture).string();
    scene_.options.camera = sim::default_camera(w, h);
    if (!distortion) scene_.options.camera.k1 = scene_.options.camera.k2 = 0.0;
    scene_.renderer = std::make_unique<sim::Renderer>(
        rt_, cv::imread(scene_.options.texture, cv::IMREAD_GRAYSCALE), scene_.options);
  }
  Pyramid pyramid_at(const SE2& pose, int levels, double gain = 1.0, double offset = 0.0,
                     double noise = 0.0, uint64_t seed = 1) {
    cv::Mat img = scene_.renderer->render_float(pose);
    if (gain != 1.0 || offset != 0.0 || noise > 0.0) {
      cv::Mat u8 = sim::apply_camera(img, {gain, offset}, noise, seed);
      u8.convertTo(img, CV_32FC1);
    }
    return test::test_upload(rt_, test::test_pyramid(img, nullptr, levels));
  }

  ocl::Runtime rt_;
  Scene scene_;
};

TEST_F(TrackEsm, RecoversASmallMotionOnNoiseFreeRenders) {
  make_scene("asphalt_01.png", 640, 480);
  const SE2 a(0.1, 0.2, 0.3);
  // Up to the largest motion of a frame interval (0.8 m/s, 1.5 rad/s at 30 Hz), from a zero
  // initial guess (the second frame has no velocity to predict with).
  for (const SE2& m : {SE2(0.004, 0.001, 0.01), SE2(-0.012, 0.003, -0.02), SE2(0.0, 0.0, 0.05),
                       SE2(0.026, -0.002, 0.03)}) {
    // Full resolution (finest_level 0): within 0.02 mm and 0.001 degree; the default, which
    // stops at half resolution: within 0.01 mm and 0.003 degree.
    for (const int finest : {0, 1}) {
      const SE2 b = a * m;
      TrackerOptions opt;
      opt.finest_level = finest;
      Tracker tr(rt_, scene_.options.camera, scene_.options.extrinsics, opt);
      const FrameResult r0 = tr.track(pyramid_at(a, 4), 0.0);
      ASSERT_EQ(r0.status, FrameResult::Status::First);
      const FrameResult r1 = tr.track(pyramid_at(b, 4), 1.0 / 30);
      EXPECT_EQ(r1.status, FrameResult::Status::Ok) << r1.reason;
      const double et = std::hypot(r1.motion.value.x - m.x, r1.motion.value.y - m.y);
      const double er = std::abs(wrap_angle(r1.motion.value.theta - m.theta));
      std::printf("motion (%.4f %.4f %.4f), finest level %d: error %.5f mm %.6f deg, passes %d %d %d %d\n", m.x, m.y,
                  m.theta, finest, et * 1e3, er / kDeg, r1.iterations[3], r1.iterations[2], r1.iterations[1],
                  r1.iterations[0]);
      EXPECT_LT(et, finest == 0 ? 0.02e-3 : 0.01e-3);
      EXPECT_LT(er, (finest == 0 ? 0.001 : 0.003) * kDeg);
    }
  }
}

TEST_F(TrackEsm, TheTrackerReportsTheAlignersResult) {
  // The aligner updates the caller's pairs in place (their storage stays, so references taken
  // before the call see the result), and the tracker's motion is exactly what the aligner finds
  // from the same start: a tracker that read a stale state reported a step-old estimate.
  make_scene("asphalt_01.png", 320, 240);
  const SE2 a(0.1, 0.2, 0.3);
  TrackerOptions opt;
  Aligner aligner(rt_, scene_.options.camera.K(), opt, false);
  for (const SE2& m : {SE2(0.006, -0.002, 0.02), SE2(0.012, 0.003, -0.01), SE2(-0.004, 0.0, 0.04),
                       SE2(0.002, 0.001, 0.0), SE2(0.02, -0.004, 0.03)}) {
    const Pyramid ref = pyramid_at(a, 4), live = pyramid_at(a * m, 4);
    Tracker tr(rt_, scene_.options.camera, scene_.options.extrinsics, opt);
    ASSERT_EQ(tr.track(ref, 0.0).status, FrameResult::Status::First);
    const FrameResult r = tr.track(live, 1.0 / 30);
    ASSERT_EQ(r.status, FrameResult::Status::Ok) << r.reason;

    std::vector<AlignmentPair> pairs(1);
    pairs[0].reference = &ref;
    pairs[0].live = &live;
    const AlignmentPair* storage = pairs.data();
    Extrinsics e = scene_.options.extrinsics;
    const AlignmentReport rep = aligner.align(pairs, &e, aligner.levels(ref, live));
    ASSERT_TRUE(rep.ok);
    EXPECT_EQ(pairs.data(), storage);
    EXPECT_EQ(r.motion.value.x, pairs[0].motion.x) << m.x;
    EXPECT_EQ(r.motion.value.y, pairs[0].motion.y) << m.x;
    EXPECT_EQ(r.motion.value.theta, pairs[0].motion.theta) << m.x;
  }
}

TEST_F(TrackEsm, RecoversMotionWithNoiseGainAndDistortion) {
  // 8-bit frames with noise 1 grey level through the undistortion of the default camera; the
  // live frame once as the reference's exposure and once 4 % brighter and offset by 3 grey
  // levels.
  make_scene("aerial_ground_rock.png", 640, 480, true);
  const UndistortMap map = compute_undistort_map(scene_.options.camera);
  auto frame = [&](const SE2& pose, double gain, double offset, uint64_t seed) {
    const cv::Mat u8 = sim::apply_camera(scene_.renderer->render_float(pose), {gain, offset}, 1.0, seed);
    return test::test_upload(rt_, test::test_pyramid(u8, &map, 4));
  };
  const SE2 a(-0.3, 0.1, 1.0), m(0.011, -0.002, -0.015);
  FrameResult r[2];
  for (int i = 0; i < 2; ++i) {
    Tracker tr(rt_, scene_.options.camera, scene_.options.extrinsics);
    tr.track(frame(a, 1.0, 0.0, 1), 0.0);
    r[i] = tr.track(frame(a * m, i ? 1.04 : 1.0, i ? 3.0 : 0.0, 2), 1.0 / 30);
    EXPECT_EQ(r[i].status, FrameResult::Status::Ok) << r[i].reason;
    const double et = std::hypot(r[i].motion.value.x - m.x, r[i].motion.value.y - m.y);
    const double er = std::abs(wrap_angle(r[i].motion.value.theta - m.theta));
    std::printf("error %.5f mm %.6f deg, log gain %.4f, bias %.2f, sigma %.2f\n", et * 1e3, er / kDeg, r[i].log_gain,
                r[i].bias, r[i].sigma);
    EXPECT_LT(et, 0.02e-3);
    EXPECT_LT(er, 0.002 * kDeg);
  }
  // r = e^a I_l + b - I_r. Without an exposure change the fit is not a = b = 0: bilinear
  // sampling of the live level lowers its contrast a little (a few per cent at a texture's
  // finest detail), which the gain makes up for. The exposure change must add exactly its
  // own part: e^a1 = e^a0 / 1.04, b1 = b0 - 3 e^a1.
  EXPECT_NEAR(r[1].log_gain - r[0].log_gain, -std::log(1.04), 0.002);
  EXPECT_NEAR(r[1].bias, r[0].bias - 3.0 * std::exp(r[1].log_gain), 0.3);
  // The covariance is positive definite and of a plausible size (micrometres, microradians).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(r[1].motion.covariance);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  EXPECT_LT(std::sqrt(r[1].motion.covariance(0, 0)), 1e-5);
  EXPECT_LT(std::sqrt(r[1].motion.covariance(2, 2)), 1e-4);
}

// A smooth analytic ground image (frequencies below 0.12 rad per pixel, so that bilinear
// interpolation follows it closely) and its exact gradient.
double smooth_image(double u, double v, double* du, double* dv) {
  const double a = 0.11 * u + 0.05 * v, b = 0.07 * v - 0.03 * u + 1.0, c = 0.05 * u, d = 0.09 * v;
  *du = 30 * 0.11 * std::cos(a) + 25 * 0.03 * std::sin(b) + 15 * 0.05 * std::cos(c) * std::cos(d);
  *dv = 30 * 0.05 * std::cos(a) - 25 * 0.07 * std::sin(b) - 15 * 0.09 * std::sin(c) * std::sin(d);
  return 128 + 30 * std::sin(a) + 25 * std::cos(b) + 15 * std::sin(c) * std::cos(d);
}

TEST_F(TrackEsm, JacobianMatchesNumericDerivativeOfTheCost) {
  // The reference level is the smooth image with its exact gradient; the live level is the
  // same image seen after the motion m (I_l(x) = I_r(H^-1 x), gradient by the chain rule).
  // Least-squares cost C = sum r^2 / 2 (no Huber), differentiated numerically along each
  // parameter at a point about 0.1 pixel from the solution, against the kernel's J^T r: the
  // brightness columns are exact derivatives, the motion columns ESM's mean of the reference
  // and live gradients, which differs from the derivative by second-order terms.
  const int w = 160, h = 120;
  Eigen::Matrix3d K;
  K << 120, 0, 79.7, 0, 121, 60.2, 0, 0, 1;
  const Extrinsics e{0.2441, -0.0185, 0.1787, 12.4 * kDeg, 17.6 * kDeg, -9.2 * kDeg};
  const SE2 m(0.006, 0.002, 0.01);
  const Eigen::Matrix3d Hinv = motion_homography(K, e, m).H.inverse();
  std::vector<float> ref(static_cast<size_t>(w) * h * 4), live(ref.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double du, dv;
      float* R = &ref[4 * (static_cast<size_t>(y) * w + x)];
      R[0] = static_cast<float>(smooth_image(x, y, &du, &dv));
      R[1] = static_cast<float>(du);
      R[2] = static_cast<float>(dv);
      // A margin wider than the motion, so no pixel crosses the live border during the test.
      const bool inner = x >= 12 && y >= 12 && x < w - 12 && y < h - 12;
      R[3] = inner ? 1.0f : 0.0f;
      if (!inner) R[0] = R[1] = R[2] = 0.0f;
      const Eigen::Vector3d q = Hinv * Eigen::Vector3d(x, y, 1);
      const double pu = q.x() / q.z(), pv = q.y() / q.z();
      // d(pu, pv)/d(x, y) of p = pi(Hinv x)
      Eigen::Matrix<double, 2, 3> dpi;
      dpi << 1 / q.z(), 0, -pu / q.z(), 0, 1 / q.z(), -pv / q.z();
      const Eigen::Matrix<double, 2, 2> Dp = (dpi * Hinv).leftCols<2>();
      float* L = &live[4 * (static_cast<size_t>(y) * w + x)];
      L[0] = static_cast<float>(smooth_image(pu, pv, &du, &dv));
      const Eigen::RowVector2d g = Eigen::RowVector2d(du, dv) * Dp;
      L[1] = static_cast<float>(g(0));
      L[2] = static_cast<float>(g(1));
      L[3] = 1.0f;
    }
  cl::Buffer bref(rt_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, ref.size() * 4, ref.data());
  cl::Buffer blive(rt_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, live.size() * 4, live.data());
  WarpReduce wr(rt_, 3, TrackerOptions::default_kernel_options());
  struct Point { SE2 T; double a, b; };
  auto pass = [&](const Point& p, ReduceSums* s) {
    const MotionHomography mh = motion_homography(K, e, p.T);
    WarpInputs in;
    in.H = mh.H;
    for (size_t i = 0; i < 3; ++i) in.G[i] = mh.G[i];
    in.gain = std::exp(p.a);
    in.bias = p.b;
    in.huber_k = 1e30;
    wr.run(bref, w, h, blive, w, h, in, s);
  };
  // Motion columns: about 0.1 pixel away from the solution (120 px per 0.2 m: 0.1 px is about
  // 0.15 mm), brightness exact, where the cost's gradient is made of the misalignment. (At the
  // solution it is made of the interpolation's small errors and tells nothing.) Brightness
  // columns: at the solution with a brightness error.
  const Point points[2] = {{m * SE2(0.0001, -0.0001, 0.0003), 0.0, 0.0}, {m, 0.01, 0.5}};
  const double steps[5] = {1e-5, 1e-5, 3e-5, 1e-3, 0.05};
  for (int i = 0; i < 5; ++i) {
    const Point& x0 = points[i < 3 ? 0 : 1];
    ReduceSums s0;
    pass(x0, &s0);
    Point p = x0, q = x0;
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    if (i < 3) {
      d(i) = steps[i];
      p.T = x0.T * SE2::exp(d);
      q.T = x0.T * SE2::exp(-d);
    } else if (i == 3) {
      p.a += steps[i];
      q.a -= steps[i];
    } else {
      p.b += steps[i];
      q.b -= steps[i];
    }
    ReduceSums sp, sq;
    pass(p, &sp);
    pass(q, &sq);
    ASSERT_EQ(sp.valid, sq.valid);
    ASSERT_EQ(sp.valid, sp.ref);
    // The weights are 1, so wrr = sum r^2 = 2 C.
    const double numeric = (sp.wrr - sq.wrr) / (4 * steps[i]);
    std::printf("parameter %d: numeric %.6g, kernel %.6g\n", i, numeric, s0.JtWr(i));
    EXPECT_NEAR(s0.JtWr(i), numeric, (i < 3 ? 0.03 : 1e-3) * std::abs(numeric)) << "parameter " << i;
  }
}

}  // namespace
}  // namespace planarvo::track
