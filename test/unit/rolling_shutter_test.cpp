// The rolling shutter's undistortion (image/rolling_shutter.h) against the simulator: a frame
// rendered row by row from the poses a rolling shutter reads them at (Renderer::render_float_rows,
// the robot at P exp(tau_r xi)) and undistorted with the row warp of that twist must be the
// global shutter's frame at the stamp (Renderer::render_float(P)), up to the frames' 8-bit
// rounding and bilinear resampling; undistorted without it, it is sheared by tens of pixels.
// Then the ImagePipeline's plumbing: the row warp set before process(), again before reprocess(),
// and the kept frame's own warp, against undistort_rolling_reference.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/se2.h"
#include "image/photometric.h"
#include "image/pipeline.h"
#include "image/rolling_shutter.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"

namespace planarvo {
namespace {

cv::Mat smooth_texture(int side, uint64_t seed) {
  cv::Mat t(side, side, CV_32FC1);
  cv::RNG(seed).fill(t, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(t, t, cv::Size(0, 0), 6.0);
  cv::normalize(t, t, 10, 245, cv::NORM_MINMAX);
  return t;
}

// Mean |a - b| over the pixels valid in both (intensity images), and how many there were.
double mean_abs_diff(const cv::Mat& a, const cv::Mat& b, int margin, size_t* count) {
  double sum = 0.0;
  size_t n = 0;
  for (int y = margin; y < a.rows - margin; ++y)
    for (int x = margin; x < a.cols - margin; ++x) {
      const float u = a.at<float>(y, x), v = b.at<float>(y, x);
      if (u == kInvalidIntensity || v == kInvalidIntensity) continue;
      sum += std::abs(static_cast<double>(u) - v);
      ++n;
    }
  *count = n;
  return n ? sum / static_cast<double>(n) : HUGE_VAL;
}

cv::Mat to_gray(const cv::Mat& f) {
  cv::Mat g;
  f.convertTo(g, CV_8UC1);
  return g;
}

// The robot's pose at each sensor row's read: P exp(tau_r twist), tau_r = r / (H - 1) * readout.
std::vector<SE2> row_poses(const SE2& P, const Eigen::Vector3d& twist, double readout, int height) {
  std::vector<SE2> rows(static_cast<size_t>(height));
  for (int r = 0; r < height; ++r)
    rows[static_cast<size_t>(r)] = P * SE2::exp(twist * (static_cast<double>(r) / (height - 1) * readout));
  return rows;
}

struct Case {
  int configuration;
  Eigen::Vector3d twist;  // vx, vy, omega
  double readout;
};

// A 320 x 240 camera with the case's readout at the case's paper configuration.
sim::Options case_options(const Case& c) {
  sim::Options o;
  o.camera = sim::default_camera(320, 240);
  o.camera.rolling_shutter_readout = c.readout;
  o.extrinsics = sim::paper_configuration(c.configuration);
  o.supersampling = 2;
  return o;
}

TEST(RollingShutter, UndistortedFrameIsTheGlobalShuttersAtTheStamp) {
  ocl::Runtime rt;
  const Case cases[] = {{1, {1.2, 0.0, 0.0}, 0.03},   // straight ahead, 30 ms readout
                        {1, {0.8, 0.0, 1.5}, 0.025},  // turning
                        {2, {1.0, 0.0, -0.8}, 0.03},  // a tilted, yawed camera
                        {3, {2.5, 0.0, 0.3}, 0.02}};  // configuration 3 at speed
  for (const Case& c : cases) {
    sim::Options o = case_options(c);
    sim::Renderer renderer(rt, smooth_texture(1024, 5 + static_cast<uint64_t>(c.configuration)), o);
    const SE2 P(0.11, -0.04, 0.3);
    const std::vector<SE2> rows = row_poses(P, c.twist, c.readout, o.camera.height);
    const cv::Mat rolling = to_gray(renderer.render_float_rows(rows));
    const cv::Mat global = to_gray(renderer.render_float(P));
    const UndistortMap map = compute_undistort_map(o.camera);
    const cv::Mat truth = undistort_reference(global, map);
    const cv::Mat unrolled = undistort_rolling_reference(rolling, o.camera, map, rolling_shutter_warp(o.camera, o.extrinsics, c.twist));
    const cv::Mat plain = undistort_reference(rolling, map);
    size_t n_unrolled = 0, n_plain = 0, n_same = 0;
    const double e_unrolled = mean_abs_diff(unrolled, truth, 4, &n_unrolled);
    const double e_plain = mean_abs_diff(plain, truth, 4, &n_plain);
    const double e_same = mean_abs_diff(truth, undistort_reference(to_gray(renderer.render_float(P)), map), 4, &n_same);
    const std::string what = "configuration " + std::to_string(c.configuration) + " twist " +
                             std::to_string(c.twist.x()) + " " + std::to_string(c.twist.z());
    EXPECT_EQ(e_same, 0.0) << what;
    // The 8-bit rounding of two frames and one bilinear resampling: a few tenths of a grey
    // level on this texture (0.8 where configuration 2 sees the ground obliquely); the shear is
    // 17-26. A readout or twist 5 % off would leave 5 % of it.
    EXPECT_LT(e_unrolled, 1.0) << what << " plain " << e_plain;
    EXPECT_LT(e_unrolled, 0.04 * e_plain) << what;
    EXPECT_GT(n_unrolled, rolling.total() / 2) << what;
    RecordProperty("mean_abs_" + std::to_string(c.configuration), std::to_string(e_unrolled) + " vs " + std::to_string(e_plain));
  }
}

// The light fixed to the camera under a rolling shutter: a lamp's falloff and the robot's
// shadow (sharp-edged) lie on the camera's pixels, and the row warp moves those pixels in the
// undistorted image. A rolling frame under that light, undistorted with its row warp and
// corrected with the true flat field read through the warp's light field
// (photometric_rolling_reference), must be the unlit global shutter's frame at the stamp times
// the flat field's maximum; corrected where the pixels are (photometric_reference) it is not,
// by the shadow's edge moved tens of pixels.
TEST(RollingShutter, TheLightStaysOnTheCamerasPixels) {
  ocl::Runtime rt;
  const Case cases[] = {{1, {0.8, 0.0, 1.5}, 0.025}, {2, {1.0, 0.0, -0.8}, 0.03}};
  for (const Case& c : cases) {
    sim::Options o = case_options(c);
    o.lamp_falloff = 0.6;
    o.shadow = 0.6;
    sim::Renderer renderer(rt, smooth_texture(1024, 9 + static_cast<uint64_t>(c.configuration)), o);
    const SE2 P(0.05, 0.02, -0.2);
    const std::vector<SE2> rows = row_poses(P, c.twist, c.readout, o.camera.height);
    const sim::Lighting light = sim::camera_lighting(o);
    cv::Mat lit = renderer.render_float_rows(rows);
    sim::apply_lighting(light, lit);
    const UndistortMap map = compute_undistort_map(o.camera);
    const cv::Mat valid(o.camera.height, o.camera.width, CV_8UC1, const_cast<uint8_t*>(map.valid.data()));
    PhotometricOptions po;
    po.min_contrast = 0.05;  // the shadow keeps its values
    const PhotometricFit fit = flat_field_photometric(flat_field_to_undistorted(light.gain, map), valid, po);
    double top = 0.0;
    cv::minMaxLoc(flat_field_to_undistorted(light.gain, map), nullptr, &top, nullptr, nullptr, valid);
    cv::Mat truth = undistort_reference(to_gray(renderer.render_float(P)), map);
    for (float& v : cv::Mat_<float>(truth))
      if (v != kInvalidIntensity) v *= static_cast<float>(top);
    const RowWarp warp = rolling_shutter_warp(o.camera, o.extrinsics, c.twist);
    const cv::Mat unrolled = undistort_rolling_reference(to_gray(lit), o.camera, map, warp);
    const cv::Mat moved = photometric_rolling_reference(unrolled, fit, warp, 1e9);
    const cv::Mat fixed = photometric_reference(unrolled, fit, 1e9);
    size_t n_moved = 0, n_fixed = 0;
    const double e_moved = mean_abs_diff(moved, truth, 4, &n_moved);
    const double e_fixed = mean_abs_diff(fixed, truth, 4, &n_fixed);
    const std::string what = "configuration " + std::to_string(c.configuration);
    // 8-bit rounding under a gain down to 0.3 (amplified 3x by the correction) and one bilinear
    // resampling.
    EXPECT_LT(e_moved, 1.5) << what << " fixed " << e_fixed;
    EXPECT_LT(e_moved, 0.35 * e_fixed) << what;
    EXPECT_GT(n_moved, truth.total() / 2) << what;
    RecordProperty("mean_abs_light_" + std::to_string(c.configuration), std::to_string(e_moved) + " vs " + std::to_string(e_fixed));
  }
}

// The grid's interpolated displacement against the per-pixel solution (rolling_shutter_source),
// and that solution against its own definition: the sensor row it lands on is the row whose
// pose sees the pixel there (distort(H_r p) with H_r computed afresh from that row's time).
TEST(RollingShutter, GridMatchesThePerPixelSolution) {
  CameraModel cam = sim::default_camera(640, 480);
  cam.rolling_shutter_readout = 0.03;
  const UndistortMap map = compute_undistort_map(cam);
  for (int config = 1; config <= 3; ++config) {
    const Extrinsics e = sim::paper_configuration(config);
    const Eigen::Vector3d twist(1.5, 0.2, 1.2);
    const RowWarp warp = rolling_shutter_warp(cam, e, twist);
    cv::RNG rng(config);
    double worst = 0.0, worst_fixed = 0.0, largest = 0.0;
    Eigen::Vector2d worst_at(0, 0);
    for (int k = 0; k < 400; ++k) {
      const int u = rng.uniform(0, cam.width), v = rng.uniform(0, cam.height);
      const Eigen::Vector2d exact = rolling_shutter_source(cam, e, twist, u, v);
      // Where the frame has a source (elsewhere the solution's row is clamped to the sensor).
      if (!(exact.x() >= 0 && exact.x() <= cam.width - 1 && exact.y() >= 0 && exact.y() <= cam.height - 1)) continue;
      // The grid, interpolated as the reference does (in double here).
      const double gx = static_cast<double>(u) / warp.step, gy = static_cast<double>(v) / warp.step;
      const int i = std::min(static_cast<int>(gx), warp.nodes_x - 2), j = std::min(static_cast<int>(gy), warp.nodes_y - 2);
      const double ax = gx - i, ay = gy - j;
      Eigen::Vector2d d;
      for (int c = 0; c < 2; ++c) {
        auto g = [&](int a, int b) { return warp.delta[2 * (static_cast<size_t>(b) * warp.nodes_x + a) + c]; };
        d[c] = (1 - ay) * ((1 - ax) * g(i, j) + ax * g(i + 1, j)) + ay * ((1 - ax) * g(i, j + 1) + ax * g(i + 1, j + 1));
      }
      const size_t p = static_cast<size_t>(v) * cam.width + u;
      const Eigen::Vector2d grid(map.map_x[p] + d.x(), map.map_y[p] + d.y());
      if ((grid - exact).norm() > worst) worst_at = Eigen::Vector2d(u, v);
      worst = std::max(worst, (grid - exact).norm());
      largest = std::max(largest, (exact - Eigen::Vector2d(map.map_x[p], map.map_y[p])).norm());
      // The fixed point: the row's own pose, from scratch.
      const double tau = std::clamp(exact.y(), 0.0, cam.height - 1.0) / (cam.height - 1) * cam.rolling_shutter_readout;
      Eigen::Matrix3d H = ground_homography(cam.K(), e, SE2::exp(tau * twist).matrix3d());
      const Eigen::Vector3d q = H * Eigen::Vector3d(u, v, 1.0);
      const Eigen::Vector2d dn = cam.distort(Eigen::Vector2d((q.x() / q.z() - cam.cx) / cam.fx, (q.y() / q.z() - cam.cy) / cam.fy));
      worst_fixed = std::max(worst_fixed, (Eigen::Vector2d(cam.fx * dn.x() + cam.cx, cam.fy * dn.y() + cam.cy) - exact).norm());
    }
    // Every node inside the frame against its own exact solution: three in four are filled in by
    // cubics through solved ones (rolling_shutter_warp), whose error must stay a small part of
    // the bilinear interpolation's between nodes (0.04 px at configuration 3; 0.0034 px measured).
    double worst_node = 0.0;
    for (int j = 0; j < warp.nodes_y; ++j)
      for (int i = 0; i < warp.nodes_x; ++i) {
        const double u = i * warp.step, v = j * warp.step;
        if (u > cam.width - 1 || v > cam.height - 1) continue;
        const Eigen::Vector2d exact = rolling_shutter_source(cam, e, twist, u, v);
        if (!(exact.x() >= 0 && exact.x() <= cam.width - 1 && exact.y() >= 0 && exact.y() <= cam.height - 1)) continue;
        const Eigen::Vector2d dn = cam.distort(Eigen::Vector2d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy));
        const Eigen::Vector2d global(cam.fx * dn.x() + cam.cx, cam.fy * dn.y() + cam.cy);
        const size_t n = 2 * (static_cast<size_t>(j) * warp.nodes_x + i);
        worst_node = std::max(worst_node, (global + Eigen::Vector2d(warp.delta[n], warp.delta[n + 1]) - exact).norm());
      }
    EXPECT_LT(worst_node, 5e-3) << "configuration " << config;
    RecordProperty("worst_node_px_" + std::to_string(config), std::to_string(worst_node));
    EXPECT_GT(largest, 20.0) << "configuration " << config << ": the test wants a real shear";
    // The grid's interpolation (rolling_shutter.h): the field's curvature over 16 px.
    EXPECT_LT(worst, 0.06) << "configuration " << config << " worst at " << worst_at.transpose();
    // 65 row homographies interpolated linearly, and the fixed point to 1e-5 rows.
    EXPECT_LT(worst_fixed, 5e-3) << "configuration " << config;
  }
}

// Level 0's intensity of a pyramid, kInvalidIntensity where not valid (invalid pixels are zeros
// in the pyramid's layout, pyramid.h).
cv::Mat level0(ocl::Runtime& rt, const Pyramid& p) {
  std::vector<cv::Mat> ch;
  cv::split(download_pyramid(rt, p)[0], ch);
  cv::Mat i = ch[0].clone();
  for (int y = 0; y < i.rows; ++y)
    for (int x = 0; x < i.cols; ++x)
      if (ch[3].at<float>(y, x) == 0.0f) i.at<float>(y, x) = kInvalidIntensity;
  return i;
}

// The pipeline's level 0 against a reference: within 0.01 grey levels on average, over more than
// half the image.
void expect_matches(const cv::Mat& got, const cv::Mat& want, const std::string& what) {
  size_t n = 0;
  EXPECT_LT(mean_abs_diff(got, want, 1, &n), 0.01) << what;
  EXPECT_GT(n, got.total() / 2) << what;
}

// The pipeline tests' camera: small, distorted, read out over 30 ms.
CameraModel pipeline_test_camera() {
  CameraModel cam = sim::default_camera(160, 120);
  cam.k1 = -0.08;
  cam.rolling_shutter_readout = 0.03;
  return cam;
}

TEST(RollingShutter, PipelineUsesEachFramesRowWarp) {
  ocl::Runtime rt;
  const CameraModel cam = pipeline_test_camera();
  const Extrinsics e = sim::paper_configuration(1);
  const UndistortMap map = compute_undistort_map(cam);
  ImagePipelineOptions po;
  po.prefilter = false;  // level 0's intensity is the undistorted frame
  ImagePipeline pipeline(rt, cam, 2, po);
  cv::Mat a(cam.height, cam.width, CV_8UC1), b(cam.height, cam.width, CV_8UC1);
  cv::Mat fa = smooth_texture(cam.width, 1)(cv::Rect(0, 0, cam.width, cam.height)).clone();
  cv::Mat fb = smooth_texture(cam.width, 2)(cv::Rect(0, 0, cam.width, cam.height)).clone();
  fa.convertTo(a, CV_8UC1);
  fb.convertTo(b, CV_8UC1);
  const RowWarp wa = rolling_shutter_warp(cam, e, Eigen::Vector3d(1.0, 0.0, 0.5));
  const RowWarp wb = rolling_shutter_warp(cam, e, Eigen::Vector3d(-0.7, 0.1, -1.0));
  const RowWarp wc = rolling_shutter_warp(cam, e, Eigen::Vector3d(0.3, 0.0, 2.0));
  Pyramid out;
  pipeline.set_row_warp(wa);
  pipeline.process(a, out);
  expect_matches(level0(rt, out), undistort_rolling_reference(a, cam, map, wa), "process with the warp set before");
  pipeline.keep();
  pipeline.set_row_warp(wb);
  pipeline.process(b, out);
  expect_matches(level0(rt, out), undistort_rolling_reference(b, cam, map, wb), "the next frame with its own warp");
  pipeline.set_row_warp(wc);
  pipeline.reprocess(out);
  expect_matches(level0(rt, out), undistort_rolling_reference(b, cam, map, wc), "reprocessed with a new warp");
  pipeline.reprocess_kept(out);
  expect_matches(level0(rt, out), undistort_rolling_reference(a, cam, map, wa), "the kept frame keeps its warp");
  pipeline.set_kept_row_warp(wb);
  pipeline.reprocess_kept(out);
  expect_matches(level0(rt, out), undistort_rolling_reference(a, cam, map, wb), "the kept frame with a new warp");
  pipeline.set_row_warp(identity_row_warp(cam.width, cam.height));
  pipeline.reprocess(out);
  expect_matches(level0(rt, out), undistort_reference(b, map), "the identity is the plain undistortion");
  EXPECT_THROW(pipeline.set_row_warp(identity_row_warp(cam.width, cam.height + 1)), Error);
}

// The pipeline with a photometric model (a known one, so that nothing is learnt) and a row warp:
// level 0 is the rolling undistortion corrected through the warp's light field
// (photometric_rolling_reference), for the frame and for the kept frame with its own warp; an
// identity model, or an identity warp, is the plain correction.
TEST(RollingShutter, PipelineReadsTheLightThroughEachFramesWarp) {
  ocl::Runtime rt;
  const CameraModel cam = pipeline_test_camera();
  const Extrinsics e = sim::paper_configuration(1);
  const UndistortMap map = compute_undistort_map(cam);
  ImagePipelineOptions po;
  po.prefilter = false;
  po.photometric.enabled = true;
  ImagePipeline pipeline(rt, cam, 2, po);
  ASSERT_NE(pipeline.photometric(), nullptr);
  // A smooth falloff with a hole (no value) and a sharp step: both move with the warp.
  PhotometricFit fit = identity_photometric(cam.width, cam.height);
  fit.identity = false;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      fit.scale.at<float>(y, x) = 1.0f + 0.004f * static_cast<float>(std::hypot(x - 80, y - 50)) + (y > 90 ? 1.0f : 0.0f);
      fit.offset.at<float>(y, x) = y > 90 ? -20.0f : 0.0f;
    }
  cv::circle(fit.scale, cv::Point(40, 40), 6, cv::Scalar(0.0f), cv::FILLED);
  pipeline.photometric()->set(fit);
  cv::Mat a, b;
  smooth_texture(cam.width, 3)(cv::Rect(0, 0, cam.width, cam.height)).convertTo(a, CV_8UC1);
  smooth_texture(cam.width, 4)(cv::Rect(0, 0, cam.width, cam.height)).convertTo(b, CV_8UC1);
  const RowWarp wa = rolling_shutter_warp(cam, e, Eigen::Vector3d(1.0, 0.0, 0.5));
  const RowWarp wb = rolling_shutter_warp(cam, e, Eigen::Vector3d(-0.7, 0.1, -1.0));
  const double sat = pipeline.photometric()->options().saturation;
  auto corrected = [&](const cv::Mat& frame, const RowWarp& w) {
    return photometric_rolling_reference(undistort_rolling_reference(frame, cam, map, w), fit, w, sat);
  };
  Pyramid out;
  pipeline.set_row_warp(wa);
  pipeline.process(a, out);
  const cv::Mat got_a = level0(rt, out);
  expect_matches(got_a, corrected(a, wa), "the frame, through its warp's light field");
  // The light read in place would differ (the step and the hole moved by the warp).
  size_t n = 0;
  EXPECT_GT(mean_abs_diff(got_a, photometric_reference(undistort_rolling_reference(a, cam, map, wa), fit, sat), 1, &n), 1.0);
  pipeline.keep();
  pipeline.set_row_warp(wb);
  pipeline.process(b, out);
  expect_matches(level0(rt, out), corrected(b, wb), "the next frame, its own warp");
  pipeline.reprocess_kept(out);
  expect_matches(level0(rt, out), corrected(a, wa), "the kept frame keeps its warp's light field");
  pipeline.set_row_warp(identity_row_warp(cam.width, cam.height));
  pipeline.reprocess(out);
  expect_matches(level0(rt, out), photometric_reference(undistort_reference(b, map), fit, sat), "the identity warp");
}

}  // namespace
}  // namespace planarvo
