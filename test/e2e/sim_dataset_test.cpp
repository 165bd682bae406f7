// simulate(): a short data set written, opened with io::Dataset and checked against the
// trajectory it was made from; deterministic for a seed; cancellable.
#include <chrono>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "core/error.h"
#include "io/dataset/dataset.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"

namespace planarvo::sim {
namespace {

namespace fs = std::filesystem;

Options small_options(uint64_t seed) {
  Options o;
  o.texture = test::texture("asphalt_01.png").string();
  o.camera = default_camera(160, 120);
  o.seconds = 1.0;
  o.seed = seed;
  return o;
}

TEST(SimDataset, WritesAReadableDataSet) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  const Options o = small_options(3);
  double last_fraction = -1;
  Options with_progress = o;
  with_progress.progress = [&](double f, const char*) {
    EXPECT_GE(f, last_fraction);
    last_fraction = f;
    return true;
  };
  SimulationStats stats;
  simulate(rt, with_progress, dir.path().string(), &stats);
  EXPECT_EQ(last_fraction, 1.0);
  EXPECT_EQ(stats.frames, 30);
  for (const char* f : {"camera.yaml", "frames.txt", "odometry.txt", "direction.txt",
                        "groundtruth.txt", "extrinsics_gt.yaml", "simulation.yaml",
                        "images/000000.png", "images/000029.png"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;

  io::Dataset ds(dir.path().string(), {});
  ASSERT_EQ(ds.frame_count(), 30);
  EXPECT_EQ(ds.camera().width, 160);
  EXPECT_NEAR(ds.camera().fx, o.camera.fx, 1e-9 * o.camera.fx);
  EXPECT_NEAR(ds.camera().k1, o.camera.k1, 1e-12);
  ASSERT_TRUE(ds.extrinsics_gt().has_value());
  EXPECT_NEAR(ds.extrinsics_gt()->value.pitch, o.extrinsics.pitch, 1e-12);
  EXPECT_NEAR(ds.extrinsics_gt()->value.x, o.extrinsics.x, 1e-12);
  ASSERT_TRUE(ds.has_groundtruth() && ds.has_odometry() && ds.has_direction());

  const Trajectory tr = generate_trajectory(o);
  for (int64_t i = 0; i < ds.frame_count(); ++i) {
    const size_t k = static_cast<size_t>(i);
    EXPECT_NEAR(ds.timestamp(i), tr.t[k], 1e-9);
    const SE2 g = *ds.groundtruth_at(i), od = *ds.odometry_at(i);
    EXPECT_NEAR(g.x, tr.pose[k].x, 1e-9);
    EXPECT_NEAR(g.y, tr.pose[k].y, 1e-9);
    EXPECT_NEAR(wrap_angle(g.theta - tr.pose[k].theta), 0.0, 1e-9);
    EXPECT_NEAR(od.x, tr.odometry[k].x, 1e-9);
    EXPECT_NEAR(wrap_angle(od.theta - tr.odometry[k].theta), 0.0, 1e-9);
    if (i > 0) {
      const std::optional<int> d = ds.direction_for_interval(i);
      ASSERT_TRUE(d.has_value());
      EXPECT_EQ(*d, tr.direction[k - 1]);
    }
    const cv::Mat img = ds.frame(i);
    EXPECT_EQ(img.size(), cv::Size(160, 120));
  }
  // The images are the renders plus the camera's gain, offset and noise: a residual of about
  // the noise's size (1 grey level, plus rounding), a gain within its 5 %.
  Renderer renderer(rt, cv::imread(o.texture, cv::IMREAD_GRAYSCALE), o);
  const cv::Mat clean = renderer.render_float(tr.pose[17]);
  cv::Mat img;
  ds.frame(17).convertTo(img, CV_32F);
  const std::vector<Exposure> ex = exposure_series(o, tr.t);
  cv::Scalar mean, sd;
  cv::meanStdDev(img - (clean * ex[17].gain + ex[17].offset), mean, sd);
  EXPECT_NEAR(mean[0], 0.0, 0.1);
  EXPECT_NEAR(sd[0], std::sqrt(1.0 + 1.0 / 12), 0.1);
}

TEST(SimDataset, DeterministicForASeed) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  Options o = small_options(5);
  o.seconds = 0.2;
  simulate(rt, o, (dir / "a").string());
  simulate(rt, o, (dir / "b").string());
  o.seed = 6;
  simulate(rt, o, (dir / "c").string());
  for (const char* f : {"images/000000.png", "images/000005.png"}) {
    const cv::Mat a = cv::imread((dir / "a" / f).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat b = cv::imread((dir / "b" / f).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat c = cv::imread((dir / "c" / f).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << f;
    EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0) << f;
  }
}

TEST(SimDataset, CancelledByProgress) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  Options o = small_options(1);
  int calls = 0;
  o.progress = [&](double, const char*) { return ++calls < 5; };
  try {
    simulate(rt, o, dir.path().string());
    FAIL() << "not cancelled";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Cancelled);
  }
  EXPECT_FALSE(fs::exists(dir / "frames.txt"));
}

TEST(SimDataset, RejectsBadInput) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  Options o = small_options(1);
  o.texture = (dir / "missing.png").string();
  try {
    simulate(rt, o, (dir / "out").string());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidInput);
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos);
  }
  o = small_options(1);
  o.texture.clear();
  EXPECT_THROW(simulate(rt, o, (dir / "out").string()), Error);
}

// The full-size default: 10 s of 640x480 at 30 Hz. Run by hand for the timing:
//   planarvo_test_e2e --gtest_also_run_disabled_tests --gtest_filter='*TenSeconds*'
TEST(SimDataset, DISABLED_TenSecondsDefault) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  Options o;
  o.texture = test::texture("asphalt_01.png").string();
  SimulationStats st;
  const auto t0 = std::chrono::steady_clock::now();
  simulate(rt, o, dir.path().string(), &st);
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%lld frames 640x480: total %.1f s; setup %.2f s, render %.1f s, camera %.1f s, "
              "write %.1f s\n", static_cast<long long>(st.frames), total, st.setup, st.render,
              st.camera, st.write);
  EXPECT_EQ(st.frames, 300);
}

}  // namespace
}  // namespace planarvo::sim
