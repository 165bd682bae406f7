// `planarvo track` as a user runs it, compared value by value with the same data set tracked
// through the C API (planarvo_tracker_track, planarvo_evaluate_motions): the TUM trajectory, every
// column of the statistics CSV, the motion pairs of --motions-out, and the printed summary and
// accuracy figures; the accuracy also against the simulator's ground truth. Exit codes for bad
// usage.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "common/capi_util.h"
#include "common/printed_values.h"
#include "common/test_util.h"
#include "io/formats.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::expect_printed;
using test::numbers_after;
using test::run_cli;
using test::ScratchDir;
using test::TrackedFrame;

constexpr double kDeg = M_PI / 180.0;

const char* status_label(planarvo_track_status s) {
  switch (s) {
    case PLANARVO_TRACK_FIRST: return "first";
    case PLANARVO_TRACK_OK: return "ok";
    case PLANARVO_TRACK_DEGRADED: return "degraded";
    case PLANARVO_TRACK_LOST: return "lost";
  }
  return "?";
}

bool tracked(const TrackedFrame& f) {
  return f.result.status == PLANARVO_TRACK_OK || f.result.status == PLANARVO_TRACK_DEGRADED;
}

// The trajectory file: one row per frame, the pose the C API reports for it.
void expect_trajectory(const std::string& path, const std::vector<TrackedFrame>& frames) {
  const std::vector<io::StampedPose> tum = io::read_tum(path);
  ASSERT_EQ(tum.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const planarvo_se2& p = frames[i].result.pose;
    EXPECT_NEAR(tum[i].t, frames[i].data.timestamp, 1e-9) << i;  // written with 9 decimals
    EXPECT_EQ(tum[i].pose.x, p.x) << i;
    EXPECT_EQ(tum[i].pose.y, p.y) << i;
    EXPECT_NEAR(tum[i].pose.theta, p.theta, 1e-14) << i;  // through sin and cos of theta / 2
  }
}

// The statistics CSV: per frame the time, the velocity over the interval ending there, the
// alignment steps over all levels, the cost, the inlier fraction, the engine time and the status.
void expect_stats(const std::string& path, const std::vector<TrackedFrame>& frames) {
  const auto rows = test::read_csv(path);
  ASSERT_EQ(rows.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const planarvo_track_result& r = frames[i].result;
    const std::vector<std::string>& f = rows[i];
    ASSERT_EQ(f.size(), 14u) << i;
    const double dt = i > 0 ? frames[i].data.timestamp - frames[i - 1].data.timestamp : 0.0;
    int iterations = 0;
    for (int l = 0; l < 8; ++l) iterations += r.iterations[l];
    EXPECT_NEAR(std::stod(f[0]), frames[i].data.timestamp, 1e-9) << i;
    EXPECT_EQ(std::stod(f[1]), dt > 0 ? r.motion.x / dt : 0.0) << i;
    EXPECT_EQ(std::stod(f[2]), dt > 0 ? r.motion.y / dt : 0.0) << i;
    EXPECT_EQ(std::stod(f[3]), dt > 0 ? r.motion.theta / dt : 0.0) << i;
    EXPECT_EQ(std::stoi(f[4]), iterations) << i;
    EXPECT_EQ(std::stod(f[5]), r.final_cost) << i;
    EXPECT_EQ(std::stod(f[6]), r.inlier_fraction) << i;
    const double ms = std::stod(f[7]);  // a time: only its range can be known
    EXPECT_TRUE(ms > 0 && ms < 60e3) << i << ": " << f[7];
    EXPECT_EQ(f[8], status_label(r.status)) << i;
    for (size_t c = 9; c < 14; ++c) EXPECT_EQ(f[c], "") << i << " " << c;  // no attitude without the local plane
  }
}

// The motion pairs: one per tracked interval, the tracker's motion as the sensor's, the data
// set's odometry between the two frames and the interval's direction label.
// The camera's own motion from a robot motion tracked with e (docs/conventions.md, "Sensor
// motions and the calibration model"): T^-1 M T with T = (x, y, yaw), by matrices, over z.
planarvo_se2 camera_motion(const planarvo_extrinsics& e, const planarvo_se2& m) {
  const auto hom = [](double x, double y, double t) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
    h.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(t).toRotationMatrix();
    h(0, 2) = x;
    h(1, 2) = y;
    return h;
  };
  const Eigen::Matrix3d T = hom(e.x, e.y, e.yaw);
  const Eigen::Matrix3d s = T.inverse() * hom(m.x, m.y, m.theta) * T;
  return {s(0, 2) / e.z, s(1, 2) / e.z, std::atan2(s(1, 0), s(0, 0))};
}

void expect_motion_pairs(const std::string& path, const std::vector<TrackedFrame>& frames,
                         const planarvo_extrinsics& e) {
  size_t n = 0;
  ASSERT_EQ(planarvo_motion_pairs_load(path.c_str(), nullptr, 0, &n), PLANARVO_OK) << planarvo_last_error();
  std::vector<planarvo_motion_pair> pairs(n);
  for (planarvo_motion_pair& p : pairs) planarvo_motion_pair_init(&p);
  ASSERT_EQ(planarvo_motion_pairs_load(path.c_str(), pairs.data(), n, &n), PLANARVO_OK) << planarvo_last_error();
  size_t k = 0;
  for (size_t i = 1; i < frames.size(); ++i) {
    const TrackedFrame &a = frames[i - 1], &b = frames[i];
    if (!tracked(b) || !a.data.has_odometry || !b.data.has_odometry || !b.data.has_direction) continue;
    ASSERT_LT(k, pairs.size());
    const planarvo_motion_pair& p = pairs[k++];
    EXPECT_EQ(p.interval, b.data.timestamp - a.data.timestamp) << i;
    // The camera's own motion, whatever extrinsics the robot's was tracked with.
    const planarvo_se2 s = camera_motion(e, b.result.motion);
    EXPECT_NEAR(p.sensor.x, s.x, 1e-12) << i;
    EXPECT_NEAR(p.sensor.y, s.y, 1e-12) << i;
    EXPECT_NEAR(p.sensor.theta, s.theta, 1e-12) << i;
    ASSERT_EQ(p.has_odometry, 1) << i;
    const planarvo_se2 odo = test::between(a.data.odometry, b.data.odometry);
    EXPECT_NEAR(p.odometry.x, odo.x, 1e-15) << i;
    EXPECT_NEAR(p.odometry.y, odo.y, 1e-15) << i;
    EXPECT_NEAR(p.odometry.theta, odo.theta, 1e-15) << i;
    ASSERT_EQ(p.has_direction, 1) << i;
    EXPECT_EQ(p.direction, b.data.direction) << i;
  }
  EXPECT_EQ(k, pairs.size());
}

// The printed summary: frame counts, and the accuracy against ground truth to the digits printed.
void expect_printed_summary(const std::string& output, const std::vector<TrackedFrame>& frames) {
  long ok = 0, degraded = 0, lost = 0, keyframes = 0;
  for (const TrackedFrame& f : frames) {
    const planarvo_track_status s = f.result.status;
    ok += s == PLANARVO_TRACK_OK || s == PLANARVO_TRACK_FIRST;
    degraded += s == PLANARVO_TRACK_DEGRADED;
    lost += s == PLANARVO_TRACK_LOST;
    keyframes += f.result.keyframe != 0;
  }
  const std::vector<double> counts = numbers_after(output, "frames ");
  ASSERT_EQ(counts.size(), 5u) << output;
  EXPECT_EQ(counts[0], static_cast<double>(frames.size()));
  EXPECT_EQ(counts[1], ok);
  EXPECT_EQ(counts[2], degraded);
  EXPECT_EQ(counts[3], lost);
  EXPECT_EQ(counts[4], keyframes);

  const planarvo_motion_accuracy a = test::accuracy_of(frames);
  const auto over = numbers_after(output, "accuracy against ground truth over");
  const auto slope = numbers_after(output, "velocity slope");
  const auto translation = numbers_after(output, "per-frame translation error");
  const auto rotation = numbers_after(output, "per-frame rotation error");
  const auto end = numbers_after(output, "end point");
  ASSERT_EQ(over.size(), 2u) << output;
  ASSERT_EQ(slope.size(), 2u) << output;
  ASSERT_EQ(translation.size(), 4u) << output;  // RMS, max, the threshold (1 mm), gross
  ASSERT_EQ(rotation.size(), 1u) << output;
  ASSERT_EQ(end.size(), 3u) << output;
  EXPECT_EQ(over[0], a.intervals);
  expect_printed(over[1], a.distance, 3, "distance");
  expect_printed(slope[0], a.slope_linear, 4, "linear slope");
  expect_printed(slope[1], a.slope_angular, 4, "angular slope");
  expect_printed(translation[0], a.rms_translation * 1e3, 4, "RMS translation");
  expect_printed(translation[1], a.max_translation * 1e3, 4, "max translation");
  EXPECT_EQ(translation[3], a.gross_errors);
  expect_printed(rotation[0], a.rms_rotation / kDeg, 4, "RMS rotation");
  expect_printed(end[0], a.endpoint_error * 1e3, 2, "end point");
  expect_printed(end[1], 100 * a.endpoint_drift, 3, "drift");
  expect_printed(end[2], a.endpoint_heading / kDeg, 3, "heading");

  // By status: a line per status that ends an interval, with its own figures.
  const std::pair<planarvo_track_status, const char*> groups[] = {
      {PLANARVO_TRACK_OK, "ok "}, {PLANARVO_TRACK_DEGRADED, "degraded "}, {PLANARVO_TRACK_LOST, "lost "}};
  for (const auto& [status, name] : groups) {
    const planarvo_motion_accuracy b = test::accuracy_of(frames, status);
    const auto printed = numbers_after(output, std::string(name) + "intervals");
    if (b.intervals == 0) {
      EXPECT_TRUE(printed.empty()) << name << output;
      continue;
    }
    ASSERT_EQ(printed.size(), 4u) << name << output;
    EXPECT_EQ(printed[0], b.intervals) << name;
    expect_printed(printed[1], b.rms_translation * 1e3, 4, "RMS translation by status");
    expect_printed(printed[2], b.max_translation * 1e3, 4, "max translation by status");
    expect_printed(printed[3], b.rms_rotation / kDeg, 4, "RMS rotation by status");
  }

  // And against the simulator's truth, independently of the tool: every interval within 1 mm,
  // the velocities unbiased.
  EXPECT_EQ(a.gross_errors, 0);
  EXPECT_NEAR(a.slope_linear, 1.0, 0.01);
  EXPECT_NEAR(a.slope_angular, 1.0, 0.01);
  EXPECT_LT(a.endpoint_drift, 0.01);
}

TEST(CliTrack, WritesAndPrintsWhatTheCApiTracks) {
  ScratchDir d;
  const std::string seq = (d / "seq").string();
  auto r = run_cli("simulate --quiet --out " + seq + " --seconds 1 --width 320 --height 240 --seed 5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string traj = (d / "traj.txt").string(), stats = (d / "stats.csv").string(),
                    motions = (d / "motions.csv").string(), extrinsics = seq + "/extrinsics_gt.yaml";
  r = run_cli("track --quiet " + seq + " --extrinsics " + extrinsics + " -o " + traj + " --stats " + stats +
              " --motions-out " + motions);
  ASSERT_EQ(r.exit_code, 0) << r.output;

  planarvo_extrinsics e{};
  ASSERT_EQ(planarvo_extrinsics_load(extrinsics.c_str(), &e), PLANARVO_OK) << planarvo_last_error();
  const std::vector<TrackedFrame> frames = test::track_through_api(seq, e);
  ASSERT_EQ(frames.size(), 30u);
  expect_trajectory(traj, frames);
  expect_stats(stats, frames);
  expect_motion_pairs(motions, frames, e);
  expect_printed_summary(r.output, frames);
}

TEST(CliTrack, MissingExtrinsicsIsUsageError) {
  ScratchDir d;
  const std::string seq = (d / "seq").string();
  ASSERT_EQ(run_cli("simulate --quiet --out " + seq + " --seconds 0.2 --width 96 --height 64").exit_code, 0);
  auto r = run_cli("track --quiet " + seq);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("extrinsics.yaml"), std::string::npos) << r.output;
}

// The local plane: `track --local-plane --plane-out` on a car whose body leans and pitches writes
// one attitude per frame, against the simulator's truth (its plane.txt, the same format, read with
// the same reader); --plane-out or --plane-prior without --local-plane, and a prior that is not a
// positive number of degrees, are usage errors that write nothing.
TEST(CliTrack, LocalPlaneWritesTheBodysAttitude) {
  ScratchDir d;
  const std::string seq = (d / "car").string();
  auto r = run_cli("simulate --quiet --out " + seq + " --seconds 2 --width 320 --height 240 --fov 60 --motion car "
                   "--max-speed 3 --min-turn-radius 6 --extrinsics=-1,0,0.9,0,40,180 --lean -0.07 --bumps 6 --seed 3");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string plane = (d / "plane.txt").string(), extrinsics = seq + "/extrinsics_gt.yaml";
  for (const std::string& bad : std::vector<std::string>{" --plane-out " + plane, " --plane-prior 1", " --local-plane --plane-prior 0",
                                " --local-plane --plane-prior -2"}) {
    r = run_cli("track --quiet " + seq + " --extrinsics " + extrinsics + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.output;
    EXPECT_FALSE(fs::exists(plane)) << bad;
  }
  r = run_cli("track --quiet " + seq + " --extrinsics " + extrinsics + " --local-plane --plane-out " + plane);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<io::PlaneAttitude> got = io::read_plane(plane), truth = io::read_plane(seq + "/plane.txt");
  ASSERT_EQ(got.size(), truth.size());
  double sq = 0;
  for (size_t k = 0; k < got.size(); ++k) {
    EXPECT_NEAR(got[k].t, truth[k].t, 1e-6);
    EXPECT_GT(got[k].sigma_roll, 0.0);
    sq += std::pow(got[k].roll - truth[k].roll, 2) + std::pow(got[k].pitch - truth[k].pitch, 2);
  }
  EXPECT_LT(std::sqrt(sq / (2.0 * static_cast<double>(got.size()))), 0.3 * M_PI / 180.0);
}

// A knocked camera through the tool: `simulate --knock` tilts it by 2 degrees of pitch; `track
// --local-plane` warns, marks the frame in the statistics, and `--mounting-out` writes the knocked
// mounting (the simulator's extrinsics_knocked.yaml, read with the same reader) within 0.2
// degrees, and the attitude after it is the truth's again; with `--mounting-change report` the
// frames are tracked with the mounting given (the attitude stays stepped). The watch's
// options without --local-plane, or with bad values, are usage errors that write nothing.
TEST(CliTrack, AKnockedMountingIsReportedAndRecalibrated) {
  ScratchDir d;
  const std::string seq = (d / "car").string();
  auto r = run_cli("simulate --quiet --out " + seq + " --seconds 4 --width 320 --height 240 --fov 60 --motion car "
                   "--max-speed 3 --min-turn-radius 6 --extrinsics=-1,0,0.9,0,40,180 --lean -0.07 --seed 5 "
                   "--knock 2:0,2,0");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string out = (d / "mounting.yaml").string(), stats = (d / "stats.csv").string();
  const std::string track = "track --quiet " + seq + " --extrinsics " + seq + "/extrinsics_gt.yaml";
  for (const std::string& bad : std::vector<std::string>{" --mounting-out " + out, " --mounting-change report",
                                " --local-plane --mounting-change sometimes", " --local-plane --mounting-step 0"}) {
    r = run_cli(track + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.output;
    EXPECT_FALSE(fs::exists(out)) << bad;
  }
  r = run_cli(track + " --local-plane --mounting-out " + out + " --stats " + stats);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Extrinsics got = io::read_extrinsics_yaml(out).value, knocked = io::read_extrinsics_yaml(seq + "/extrinsics_knocked.yaml").value;
  EXPECT_NEAR(got.pitch, knocked.pitch, 0.2 * M_PI / 180.0);
  EXPECT_NEAR(got.roll, knocked.roll, 0.2 * M_PI / 180.0);
  EXPECT_NEAR(got.z, knocked.z, 1e-9);
  // The statistics: the frame that found it, within a second of the knock.
  std::vector<double> found;
  for (const std::vector<std::string>& row : test::read_csv(stats)) {
    ASSERT_EQ(row.size(), 14u);
    if (row[13] == "1") found.push_back(std::stod(row[0]));
  }
  ASSERT_GE(found.size(), 1u);
  EXPECT_GT(found[0], 2.0);
  EXPECT_LT(found[0], 3.0);
  // Reported only: the mounting found is written, but the frames are tracked with the one given, so
  // the body's attitude stays stepped by the knock (about -2 degrees of pitch: a rear camera's pitch
  // turns the other way in the body's axes) where recalibrating brings it back to the truth.
  const std::string plane = (d / "plane.txt").string();
  const std::vector<io::PlaneAttitude> truth = io::read_plane(seq + "/plane.txt");
  r = run_cli(track + " --local-plane --plane-out " + plane);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NEAR(io::read_plane(plane).back().pitch, truth.back().pitch, 0.2 * M_PI / 180.0);
  r = run_cli(track + " --local-plane --mounting-change report --mounting-out " + out + " --plane-out " + plane);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NEAR(io::read_extrinsics_yaml(out).value.pitch, knocked.pitch, 0.2 * M_PI / 180.0);
  EXPECT_NEAR(io::read_plane(plane).back().pitch, truth.back().pitch - 2.0 * M_PI / 180.0, 0.2 * M_PI / 180.0);
}

}  // namespace
}  // namespace planarvo
