// The camera calibration from images (calib/pipeline.h) end to end on simulated data sets written to
// disk: through the C API against the simulator's true extrinsics and against the engine's own
// pipeline; through `planarvo calibrate DATASET`, whose written extrinsics and printed report must
// be the C API's numbers; and the bad inputs (a method's missing inputs: exit 2; a drive that does
// not determine the answer or a camera standing still: exit 1, no file written).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "calib/pipeline.h"
#include "common/printed_values.h"
#include "common/test_util.h"
#include "io/dataset/dataset.h"
#include "io/formats.h"
#include "ocl/runtime.h"
#include "planarvo/planarvo.h"
#include "sim/simulator.h"
#include "track/roll_pitch.h"

namespace planarvo::calib {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct ContextDeleter {
  void operator()(planarvo_context* c) const { planarvo_context_destroy(c); }
};
struct DatasetDeleter {
  void operator()(planarvo_dataset* d) const { planarvo_dataset_destroy(d); }
};

sim::Options drive(double seconds, sim::MotionProfile motion, uint64_t seed) {
  sim::Options o;
  o.texture = test::texture("asphalt_01.png").string();
  o.camera = sim::default_camera(320, 240);
  o.extrinsics = sim::paper_configuration(3);
  o.seconds = seconds;
  o.seed = seed;
  o.motion = motion;
  o.supersampling = 2;
  o.odometry_noise = 0.02;
  return o;
}

planarvo_camera_calibration_result calibrate_c(const std::string& dir, planarvo_status* status,
                                               const planarvo_camera_calibration_options& o) {
  planarvo_context* ctx = nullptr;
  EXPECT_EQ(planarvo_context_create(nullptr, &ctx), PLANARVO_OK) << planarvo_last_error();
  std::unique_ptr<planarvo_context, ContextDeleter> context(ctx);
  planarvo_dataset* ds = nullptr;
  EXPECT_EQ(planarvo_dataset_open(dir.c_str(), nullptr, &ds), PLANARVO_OK) << planarvo_last_error();
  std::unique_ptr<planarvo_dataset, DatasetDeleter> dataset(ds);
  planarvo_camera_calibration_result r{};
  r.struct_size = sizeof r;
  *status = planarvo_calibrate_dataset(ctx, ds, &o, &r);
  return r;
}

planarvo_camera_calibration_result calibrate_c(const std::string& dir, planarvo_status* status,
                                               planarvo_calibration_method method = PLANARVO_CALIBRATE_ODOMETRY,
                                               double height = 0) {
  planarvo_camera_calibration_options o;
  planarvo_camera_calibration_options_init(&o);
  o.method = method;
  o.height = height;
  return calibrate_c(dir, status, o);
}

// Stage 1 alone on a data set's frames, from straight down (the preconditions of the tests of
// the pipeline's other starts).
track::RollPitchResult roll_pitch_from_straight_down(ocl::Runtime& rt, const std::string& dir) {
  io::Dataset ds(dir);
  track::RollPitchEstimator alone(rt, ds.camera());
  for (int64_t i = 0; i < ds.frame_count(); ++i) {
    const cv::Mat f = ds.frame(i);
    if (alone.add_frame(f.data, f.cols, f.rows, f.step, ds.timestamp(i))) break;
  }
  return alone.estimate();
}

// The tool's printed report against the C API's result: the stage counts and, per parameter,
// the value and sigma to the digits printed.
void expect_printed_report(const std::string& output, const planarvo_camera_calibration_result& r) {
  const std::vector<double> tracking = test::numbers_after(output, "tracking: ");
  ASSERT_GE(tracking.size(), 5u) << output;
  EXPECT_EQ(tracking[0], r.frames);
  EXPECT_EQ(tracking[1], r.frames_ok);
  EXPECT_EQ(tracking[2], r.frames_degraded);
  EXPECT_EQ(tracking[3], r.frames_lost);
  EXPECT_EQ(tracking[4], r.samples);
  const std::vector<double> graph = test::numbers_after(output, "graph calibration: ");
  ASSERT_GE(graph.size(), 3u) << output;
  EXPECT_EQ(graph[0], r.graph.total_iterations);
  EXPECT_EQ(graph[1], r.graph.outliers);
  EXPECT_NEAR(graph[2], r.graph.variance_factor, 5e-3 * r.graph.variance_factor);  // %.3g
  const double v[6] = {r.extrinsics.x, r.extrinsics.y, r.extrinsics.z, r.extrinsics.roll, r.extrinsics.pitch,
                       r.extrinsics.yaw};
  const char* names[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  for (int i = 0; i < 6; ++i) {
    std::string label = std::string("  ") + names[i];
    label.resize(8, ' ');
    const std::string line = test::line_with(output, label);
    ASSERT_EQ(line.rfind(label, 0), 0u) << label << "\n" << output;
    const std::vector<double> p = test::numbers_in(line);
    ASSERT_EQ(p.size(), 2u) << line;
    const double k = i < 3 ? 1e3 : 1 / kDeg;
    test::expect_printed(p[0], v[i] * k, 3, line);
    test::expect_printed(p[1], std::sqrt(r.covariance[i * 7]) * k, 3, line);
  }
}

TEST(CalibrateDataset, OdometryMethodThroughTheCApiAndTheTool) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  const sim::Options so = drive(8.0, sim::MotionProfile::Mixed, 11);
  sim::simulate(rt, so, dir.path().string());
  const Extrinsics& t = so.extrinsics;

  planarvo_status st;
  const planarvo_camera_calibration_result r = calibrate_c(dir.path().string(), &st);
  ASSERT_EQ(st, PLANARVO_OK) << planarvo_last_error();
  ASSERT_EQ(r.status, PLANARVO_CALIBRATION_OK);
  const planarvo_extrinsics& e = r.extrinsics;
  // 8 s at 320x240 with 2 % odometry noise: looser than the 20 s figures of the README.
  EXPECT_LT(std::abs(e.roll - t.roll), 0.1 * kDeg);
  EXPECT_LT(std::abs(e.pitch - t.pitch), 0.1 * kDeg);
  EXPECT_LT(std::abs(e.x - t.x), 3e-3);
  EXPECT_LT(std::abs(e.y - t.y), 3e-3);
  EXPECT_LT(std::abs(e.z - t.z), 2e-3);
  EXPECT_LT(std::abs(std::remainder(e.yaw - t.yaw, 2 * M_PI)), 0.3 * kDeg);
  for (int i = 0; i < 6; ++i) {
    EXPECT_TRUE(r.estimated[i]) << i;
    EXPECT_TRUE(r.observable[i]) << i;
    EXPECT_GT(r.covariance[i * 7], 0.0) << i;
  }
  EXPECT_EQ(r.frames, static_cast<int>(std::lround(so.seconds * so.fps)));
  EXPECT_GT(r.samples, r.frames - 5);

  // The C API is a translation of the engine's pipeline: the same numbers.
  io::Dataset ds(dir.path().string());
  const PipelineReport p = calibrate_dataset(rt, ds, PipelineOptions());
  ASSERT_TRUE(p.ok()) << p.reason;
  EXPECT_NEAR(p.extrinsics.value.x, e.x, 1e-12);
  EXPECT_NEAR(p.extrinsics.value.yaw, e.yaw, 1e-12);
  EXPECT_NEAR(p.extrinsics.value.roll, e.roll, 1e-12);
  EXPECT_NEAR(p.extrinsics.covariance(2, 2), r.covariance[14], 1e-18);

  // The tool writes what the C API computes.
  const std::string out = (dir / "calibrated.yaml").string();
  const test::CommandResult c = test::run_cli("calibrate \"" + dir.path().string() + "\" --quiet -o \"" + out + "\"");
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const ExtrinsicsEstimate f = io::read_extrinsics_yaml(out);
  EXPECT_NEAR(f.value.x, e.x, 1e-12);
  EXPECT_NEAR(f.value.y, e.y, 1e-12);
  EXPECT_NEAR(f.value.z, e.z, 1e-12);
  EXPECT_NEAR(f.value.roll, e.roll, 1e-12);
  EXPECT_NEAR(f.value.pitch, e.pitch, 1e-12);
  EXPECT_NEAR(f.value.yaw, e.yaw, 1e-12);
  for (int i = 0; i < 36; ++i) EXPECT_NEAR(f.covariance(i / 6, i % 6), r.covariance[i], 1e-20) << i;
  EXPECT_EQ(f.estimated, (std::array<bool, 6>{true, true, true, true, true, true}));
  expect_printed_report(c.output, r);

  // The other route: track at the camera's own frame (true tilt, x = y = 0, z = 1, yaw = 0), write
  // the motions with --motions-out, calibrate from the CSV: x, y, height and yaw again.
  ExtrinsicsEstimate virtual_frame;
  virtual_frame.value = Extrinsics{0, 0, 1, t.roll, t.pitch, 0};
  io::write_extrinsics_yaml((dir / "virtual.yaml").string(), virtual_frame);
  const std::string pairs = (dir / "pairs.csv").string();
  ASSERT_EQ(test::run_cli("track \"" + dir.path().string() + "\" --quiet --extrinsics \"" + (dir / "virtual.yaml").string() +
                          "\" --motions-out \"" + pairs + "\"").exit_code, 0);
  const std::string from_pairs = (dir / "from_pairs.yaml").string();
  const test::CommandResult cp = test::run_cli("calibrate --motions \"" + pairs + "\" -o \"" + from_pairs + "\"");
  ASSERT_EQ(cp.exit_code, 0) << cp.output;
  const ExtrinsicsEstimate g = io::read_extrinsics_yaml(from_pairs);
  EXPECT_LT(std::abs(g.value.x - t.x), 3e-3);
  EXPECT_LT(std::abs(g.value.y - t.y), 3e-3);
  EXPECT_LT(std::abs(g.value.z - t.z), 2e-3);
  EXPECT_LT(std::abs(std::remainder(g.value.yaw - t.yaw, 2 * M_PI)), 0.3 * kDeg);

  // The README's route: track with the true extrinsics themselves. --motions-out writes the
  // camera's own motions whatever extrinsics it tracked with, so the calibration is the same
  // (before, it came out x = y = 0, yaw = 0 and a "scale" of 1 m).
  const std::string pairs_gt = (dir / "pairs_gt.csv").string(), from_gt = (dir / "from_gt.yaml").string();
  ASSERT_EQ(test::run_cli("track \"" + dir.path().string() + "\" --quiet --extrinsics \"" +
                          (dir / "extrinsics_gt.yaml").string() + "\" --motions-out \"" + pairs_gt + "\"").exit_code, 0);
  const test::CommandResult cg = test::run_cli("calibrate --motions \"" + pairs_gt + "\" -o \"" + from_gt + "\"");
  ASSERT_EQ(cg.exit_code, 0) << cg.output;
  const ExtrinsicsEstimate h = io::read_extrinsics_yaml(from_gt);
  EXPECT_LT(std::abs(h.value.x - t.x), 3e-3);
  EXPECT_LT(std::abs(h.value.y - t.y), 3e-3);
  EXPECT_LT(std::abs(h.value.z - t.z), 2e-3);
  EXPECT_LT(std::abs(std::remainder(h.value.yaw - t.yaw, 2 * M_PI)), 0.3 * kDeg);

  // Bad usage: exit 2 and nothing written.
  std::filesystem::remove(out);
  EXPECT_EQ(test::run_cli("calibrate \"" + dir.path().string() + "\" --method nonholonomic -o \"" + out + "\"").exit_code, 2);
  std::filesystem::remove(dir / "odometry.txt");
  EXPECT_EQ(test::run_cli("calibrate \"" + dir.path().string() + "\" --quiet -o \"" + out + "\"").exit_code, 2);
  std::filesystem::remove(dir / "direction.txt");
  EXPECT_EQ(test::run_cli("calibrate \"" + dir.path().string() + "\" --method nonholonomic --height 0.15 --quiet -o \"" +
                          out + "\"").exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CalibrateDataset, NonholonomicMethodWithTheHeightGiven) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  const sim::Options so = drive(8.0, sim::MotionProfile::Mixed, 12);
  sim::simulate(rt, so, dir.path().string());
  std::filesystem::remove(dir / "odometry.txt");  // the method must not need it
  const Extrinsics& t = so.extrinsics;
  planarvo_status st;
  const planarvo_camera_calibration_result r =
      calibrate_c(dir.path().string(), &st, PLANARVO_CALIBRATE_NONHOLONOMIC, t.z);
  ASSERT_EQ(st, PLANARVO_OK) << planarvo_last_error();
  EXPECT_LT(std::abs(r.extrinsics.roll - t.roll), 0.1 * kDeg);
  EXPECT_LT(std::abs(r.extrinsics.pitch - t.pitch), 0.1 * kDeg);
  EXPECT_LT(std::abs(r.extrinsics.x - t.x), 3e-3);
  EXPECT_LT(std::abs(r.extrinsics.y - t.y), 10e-3);
  EXPECT_EQ(r.extrinsics.z, t.z);
  EXPECT_LT(std::abs(std::remainder(r.extrinsics.yaw - t.yaw, 2 * M_PI)), 0.3 * kDeg);
  EXPECT_FALSE(r.estimated[2]);  // the height was given
  EXPECT_EQ(r.covariance[14], 0.0);
}

TEST(CalibrateDataset, StraightDrivingIsUnobservableExit1AndNoFile) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  sim::simulate(rt, drive(4.0, sim::MotionProfile::Straight, 13), dir.path().string());
  planarvo_status st;
  const planarvo_camera_calibration_result r = calibrate_c(dir.path().string(), &st);
  EXPECT_EQ(st, PLANARVO_ERROR_FAILED);
  EXPECT_EQ(r.status, PLANARVO_CALIBRATION_UNOBSERVABLE);
  EXPECT_TRUE(r.estimated[0]);
  EXPECT_FALSE(r.observable[0]);  // x and y need turns
  const std::string out = (dir / "calibrated.yaml").string();
  const test::CommandResult c = test::run_cli("calibrate \"" + dir.path().string() + "\" --quiet -o \"" + out + "\"");
  EXPECT_EQ(c.exit_code, 1) << c.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// Stage 2 tracks with the roll and pitch of stage 1 (or given): when it loses most frames they do
// not describe the camera, and the graph's answer from the intervals left is not to be written
// (found on a camera 8 cm high over black planks under its own lamp and reflection: roll 30.8 deg
// off, 234 of 300 frames lost, a result written with sigmas of 0.06 deg). Here roll and pitch
// given 20 deg off the simulator's truth: FAILED naming the frames lost; the truth: OK.
TEST(CalibrateDataset, ATiltThatTrackingCannotHoldIsFailedNotWritten) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  const sim::Options so = drive(4.0, sim::MotionProfile::Mixed, 15);
  sim::simulate(rt, so, dir.path().string());
  const Extrinsics& t = so.extrinsics;
  const auto calibrate_with = [&](double roll, double pitch, planarvo_status* st) {
    planarvo_camera_calibration_options o;
    planarvo_camera_calibration_options_init(&o);
    o.estimate_roll_pitch = 0;
    o.has_initial = 1;
    o.initial = {t.x, t.y, t.z, roll, pitch, t.yaw};
    return calibrate_c(dir.path().string(), st, o);
  };
  planarvo_status st;
  const planarvo_camera_calibration_result wrong = calibrate_with(t.roll + 20 * kDeg, t.pitch - 20 * kDeg, &st);
  EXPECT_EQ(st, PLANARVO_ERROR_FAILED);
  EXPECT_EQ(wrong.status, PLANARVO_CALIBRATION_FAILED);
  EXPECT_GT(2 * wrong.frames_lost, wrong.frames) << wrong.reason;
  EXPECT_NE(std::string(wrong.reason).find(std::to_string(wrong.frames_lost) + " of " + std::to_string(wrong.frames)),
            std::string::npos) << wrong.reason;
  const planarvo_camera_calibration_result right = calibrate_with(t.roll, t.pitch, &st);
  EXPECT_EQ(st, PLANARVO_OK) << right.reason;
  EXPECT_EQ(right.frames_lost, 0);
}

// Stage 1 from straight down does not converge on every rig: a car at 15 fps with its camera
// pitched 35 deg over gravel failed ("the keyframes do not align" on a 10-s drive; on this 6-s one
// "moved too little": 2 keyframes, the map's tracker at 35 deg off losing the frames). The
// pipeline then tries other starting tilts on the frames it holds. The precondition is checked
// here (the estimator alone, from straight down, fails on this drive); the calibration then finds
// the simulator's truth.
TEST(CalibrateDataset, RollAndPitchFromAnotherStartWhenStraightDownFails) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  sim::Options so = drive(6.0, sim::MotionProfile::Car, 16);
  so.texture = test::texture("skimage_gravel.png").string();
  so.camera = sim::default_camera(640, 480);
  so.min_turn_radius = 1.0;
  so.fps = 15;
  so.extrinsics = {0.3, 0.0, 0.25, 0.0, 35 * kDeg, 0.0};
  sim::simulate(rt, so, dir.path().string());
  const track::RollPitchResult first = roll_pitch_from_straight_down(rt, dir.path().string());
  ASSERT_FALSE(first.ok()) << "the drive no longer needs another start; make it harder: " << first.roll / kDeg
                           << " " << first.pitch / kDeg;
  planarvo_status st;
  const planarvo_camera_calibration_result r = calibrate_c(dir.path().string(), &st);
  ASSERT_EQ(st, PLANARVO_OK) << r.reason;
  EXPECT_LT(std::abs(r.extrinsics.roll - so.extrinsics.roll), 0.1 * kDeg);
  EXPECT_LT(std::abs(r.extrinsics.pitch - so.extrinsics.pitch), 0.1 * kDeg);
  EXPECT_EQ(r.frames_lost, 0);
}

// Stage 1 can also succeed on a wrong minimum: a camera 8 cm high behind the axle over black
// planks under its own lamp and reflection gave roll and pitch 30.8 and 19.4 deg off from straight
// down, with which stage 2 lost 234 of 300 frames. The pipeline sees stage 2 lose the held frames,
// runs stage 1 from the other starts and keeps the one stage 2 holds. The precondition is checked
// (the estimator alone, from straight down, ends over 5 deg off); the calibration then finds the
// simulator's truth. (640x480: at 320x240 the first start is already right.)
TEST(CalibrateDataset, AStage1MinimumThatStage2CannotHoldIsLeftForAnotherStart) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  sim::Options so = drive(4.0, sim::MotionProfile::Mixed, 1);
  so.texture = test::texture("black_painted_planks.png").string();
  so.camera = sim::default_camera(640, 480);
  so.odometry_noise = 0.01;
  so.extrinsics = {-0.15, 0.05, 0.08, -5 * kDeg, 30 * kDeg, 170 * kDeg};
  so.lamp_falloff = 0.6;
  so.reflection = 40;
  sim::simulate(rt, so, dir.path().string());
  const track::RollPitchResult first = roll_pitch_from_straight_down(rt, dir.path().string());
  ASSERT_TRUE(first.ok()) << first.reason;
  ASSERT_GT(std::abs(first.roll - so.extrinsics.roll) + std::abs(first.pitch - so.extrinsics.pitch), 5 * kDeg)
      << "the first start is no longer wrong on this drive; make it harder";
  planarvo_status st;
  const planarvo_camera_calibration_result r = calibrate_c(dir.path().string(), &st);
  ASSERT_EQ(st, PLANARVO_OK) << r.reason;
  EXPECT_LT(std::abs(r.extrinsics.roll - so.extrinsics.roll), 0.1 * kDeg);
  EXPECT_LT(std::abs(r.extrinsics.pitch - so.extrinsics.pitch), 0.1 * kDeg);
  EXPECT_LT(std::abs(r.extrinsics.z - so.extrinsics.z), 1e-3);
  EXPECT_EQ(r.frames_lost, 0);
}

TEST(CalibrateDataset, StandingStillIsTooLittleMotionExit1) {
  // A data set whose every frame is the same image: nothing moves.
  test::ScratchDir dir;
  ocl::Runtime rt;
  const sim::Options so = drive(2.0, sim::MotionProfile::Mixed, 14);
  sim::simulate(rt, so, dir.path().string());
  std::ifstream in(dir / "frames.txt");
  std::string first_line, line;
  std::getline(in, first_line);
  while (first_line.rfind('#', 0) == 0) std::getline(in, first_line);
  const std::string image = first_line.substr(first_line.find(' ') + 1);
  in.close();
  {
    std::ofstream f(dir / "frames.txt");
    for (int k = 0; k < 60; ++k) f << k / 30.0 << " " << image << "\n";
  }
  planarvo_status st;
  const planarvo_camera_calibration_result r = calibrate_c(dir.path().string(), &st);
  EXPECT_EQ(st, PLANARVO_ERROR_FAILED);
  EXPECT_EQ(r.status, PLANARVO_CALIBRATION_TOO_LITTLE_MOTION) << r.reason;
  const std::string out = (dir / "calibrated.yaml").string();
  EXPECT_EQ(test::run_cli("calibrate \"" + dir.path().string() + "\" --quiet -o \"" + out + "\"").exit_code, 1);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CalibrateDataset, StagesAndStreamThroughTheCApiEqualThePipeline) {
  test::ScratchDir dir;
  {
    ocl::Runtime rt;
    sim::simulate(rt, drive(6.0, sim::MotionProfile::Mixed, 15), dir.path().string());
  }
  planarvo_status st;
  const planarvo_camera_calibration_result whole = calibrate_c(dir.path().string(), &st);
  ASSERT_EQ(st, PLANARVO_OK) << planarvo_last_error();

  planarvo_context* ctx = nullptr;
  ASSERT_EQ(planarvo_context_create(nullptr, &ctx), PLANARVO_OK);
  std::unique_ptr<planarvo_context, ContextDeleter> context(ctx);
  planarvo_dataset* ds = nullptr;
  ASSERT_EQ(planarvo_dataset_open(dir.path().string().c_str(), nullptr, &ds), PLANARVO_OK);
  std::unique_ptr<planarvo_dataset, DatasetDeleter> dataset(ds);
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  ASSERT_EQ(planarvo_dataset_info_get(ds, &info), PLANARVO_OK);

  // The stream: the same frames, odometry and labels, one at a time. Its graph options are an
  // initialised struct where the whole run had none: the defaults are the init function's, so
  // the odometry's noise is fitted as it is without them (issue 26: a struct passed once lost it).
  planarvo_calibration_options stream_graph;
  planarvo_calibration_options_init(&stream_graph);
  planarvo_camera_calibration_options stream_options;
  planarvo_camera_calibration_options_init(&stream_options);
  stream_options.graph = &stream_graph;
  planarvo_camera_calibrator* cal = nullptr;
  ASSERT_EQ(planarvo_camera_calibrator_create(ctx, &info.camera, &stream_options, &cal), PLANARVO_OK)
      << planarvo_last_error();
  for (int64_t i = 0; i < info.frame_count; ++i) {
    planarvo_frame_data fd{};
    ASSERT_EQ(planarvo_dataset_frame_data(ds, i, &fd), PLANARVO_OK);
    planarvo_image img{};
    ASSERT_EQ(planarvo_dataset_frame(ds, i, &img), PLANARVO_OK);
    ASSERT_EQ(planarvo_camera_calibrator_add_frame(cal, &img, fd.timestamp, fd.has_odometry ? &fd.odometry : nullptr,
                                                   fd.has_direction ? &fd.direction : nullptr),
              PLANARVO_OK)
        << planarvo_last_error();
  }
  planarvo_camera_calibration_result streamed{};
  streamed.struct_size = sizeof streamed;
  ASSERT_EQ(planarvo_camera_calibrator_finish(cal, &streamed), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(planarvo_camera_calibrator_finish(cal, &streamed), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_camera_calibrator_destroy(cal);
  for (int i = 0; i < 36; ++i) EXPECT_EQ(streamed.covariance[i], whole.covariance[i]) << i;
  EXPECT_EQ(streamed.extrinsics.x, whole.extrinsics.x);
  EXPECT_EQ(streamed.extrinsics.yaw, whole.extrinsics.yaw);

  // A stream whose odometry comes as samples of its own (a ROS topic): odometry.txt's samples,
  // each given just before the first frame it reaches, and the frames without a pose. The
  // calibrator interpolates them as the data set does, so the result is the same, bit for bit.
  size_t n_odometry = 0;
  const std::string odometry_path = (dir / "odometry.txt").string();
  ASSERT_EQ(planarvo_read_tum(odometry_path.c_str(), nullptr, nullptr, 0, &n_odometry), PLANARVO_OK);
  std::vector<double> odometry_t(n_odometry);
  std::vector<planarvo_se2> odometry_pose(n_odometry);
  ASSERT_EQ(planarvo_read_tum(odometry_path.c_str(), odometry_t.data(), odometry_pose.data(), n_odometry, &n_odometry),
            PLANARVO_OK);
  ASSERT_EQ(planarvo_camera_calibrator_create(ctx, &info.camera, &stream_options, &cal), PLANARVO_OK);
  size_t given = 0;
  for (int64_t i = 0; i < info.frame_count; ++i) {
    planarvo_frame_data fd{};
    ASSERT_EQ(planarvo_dataset_frame_data(ds, i, &fd), PLANARVO_OK);
    while (given < n_odometry && (given == 0 || odometry_t[given - 1] < fd.timestamp)) {
      ASSERT_EQ(planarvo_camera_calibrator_add_odometry(cal, odometry_t[given], &odometry_pose[given]), PLANARVO_OK);
      ++given;
    }
    planarvo_image img{};
    ASSERT_EQ(planarvo_dataset_frame(ds, i, &img), PLANARVO_OK);
    ASSERT_EQ(planarvo_camera_calibrator_add_frame(cal, &img, fd.timestamp, nullptr,
                                                   fd.has_direction ? &fd.direction : nullptr),
              PLANARVO_OK);
  }
  // Samples out of order are refused.
  EXPECT_EQ(planarvo_camera_calibrator_add_odometry(cal, odometry_t[0], &odometry_pose[0]),
            PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_camera_calibration_result sampled{};
  sampled.struct_size = sizeof sampled;
  ASSERT_EQ(planarvo_camera_calibrator_finish(cal, &sampled), PLANARVO_OK) << planarvo_last_error();
  planarvo_camera_calibrator_destroy(cal);
  EXPECT_EQ(sampled.samples, whole.samples);
  for (int i = 0; i < 36; ++i) EXPECT_EQ(sampled.covariance[i], whole.covariance[i]) << i;
  EXPECT_EQ(sampled.extrinsics.x, whole.extrinsics.x);
  EXPECT_EQ(sampled.extrinsics.z, whole.extrinsics.z);
  EXPECT_EQ(sampled.extrinsics.yaw, whole.extrinsics.yaw);

  // The library writes the result's extrinsics.yaml: what the result holds, the method of the
  // pipeline, the notes given.
  const std::string saved = (dir / "saved.yaml").string();
  ASSERT_EQ(planarvo_camera_calibration_save(saved.c_str(), &sampled, "a stream"), PLANARVO_OK) << planarvo_last_error();
  const ExtrinsicsEstimate read = io::read_extrinsics_yaml(saved);
  EXPECT_EQ(read.value.x, sampled.extrinsics.x);
  EXPECT_EQ(read.value.pitch, sampled.extrinsics.pitch);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(read.estimated[static_cast<size_t>(i)], sampled.estimated[i] != 0) << i;
    for (int j = 0; j < 6; ++j) EXPECT_EQ(read.covariance(i, j), sampled.covariance[i * 6 + j]) << i << " " << j;
  }
  EXPECT_EQ(read.method, describe_camera_calibration(graph::CalibrationMethod::Odometry));
  EXPECT_EQ(std::string(sampled.method), read.method);
  EXPECT_EQ(read.notes, "a stream");

  // The stages by hand: motions tracked with the pipeline's roll and pitch, the graph calibration
  // with the odometry's noise estimated, the composition.
  const planarvo_extrinsics frame{0, 0, 1, whole.roll_pitch.roll, whole.roll_pitch.pitch, 0};
  std::vector<planarvo_motion_pair> pairs(static_cast<size_t>(info.frame_count));
  pairs[0].struct_size = sizeof(planarvo_motion_pair);
  size_t n = 0;
  EXPECT_EQ(planarvo_track_motions(ctx, ds, &frame, nullptr, pairs.data(), 3, &n), PLANARVO_ERROR_BUFFER_TOO_SMALL);
  ASSERT_EQ(planarvo_track_motions(ctx, ds, &frame, nullptr, pairs.data(), pairs.size(), &n), PLANARVO_OK)
      << planarvo_last_error();
  EXPECT_EQ(static_cast<int>(n), whole.samples);
  planarvo_calibration_options go;
  planarvo_calibration_options_init(&go);
  EXPECT_EQ(go.estimate_odometry_noise, -1);  // the workflow's choice
  // Motion pairs given: by default the odometry_sigma_* model is kept, as with 0.
  planarvo_calibration_result kept{}, zero{};
  kept.struct_size = zero.struct_size = sizeof kept;
  ASSERT_EQ(planarvo_calibrate(pairs.data(), n, &go, &kept), PLANARVO_OK) << planarvo_last_error();
  go.estimate_odometry_noise = 0;
  ASSERT_EQ(planarvo_calibrate(pairs.data(), n, &go, &zero), PLANARVO_OK) << planarvo_last_error();
  for (int i = 0; i < 16; ++i) EXPECT_EQ(kept.covariance[i], zero.covariance[i]) << i;
  go.estimate_odometry_noise = 1;
  planarvo_calibration_result g{};
  g.struct_size = sizeof g;
  ASSERT_EQ(planarvo_calibrate(pairs.data(), n, &go, &g), PLANARVO_OK) << planarvo_last_error();
  EXPECT_NE(g.covariance[0], kept.covariance[0]);  // the fit changes the covariance
  planarvo_extrinsics e{};
  double cov[36];
  int32_t estimated[6];
  ASSERT_EQ(planarvo_compose_extrinsics(whole.roll_pitch.roll, whole.roll_pitch.pitch, whole.roll_pitch.covariance, &g,
                                        &e, cov, estimated),
            PLANARVO_OK);
  EXPECT_NEAR(e.x, whole.extrinsics.x, 1e-12);
  EXPECT_NEAR(e.y, whole.extrinsics.y, 1e-12);
  EXPECT_NEAR(e.z, whole.extrinsics.z, 1e-12);
  EXPECT_NEAR(e.yaw, whole.extrinsics.yaw, 1e-12);
  EXPECT_EQ(e.roll, whole.extrinsics.roll);
  // The stages composed by hand take them as independent; the pipeline also carries the tilt's
  // share into x, y, z and yaw (calib/tilt_propagation.h), which motion pairs cannot hold: the
  // roll/pitch block is the same, and the rest of the pipeline's covariance is the hand-made one
  // plus a positive semi-definite share with the tilt's cross-covariance beside it.
  const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> W(whole.covariance), C(cov);
  EXPECT_TRUE((W.block<2, 2>(3, 3).isApprox(C.block<2, 2>(3, 3), 1e-12)));
  const int at[4] = {0, 1, 2, 5};
  Eigen::Matrix4d share;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) share(i, j) = W(at[i], at[j]) - C(at[i], at[j]);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(0.5 * (share + share.transpose()));
  EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-9 * W.diagonal().maxCoeff());
  EXPECT_GT(eig.eigenvalues().maxCoeff(), 0.0);
  for (int i = 0; i < 4; ++i)
    for (int k = 3; k < 5; ++k) {
      EXPECT_EQ(C(at[i], k), 0.0);
      // The cross-covariance is J C_rp: within what the share and the tilt's variance allow.
      EXPECT_LE(W(at[i], k) * W(at[i], k), (share(i, i) + 1e-30) * W(k, k) * (1 + 1e-9));
    }
  for (int i = 0; i < 6; ++i) EXPECT_EQ(estimated[i], whole.estimated[i]) << i;
}

}  // namespace
}  // namespace planarvo::calib
