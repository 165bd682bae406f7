// `planarvo devices`, `info`, `simulate`, `kernels --export` and `demo` as a user runs them,
// compared value by value with the same things through the C API (planarvo_list_devices,
// planarvo_dataset_info_get, planarvo_tracker_track, planarvo_calibrate_dataset) and with
// independent references: the values the test wrote into a data set, the simulator's options and
// ground truth, drive figures recomputed here from the data set, images rendered with kernels
// compiled at run time.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/capi_util.h"
#include "common/printed_values.h"
#include "common/test_util.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::expect_printed;
using test::numbers_after;
using test::run_cli;
using test::ScratchDir;

constexpr double kDeg = M_PI / 180.0;

std::string read(const fs::path& p) { return test::read_file(p); }

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

TEST(CliData, DevicesPrintsWhatTheCApiLists) {
  const auto r = run_cli("devices");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  size_t n = 0;
  ASSERT_EQ(planarvo_list_devices(nullptr, 0, &n), PLANARVO_OK) << planarvo_last_error();
  ASSERT_GT(n, 0u);
  std::vector<planarvo_device_info> devices(n);
  for (auto& d : devices) d.struct_size = sizeof d;
  ASSERT_EQ(planarvo_list_devices(devices.data(), n, &n), PLANARVO_OK) << planarvo_last_error();
  const std::vector<std::string> lines = lines_of(r.output);
  ASSERT_EQ(lines.size(), 3 * n) << r.output;  // three lines per device
  bool pocl = false;
  for (size_t i = 0; i < n; ++i) {
    const planarvo_device_info& d = devices[i];
    const std::string& first = lines[3 * i];
    EXPECT_EQ(test::numbers_in(first).at(0), d.index) << first;
    EXPECT_NE(first.find(std::string(d.platform_name) + " / " + d.device_name), std::string::npos) << first;
    EXPECT_NE(first.find(d.device_type), std::string::npos) << first;
    EXPECT_NE(lines[3 * i + 1].find(d.device_version), std::string::npos) << lines[3 * i + 1];
    EXPECT_NE(lines[3 * i + 1].find(d.driver_version), std::string::npos) << lines[3 * i + 1];
    const std::string& third = lines[3 * i + 2];
    EXPECT_EQ(numbers_after(third, "max work-group").at(0), static_cast<double>(d.max_work_group_size)) << third;
    EXPECT_EQ(numbers_after(third, "compute units").at(0), d.compute_units) << third;
    EXPECT_NE(third.find(std::string("fp64 ") + (d.fp64 ? "yes" : "no")), std::string::npos) << third;
    EXPECT_EQ(third.find("kernels cached by the driver") != std::string::npos, d.driver_caches_kernels != 0) << third;
    pocl = pocl || std::string(d.platform_name) == "Portable Computing Language";
  }
  EXPECT_TRUE(pocl) << r.output;  // the CI machine's CPU device
}

// The "camera" line of `info` against a camera.
void expect_camera_line(const std::string& output, const planarvo_camera& c) {
  const std::string line = test::line_with(output, "  camera ");
  EXPECT_NE(line.find(std::to_string(c.width) + "x" + std::to_string(c.height) + ","), std::string::npos) << line;
  const std::vector<double> v = numbers_after(line, ", fx");
  ASSERT_EQ(v.size(), 9u) << line;
  const double expected[4] = {c.fx, c.fy, c.cx, c.cy};
  for (int i = 0; i < 4; ++i) expect_printed(v[static_cast<size_t>(i)], expected[i], 2, line);
  const double distortion[5] = {c.k1, c.k2, c.p1, c.p2, c.k3};
  for (int i = 0; i < 5; ++i)  // %.4g
    EXPECT_NEAR(v[static_cast<size_t>(4 + i)], distortion[i], 5e-4 * std::abs(distortion[i]) + 1e-300) << line;
}

void expect_frames_line(const std::string& output, const planarvo_dataset_info& info) {
  const std::vector<double> v = numbers_after(output, "  frames ");
  ASSERT_EQ(v.size(), 3u) << output;
  const double span = info.last_timestamp - info.first_timestamp;
  EXPECT_EQ(v[0], static_cast<double>(info.frame_count));
  expect_printed(v[1], span, 3, "time span");
  expect_printed(v[2], static_cast<double>(info.frame_count - 1) / span, 2, "frame rate");
}

void expect_yes_no(const std::string& output, const std::string& label, int has) {
  const std::string line = test::line_with(output, "  " + label + " ");
  EXPECT_EQ(line.substr(line.find_last_of(' ') + 1), has ? "yes" : "no") << line;
}

TEST(CliData, InfoPrintsTheValuesTheTestWroteAndTheCApiReads) {
  ScratchDir d;
  std::ofstream(d / "camera.yaml")
      << "%YAML:1.0\n---\nimage_width: 64\nimage_height: 48\n"
         "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
         "   data: [ 52.25, 0., 31.5, 0., 50.75, 23.25, 0., 0., 1. ]\n"
         "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n"
         "   data: [ -0.1, 0.0125, 0.001, -0.002, 0.0003 ]\n";
  fs::create_directories(d / "images");
  cv::Mat img(48, 64, CV_8UC1);
  cv::RNG rng(3);
  std::ofstream frames(d / "frames.txt");
  for (int i = 0; i < 4; ++i) {
    rng.fill(img, cv::RNG::UNIFORM, 0, 255);
    cv::imwrite((d / "images" / (std::to_string(i) + ".png")).string(), img);
    frames << 10 + 0.25 * i << " images/" << i << ".png\n";
  }
  frames.close();
  std::ofstream(d / "odometry.txt") << "10.0 0 0 0 0 0 0 1\n10.75 0.1 0 0 0 0 0 1\n";
  const auto r = run_cli("info --verify " + d.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;

  // What the test wrote: 4 frames over 0.75 s, the camera above.
  test::ApiDataset ds = test::api_dataset(d.path().string());
  ASSERT_TRUE(ds);
  const planarvo_dataset_info info = test::api_info(ds.get());
  EXPECT_EQ(info.frame_count, 4);
  EXPECT_EQ(info.last_timestamp - info.first_timestamp, 0.75);
  const planarvo_camera written{64, 48, 52.25, 50.75, 31.5, 23.25, -0.1, 0.0125, 0.001, -0.002, 0.0003, {0, 0, 0, 0}, 0.0, 0.0};
  expect_camera_line(r.output, written);
  expect_camera_line(r.output, info.camera);
  expect_frames_line(r.output, info);
  const std::vector<double> frames_line = numbers_after(r.output, "  frames ");
  ASSERT_EQ(frames_line.size(), 3u);
  EXPECT_EQ(frames_line[1], 0.75);
  EXPECT_EQ(frames_line[2], 4.0);
  expect_yes_no(r.output, "odometry", 1);
  expect_yes_no(r.output, "direction", 0);
  expect_yes_no(r.output, "groundtruth", 0);
  expect_yes_no(r.output, "extrinsics", 0);
  EXPECT_EQ(info.has_odometry, 1);
  EXPECT_EQ(info.has_direction + info.has_groundtruth + info.has_extrinsics, 0);
}

// What a drive looks like, recomputed from the data set's ground truth and labels.
struct Drive {
  double distance = 0, peak_speed = 0, peak_turn = 0;
  int forward = 0, backward = 0, still = 0;
};

Drive drive_of(planarvo_dataset* ds) {
  const planarvo_dataset_info info = test::api_info(ds);
  Drive d;
  planarvo_frame_data a{}, b{};
  EXPECT_EQ(planarvo_dataset_frame_data(ds, 0, &a), PLANARVO_OK);
  for (int64_t i = 1; i < info.frame_count; ++i, a = b) {
    EXPECT_EQ(planarvo_dataset_frame_data(ds, i, &b), PLANARVO_OK);
    const double dt = b.timestamp - a.timestamp;
    const double step = std::hypot(b.groundtruth.x - a.groundtruth.x, b.groundtruth.y - a.groundtruth.y);
    d.distance += step;
    d.peak_speed = std::max(d.peak_speed, step / dt);
    const double turn = std::remainder(b.groundtruth.theta - a.groundtruth.theta, 2 * M_PI);
    d.peak_turn = std::max(d.peak_turn, std::abs(turn) / dt);
    (b.direction > 0 ? d.forward : b.direction < 0 ? d.backward : d.still) += 1;
  }
  return d;
}

// The printed drive figures (metres, m/s, rad/s, then the three counts) against the recomputed.
void expect_drive(const std::vector<double>& v, const Drive& d) {
  ASSERT_EQ(v.size(), 6u);
  expect_printed(v[0], d.distance, 2, "distance");
  expect_printed(v[1], d.peak_speed, 2, "peak speed");
  expect_printed(v[2], d.peak_turn, 2, "peak turn rate");
  EXPECT_EQ(v[3], d.forward);
  EXPECT_EQ(v[4], d.backward);
  EXPECT_EQ(v[5], d.still);
}

// The extrinsics printed as "x %.1f mm, y %.1f mm, z %.1f mm, roll %.2f deg, ..." (or, in the
// demo, with one decimal everywhere).
void expect_extrinsics(const std::vector<double>& v, const planarvo_extrinsics& e, int mm_decimals, int deg_decimals) {
  ASSERT_EQ(v.size(), 6u);
  const double expected[6] = {e.x * 1e3, e.y * 1e3, e.z * 1e3, e.roll / kDeg, e.pitch / kDeg, e.yaw / kDeg};
  for (int i = 0; i < 6; ++i)
    expect_printed(v[static_cast<size_t>(i)], expected[i], i < 3 ? mm_decimals : deg_decimals, std::to_string(i));
}

TEST(CliData, SimulateThenInfoPrintsTheSimulatorsTruth) {
  ScratchDir d;
  const std::string out = (d / "sim").string();
  auto r = run_cli("simulate --quiet --out " + out + " --seconds 0.5 --width 160 --height 120 --fov 80 --seed 4");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("info --verify " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;

  // The simulator's options: 0.5 s at 30 fps, its camera for 160x120 and 80 degrees, its default
  // extrinsics (the paper's configuration 1).
  planarvo_sim_options so;
  planarvo_sim_options_init(&so);
  planarvo_camera camera{};
  ASSERT_EQ(planarvo_sim_default_camera(160, 120, 80, &camera), PLANARVO_OK);
  test::ApiDataset ds = test::api_dataset(out);
  ASSERT_TRUE(ds);
  const planarvo_dataset_info info = test::api_info(ds.get());
  EXPECT_EQ(info.frame_count, 15);
  expect_frames_line(r.output, info);
  expect_printed(numbers_after(r.output, "  frames ").at(2), so.fps, 2, "frame rate");
  expect_camera_line(r.output, camera);
  expect_extrinsics(numbers_after(r.output, "  true extr. "), so.extrinsics, 1, 2);
  EXPECT_EQ(info.has_extrinsics_gt, 1);
  expect_extrinsics(numbers_after(r.output, "  true extr. "), info.extrinsics_gt, 1, 2);
  expect_yes_no(r.output, "groundtruth", 1);
  expect_yes_no(r.output, "extrinsics", 0);
  expect_drive(numbers_after(r.output, "  drive "), drive_of(ds.get()));
}

// FPGA flow: export binaries, then render a data set from them without a compiler: the same
// images, bit for bit, as with kernels compiled at run time.
TEST(CliData, KernelBinariesRenderWhatRunTimeCompiledKernelsRender) {
  ScratchDir d;
  const std::string bins = (d / "bins").string();
  auto r = run_cli("kernels --export " + bins);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::exists(d / "bins" / "planarvo-kernels.txt"));
  const std::string sim = " --seconds 0.2 --width 96 --height 64 --seed 9 --out ";
  r = run_cli("simulate --quiet --no-cache --kernel-binaries " + bins + sim + (d / "from_bins").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("simulate --quiet --no-cache" + sim + (d / "compiled").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read(d / "from_bins" / "groundtruth.txt"), read(d / "compiled" / "groundtruth.txt"));
  int images = 0;
  for (const auto& e : fs::directory_iterator(d / "compiled" / "images")) {
    const cv::Mat a = cv::imread(e.path().string(), cv::IMREAD_UNCHANGED);
    const cv::Mat b = cv::imread((d / "from_bins" / "images" / e.path().filename()).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(a.empty());
    ASSERT_EQ(a.size(), b.size()) << e.path();
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << e.path();
    ++images;
  }
  EXPECT_EQ(images, 6);
  // A directory without binaries: a clear error naming the program.
  fs::create_directories(d / "empty");
  r = run_cli("simulate --quiet --no-cache --kernel-binaries " + (d / "empty").string() + sim + (d / "sim2").string());
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("render"), std::string::npos) << r.output;
}

// Wheel odometry against ground truth as the demo reports it: end-point error, heading error and
// per-interval RMS translation error, over the whole drive.
std::vector<double> wheel_odometry_errors(planarvo_dataset* ds) {
  const planarvo_dataset_info info = test::api_info(ds);
  std::vector<planarvo_frame_data> f(static_cast<size_t>(info.frame_count));
  for (size_t i = 0; i < f.size(); ++i)
    EXPECT_EQ(planarvo_dataset_frame_data(ds, static_cast<int64_t>(i), &f[i]), PLANARVO_OK);
  double sq = 0;
  for (size_t i = 1; i < f.size(); ++i) {
    const planarvo_se2 g = test::between(f[i - 1].groundtruth, f[i].groundtruth);
    const planarvo_se2 o = test::between(f[i - 1].odometry, f[i].odometry);
    sq += (g.x - o.x) * (g.x - o.x) + (g.y - o.y) * (g.y - o.y);
  }
  const planarvo_se2 g = test::between(f.front().groundtruth, f.back().groundtruth);
  const planarvo_se2 o = test::between(f.front().odometry, f.back().odometry);
  return {std::hypot(g.x - o.x, g.y - o.y), std::abs(std::remainder(g.theta - o.theta, 2 * M_PI)),
          std::sqrt(sq / static_cast<double>(f.size() - 1))};
}

// The demo's report against the same steps done here on the data set it wrote: the drive
// recomputed from its ground truth, the tracking and the calibration through the C API.
TEST(CliData, DemoPrintsWhatTheCApiComputesOnItsDataSet) {
  ScratchDir d;
  const std::string out = (d / "demo").string();
  const auto r = run_cli("demo --quiet --out " + out + " --seconds 1 --width 160 --height 120");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  planarvo_sim_options so;
  planarvo_sim_options_init(&so);
  expect_extrinsics(numbers_after(r.output, "camera at "), so.extrinsics, 1, 1);
  test::ApiDataset ds = test::api_dataset(out);
  ASSERT_TRUE(ds);
  const planarvo_dataset_info info = test::api_info(ds.get());
  const Drive drive = drive_of(ds.get());
  expect_drive(numbers_after(r.output, "the drive (ground truth):"), drive);

  // 4. tracking with the true extrinsics.
  const std::vector<test::TrackedFrame> frames = test::track_through_api(out, info.extrinsics_gt);
  long ok = 0, degraded = 0, lost = 0;
  for (const test::TrackedFrame& f : frames) {
    ok += f.result.status == PLANARVO_TRACK_OK || f.result.status == PLANARVO_TRACK_FIRST;
    degraded += f.result.status == PLANARVO_TRACK_DEGRADED;
    lost += f.result.status == PLANARVO_TRACK_LOST;
  }
  const std::vector<double> counts = numbers_after(r.output, "tracked every frame in");
  ASSERT_GE(counts.size(), 4u) << r.output;
  EXPECT_EQ(counts[1], ok);
  EXPECT_EQ(counts[2], degraded);
  EXPECT_EQ(counts[3], lost);
  const planarvo_motion_accuracy a = test::accuracy_of(frames);
  const std::vector<double> vo = numbers_after(r.output, "visual odometry (planarvo)");
  ASSERT_EQ(vo.size(), 4u) << r.output;
  expect_printed(vo[0], a.endpoint_error * 1e3, 2, "end point");
  expect_printed(vo[1], 100 * a.endpoint_drift, 3, "drift");
  expect_printed(vo[2], a.endpoint_heading / kDeg, 3, "heading");
  expect_printed(vo[3], a.rms_translation * 1e3, 4, "RMS");
  const std::vector<double> slopes = numbers_after(r.output, "velocity slopes:");
  ASSERT_EQ(slopes.size(), 4u) << r.output;  // linear, angular, the threshold (1 mm), gross
  expect_printed(slopes[0], a.slope_linear, 4, "linear slope");
  expect_printed(slopes[1], a.slope_angular, 4, "angular slope");
  EXPECT_EQ(slopes[3], a.gross_errors);

  // The wheel odometry against ground truth, recomputed.
  const std::vector<double> wheel = numbers_after(r.output, "wheel odometry (simulated,");
  ASSERT_EQ(wheel.size(), 5u) << r.output;
  expect_printed(wheel[0], 100 * so.odometry_noise, 0, "odometry noise");
  const std::vector<double> w = wheel_odometry_errors(ds.get());
  expect_printed(wheel[1], w[0] * 1e3, 2, "odometry end point");
  expect_printed(wheel[2], 100 * w[0] / drive.distance, 3, "odometry drift");
  expect_printed(wheel[3], w[1] / kDeg, 3, "odometry heading");
  expect_printed(wheel[4], w[2] * 1e3, 4, "odometry RMS");

  // 5. the calibration: estimated, true, error and sigma per parameter, or the reason it failed.
  test::ApiContext ctx = test::api_context();
  planarvo_camera_calibration_result cr{};
  cr.struct_size = sizeof cr;
  const planarvo_status st = planarvo_calibrate_dataset(ctx.get(), ds.get(), nullptr, &cr);
  if (st == PLANARVO_ERROR_FAILED) {
    EXPECT_NE(test::line_with(r.output, "not determined: " + std::string(cr.reason)), "") << r.output;
    return;
  }
  ASSERT_EQ(st, PLANARVO_OK) << planarvo_last_error();
  const planarvo_extrinsics &e = cr.extrinsics, &t = info.extrinsics_gt;
  const double est[6] = {e.x, e.y, e.z, e.roll, e.pitch, e.yaw}, tru[6] = {t.x, t.y, t.z, t.roll, t.pitch, t.yaw};
  const char* names[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  for (int i = 0; i < 6; ++i) {
    std::string label = std::string("   ") + names[i];
    label.resize(10, ' ');
    const std::string line = test::line_with(r.output, label);
    ASSERT_EQ(line.rfind(label, 0), 0u) << label << "\n" << r.output;
    const std::vector<double> v = test::numbers_in(line);
    ASSERT_EQ(v.size(), 4u) << line;
    const double k = i < 3 ? 1e3 : 1 / kDeg;
    expect_printed(v[0], est[i] * k, 3, line);
    expect_printed(v[1], tru[i] * k, 3, line);
    expect_printed(v[2], std::remainder(est[i] - tru[i], 2 * M_PI) * k, 3, line);
    expect_printed(v[3], std::sqrt(std::max(0.0, cr.covariance[i * 7])) * k, 3, line);
  }
}

}  // namespace
}  // namespace planarvo

namespace planarvo {
namespace {

// Values in the wrong unit (millimetres for metres, degrees for radians) are exit 2 naming the
// value and the mistake, and nothing is written; --force lets an unusual rig through.
TEST(CliPlausibility, UnitMistakesAreExit2AndForceLetsAnUnusualRigThrough) {
  test::ScratchDir d;
  const std::string seq = (d / "seq").string();
  auto r = test::run_cli("simulate --quiet --out " + seq + " --seconds 0.5 --width 160 --height 120 --fov 80" +
                         " --extrinsics 244.1,-18.5,178.7,12.4,17.6,-9.2");  // millimetres
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("x = 244.1 m is more than 20 m: millimetres by mistake?"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(seq));
  r = test::run_cli("simulate --quiet --out " + seq + " --seconds 0.5 --width 160 --height 120 --fov 80");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  // A height in millimetres for the calibration: refused before anything is read or written.
  const std::string out = (d / "cal.yaml").string();
  r = test::run_cli("calibrate " + seq + " --quiet --method nonholonomic --height 178.7 -o " + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("178.7 m is over 5 m: millimetres by mistake?"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  r = test::run_cli("calibrate " + seq + " --quiet --method nonholonomic --height 178.7 --force -o " + out);
  EXPECT_NE(r.exit_code, 2) << r.output;  // let through: what the drive says decides (0 or 1)
  EXPECT_EQ(std::filesystem::exists(out), r.exit_code == 0);  // a result is written only when determined

  // Extrinsics in degrees for the tracker (written as a file by the library's writer, so that it
  // is consistent): refused; with --force tracked.
  planarvo_extrinsics degrees{0.2441, -0.0185, 0.1787, 12.4, 17.6, -9.2};
  const std::string yaml = (d / "degrees.yaml").string(), traj = (d / "traj.txt").string();
  ASSERT_EQ(planarvo_extrinsics_save(yaml.c_str(), &degrees, nullptr, nullptr, nullptr, nullptr), PLANARVO_OK);
  r = test::run_cli("track " + seq + " --quiet --extrinsics " + yaml + " -o " + traj);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("roll = 12.4 rad is more than a turn: degrees by mistake?"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(traj));
  r = test::run_cli("track " + seq + " --quiet --force --extrinsics " + yaml + " -o " + traj);
  EXPECT_NE(r.exit_code, 2) << r.output;  // let through (and, being wrong, it loses frames: exit 1)
  EXPECT_TRUE(std::filesystem::exists(traj));

  // The mosaic of a good trajectory with the extrinsics in degrees: refused, nothing written; with
  // --force built.
  const std::string good = (d / "good.txt").string(), png = (d / "floor.png").string();
  r = test::run_cli("track " + seq + " --quiet --extrinsics " + seq + "/extrinsics_gt.yaml -o " + good);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_cli("mosaic " + seq + " --quiet --trajectory " + good + " --extrinsics " + yaml + " -o " + png);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("roll = 12.4 rad is more than a turn: degrees by mistake?"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(png));
  r = test::run_cli("mosaic " + seq + " --quiet --force --trajectory " + good + " --extrinsics " + yaml + " -o " + png);
  EXPECT_NE(r.exit_code, 2) << r.output;
  EXPECT_EQ(std::filesystem::exists(png), r.exit_code == 0);  // written when some frame landed
}

}  // namespace
}  // namespace planarvo
