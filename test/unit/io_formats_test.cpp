// The file formats of src/io/formats.h and stats.h: round trips, files written the way other
// tools write them (OpenCV's calibration sample, TUM with comments), and every malformed input
// reported as InvalidInput naming the file and line.
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

#include <sys/stat.h>

#include <opencv2/core.hpp>

#include "common/test_util.h"
#include "core/output_file.h"
#include "io/formats.h"
#include "io/stats.h"
#include "io/text.h"
#include "unit/io_test_helpers.h"

namespace planarvo {
namespace {

using io::DirectionLabel;
using io::FrameEntry;
using io::StampedPose;
using test::expect_error;
using test::expect_invalid_input;
using test::ScratchDir;
using test::write_text;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

CameraModel test_camera() {
  CameraModel c;
  c.width = 640;
  c.height = 480;
  c.fx = 512.3456789012345;
  c.fy = 510.9876543210987;
  c.cx = 321.123456789;
  c.cy = 239.87654321;
  c.k1 = -0.2834567890123;
  c.k2 = 0.0912345678901;
  c.p1 = 1.234567e-4;
  c.p2 = -2.345678e-4;
  c.k3 = -0.0123456789;
  return c;
}

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

void expect_same_camera(const CameraModel& a, const CameraModel& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.fx, b.fx);
  EXPECT_EQ(a.fy, b.fy);
  EXPECT_EQ(a.cx, b.cx);
  EXPECT_EQ(a.cy, b.cy);
  EXPECT_EQ(a.k1, b.k1);
  EXPECT_EQ(a.k2, b.k2);
  EXPECT_EQ(a.p1, b.p1);
  EXPECT_EQ(a.p2, b.p2);
  EXPECT_EQ(a.k3, b.k3);
  EXPECT_EQ(a.rolling_shutter_readout, b.rolling_shutter_readout);
}

// ---------------------------------------------------------------------------------------------
// camera.yaml

TEST(IoCameraYaml, WriteThenReadIsExact) {
  ScratchDir dir;
  const std::string path = (dir / "camera.yaml").string();
  io::write_camera_yaml(path, test_camera());
  expect_same_camera(io::read_camera_yaml(path), test_camera());
}

// What samples/cpp/calibration.cpp (saveCameraParams) writes, with the distortion vector in the
// shapes OpenCV produces.
void write_like_opencv_sample(const std::string& path, const CameraModel& c, int rows, int cols) {
  cv::FileStorage fs(path, cv::FileStorage::WRITE);
  fs << "calibration_time" << "Thu 01 Jan 2024 12:00:00 CET";
  fs << "nframes" << 25;
  fs << "image_width" << c.width;
  fs << "image_height" << c.height;
  fs << "board_width" << 9;
  fs << "board_height" << 6;
  fs << "square_size" << 0.025;
  fs << "flags" << 0;
  const cv::Mat K = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  fs << "camera_matrix" << K;
  const double d[5] = {c.k1, c.k2, c.p1, c.p2, c.k3};
  cv::Mat D(rows, cols, CV_64F);
  for (int i = 0; i < rows * cols; ++i) D.at<double>(i) = d[i];
  fs << "distortion_coefficients" << D;
  fs << "avg_reprojection_error" << 0.21;
  fs << "per_view_reprojection_errors" << cv::Mat(25, 1, CV_32F, cv::Scalar(0.2));
}

TEST(IoCameraYaml, ReadsWhatOpenCVsCalibrationSampleWrites) {
  ScratchDir dir;
  const CameraModel c = test_camera();
  for (const auto& [rows, cols] : {std::pair{5, 1}, std::pair{1, 5}, std::pair{4, 1}, std::pair{1, 4}}) {
    SCOPED_TRACE(std::to_string(rows) + "x" + std::to_string(cols));
    const std::string path = (dir / ("cam_" + std::to_string(rows) + std::to_string(cols) + ".yaml")).string();
    write_like_opencv_sample(path, c, rows, cols);
    CameraModel expected = c;
    if (rows * cols == 4) expected.k3 = 0.0;
    expect_same_camera(io::read_camera_yaml(path), expected);
  }
}

TEST(IoCameraYaml, AcceptsEightCoefficientsOnlyWhenTheRationalTermsAreZero) {
  ScratchDir dir;
  const CameraModel c = test_camera();
  const cv::Mat K = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  cv::Mat D = (cv::Mat_<double>(8, 1) << c.k1, c.k2, c.p1, c.p2, c.k3, 0, 0, 0);
  const std::string ok = (dir / "ok.yaml").string(), bad = (dir / "bad.yaml").string();
  {
    cv::FileStorage fs(ok, cv::FileStorage::WRITE);
    fs << "image_width" << 640 << "image_height" << 480 << "camera_matrix" << K
       << "distortion_coefficients" << D;
  }
  expect_same_camera(io::read_camera_yaml(ok), c);
  D.at<double>(6) = 0.01;
  {
    cv::FileStorage fs(bad, cv::FileStorage::WRITE);
    fs << "image_width" << 640 << "image_height" << 480 << "camera_matrix" << K
       << "distortion_coefficients" << D;
  }
  expect_invalid_input([&] { io::read_camera_yaml(bad); }, bad);
}

const char* const kGoodCameraYaml =
    "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
    "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
    "   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n"
    "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n"
    "   data: [ -0.1, 0.01, 0., 0., 0. ]\n";

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

TEST(IoCameraYaml, HandWrittenFileReads) {
  ScratchDir dir;
  write_text(dir / "camera.yaml", kGoodCameraYaml);
  const CameraModel c = io::read_camera_yaml((dir / "camera.yaml").string());
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.fx, 500.0);
  EXPECT_EQ(c.cy, 240.0);
  EXPECT_EQ(c.k1, -0.1);
  EXPECT_EQ(c.k2, 0.01);
}

TEST(IoCameraYaml, BadFilesNameTheFile) {
  ScratchDir dir;
  const auto bad = [&](const std::string& name, const std::string& content, const char* says) {
    SCOPED_TRACE(name);
    const std::string path = (dir / name).string();
    write_text(path, content);
    const std::string msg = expect_invalid_input([&] { io::read_camera_yaml(path); }, path);
    EXPECT_THAT(msg, HasSubstr(says));
  };
  bad("malformed.yaml", "%YAML:1.0\n---\nimage_width: [640\n  : : {\n", "is not closed");
  bad("unterminated.yaml", "%YAML:1.0\n---\nimage_width: \"640\n", "valid OpenCV");  // OpenCV's error
  bad("no_width.yaml", replace(kGoodCameraYaml, "image_width: 640\n", ""), "image_width");
  bad("no_height.yaml", replace(kGoodCameraYaml, "image_height: 480\n", ""), "image_height");
  bad("no_k.yaml", replace(kGoodCameraYaml, "camera_matrix:", "other_matrix:"), "camera_matrix");
  bad("no_d.yaml", replace(kGoodCameraYaml, "distortion_coefficients:", "dist:"),
      "distortion_coefficients");
  bad("d3.yaml", replace(kGoodCameraYaml, "cols: 5\n   dt: d\n   data: [ -0.1, 0.01, 0., 0., 0. ]",
                         "cols: 3\n   dt: d\n   data: [ -0.1, 0.01, 0. ]"),
      "distortion_coefficients");
  bad("k2x3.yaml", replace(kGoodCameraYaml, "rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]",
                           "rows: 2\n   cols: 3\n   dt: d\n   data: [ 500., 0., 320., 0., 500., 240. ]"),
      "camera_matrix");
  bad("nan.yaml", replace(kGoodCameraYaml, "500., 0., 320.", ".Nan, 0., 320."), "NaN");
  bad("inf.yaml", replace(kGoodCameraYaml, "-0.1, 0.01", "-.Inf, 0.01"), "NaN or inf");
  bad("text_width.yaml", replace(kGoodCameraYaml, "image_width: 640", "image_width: wide"),
      "image_width");
  bad("zero_width.yaml", replace(kGoodCameraYaml, "image_width: 640", "image_width: 0"),
      "image_width");
  bad("skew.yaml", replace(kGoodCameraYaml, "500., 0., 320.", "500., 2., 320."), "skew");
  bad("negative_f.yaml", replace(kGoodCameraYaml, "500., 0., 320.", "-500., 0., 320."), "focal");
  const std::string missing = (dir / "missing.yaml").string();
  expect_invalid_input([&] { io::read_camera_yaml(missing); }, missing);
}

// The region of interest: written when there is one, read back exactly, as a hand would write
// it, and refused (naming the key or the region) when it is not four integers inside the image.
TEST(IoCameraYaml, RegionOfInterestRoundTripsAndIsChecked) {
  ScratchDir dir;
  CameraModel c = test_camera();
  c.roi = PixelRegion{8, 100, c.width - 8, 300};
  const std::string path = (dir / "camera.yaml").string();
  io::write_camera_yaml(path, c);
  const CameraModel back = io::read_camera_yaml(path);
  expect_same_camera(back, c);
  EXPECT_EQ(back.roi, c.roi);
  const std::string hand = (dir / "hand.yaml").string();
  write_text(hand, kGoodCameraYaml + std::string("region_of_interest: [ 0, 120, 640, 360 ]\n"));
  EXPECT_EQ(io::read_camera_yaml(hand).roi, (PixelRegion{0, 120, 640, 360}));
  EXPECT_TRUE(io::read_camera_yaml((dir / "camera.yaml").string()).roi == c.roi);
  const auto bad = [&](const std::string& name, const std::string& roi, const char* says) {
    SCOPED_TRACE(name);
    const std::string p = (dir / name).string();
    write_text(p, kGoodCameraYaml + std::string("region_of_interest: ") + roi + "\n");
    const std::string msg = expect_invalid_input([&] { io::read_camera_yaml(p); }, p);
    EXPECT_THAT(msg, HasSubstr(says));
  };
  bad("three.yaml", "[ 0, 120, 640 ]", "region_of_interest");
  bad("fraction.yaml", "[ 0, 120.5, 640, 300 ]", "region_of_interest");
  bad("outside.yaml", "[ 0, 200, 640, 300 ]", "not inside");
  bad("negative.yaml", "[ -1, 0, 100, 100 ]", "not inside");
  bad("tiny.yaml", "[ 0, 0, 8, 100 ]", "at least 16");
  bad("empty.yaml", "[ 0, 0, 0, 0 ]", "no pixels");
  bad("scalar.yaml", "7", "region_of_interest");
}

// The rolling shutter's readout: planarvo's own optional key beside OpenCV's. Absent is 0 (a
// global shutter) and then not written; otherwise read back exactly; a negative or non-numeric
// value is refused naming the file and the key.
TEST(IoCameraYaml, RollingShutterReadoutRoundTripsAndIsChecked) {
  ScratchDir dir;
  const std::string global = (dir / "global.yaml").string();
  io::write_camera_yaml(global, test_camera());
  EXPECT_EQ(test::read_text(global).find("rolling_shutter_readout"), std::string::npos);
  EXPECT_EQ(io::read_camera_yaml(global).rolling_shutter_readout, 0.0);
  CameraModel c = test_camera();
  c.rolling_shutter_readout = 0.0271234567890123;
  const std::string path = (dir / "camera.yaml").string();
  io::write_camera_yaml(path, c);
  EXPECT_NE(test::read_text(path).find("rolling_shutter_readout"), std::string::npos);
  expect_same_camera(io::read_camera_yaml(path), c);
  const std::string hand = (dir / "hand.yaml").string();
  write_text(hand, kGoodCameraYaml + std::string("rolling_shutter_readout: 0.025\n"));
  EXPECT_EQ(io::read_camera_yaml(hand).rolling_shutter_readout, 0.025);
  write_text(hand, kGoodCameraYaml + std::string("rolling_shutter_readout: 0\n"));
  EXPECT_EQ(io::read_camera_yaml(hand).rolling_shutter_readout, 0.0);
  const auto bad = [&](const std::string& name, const std::string& value) {
    SCOPED_TRACE(name);
    const std::string p = (dir / name).string();
    write_text(p, kGoodCameraYaml + std::string("rolling_shutter_readout: ") + value + "\n");
    const std::string msg = expect_invalid_input([&] { io::read_camera_yaml(p); }, p);
    EXPECT_THAT(msg, HasSubstr("rolling_shutter_readout"));
  };
  bad("negative.yaml", "-0.01");
  bad("text.yaml", "fast");
  bad("inf.yaml", ".Inf");
  // The writer refuses what the reader would (InvalidArgument: a caller's value, not a file).
  c.rolling_shutter_readout = -1e-3;
  expect_error([&] { io::write_camera_yaml(path, c); }, ErrorCode::InvalidArgument, "rolling_shutter_readout");
}

// ---------------------------------------------------------------------------------------------
// extrinsics.yaml

TEST(IoExtrinsicsYaml, WriteThenReadKeepsEverything) {
  ScratchDir dir;
  ExtrinsicsEstimate e;
  e.value = Extrinsics{0.2441, -0.0185, 0.1787, 0.21642082, 0.30717795, -0.16057029};
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) e.covariance(r, c) = (r == c ? 1e-4 : 1e-6) * (1 + r + 2 * c) / 7.0;
  e.estimated = {true, true, false, false, false, true};  // x, y, yaw
  e.method = "odometry+nonholonomic";
  e.notes = "[3 runs] {tiles}: converged # after 12 iterations, \"quoted\"";
  const std::string path = (dir / "extrinsics.yaml").string();
  io::write_extrinsics_yaml(path, e);
  const ExtrinsicsEstimate r = io::read_extrinsics_yaml(path);
  EXPECT_EQ(r.value.x, e.value.x);
  EXPECT_EQ(r.value.y, e.value.y);
  EXPECT_EQ(r.value.z, e.value.z);
  EXPECT_EQ(r.value.roll, e.value.roll);
  EXPECT_EQ(r.value.pitch, e.value.pitch);
  EXPECT_EQ(r.value.yaw, e.value.yaw);
  EXPECT_TRUE(r.covariance == e.covariance) << r.covariance;
  EXPECT_EQ(r.estimated, e.estimated);
  EXPECT_EQ(r.method, e.method);
  EXPECT_EQ(r.notes, e.notes);

  // Readable with plain cv::FileStorage, with the matrix of the six values.
  cv::FileStorage fs(path, cv::FileStorage::READ);
  cv::Mat T;
  fs["T_robot_camera"] >> T;
  ASSERT_EQ(T.rows, 4);
  const Eigen::Matrix4d expected = e.value.T_vc();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(T.at<double>(i, j), expected(i, j), 1e-15);
  EXPECT_TRUE(fs["estimated"].isSeq());
  EXPECT_EQ(fs["estimated"].size(), 3u);
}

TEST(IoExtrinsicsYaml, EmptyEstimatedAndStringsRoundTrip) {
  ScratchDir dir;
  ExtrinsicsEstimate e;
  e.value = Extrinsics{0, 0, 1, 0, 0, 0};
  const std::string path = (dir / "e.yaml").string();
  io::write_extrinsics_yaml(path, e);
  const ExtrinsicsEstimate r = io::read_extrinsics_yaml(path);
  EXPECT_EQ(r.estimated, (std::array<bool, 6>{}));
  EXPECT_EQ(r.method, "");
  EXPECT_EQ(r.notes, "");
  EXPECT_TRUE(r.covariance.isZero(0.0));
}

TEST(IoExtrinsicsYaml, OnlyTheSixValuesAreRequired) {
  ScratchDir dir;
  write_text(dir / "e.yaml", "%YAML:1.0\n---\nx: 0.1\ny: -0.2\nz: 0.3\nroll: 0\npitch: 0.05\nyaw: -1\n");
  const ExtrinsicsEstimate r = io::read_extrinsics_yaml((dir / "e.yaml").string());
  EXPECT_EQ(r.value.x, 0.1);
  EXPECT_EQ(r.value.y, -0.2);
  EXPECT_EQ(r.value.z, 0.3);
  EXPECT_EQ(r.value.roll, 0.0);
  EXPECT_EQ(r.value.pitch, 0.05);
  EXPECT_EQ(r.value.yaw, -1.0);
  EXPECT_EQ(r.estimated, (std::array<bool, 6>{}));
}

TEST(IoExtrinsicsYaml, BadFilesNameTheFile) {
  ScratchDir dir;
  const std::string six = "%YAML:1.0\n---\nx: 0.1\ny: -0.2\nz: 0.3\nroll: 0.1\npitch: 0.05\nyaw: -1\n";
  const auto bad = [&](const std::string& name, const std::string& content, const char* says) {
    SCOPED_TRACE(name);
    const std::string path = (dir / name).string();
    write_text(path, content);
    const std::string msg = expect_invalid_input([&] { io::read_extrinsics_yaml(path); }, path);
    EXPECT_THAT(msg, HasSubstr(says));
  };
  bad("no_yaw.yaml", replace(six, "yaw: -1\n", ""), "yaw");
  bad("nan.yaml", replace(six, "z: 0.3", "z: .Nan"), "finite");
  bad("text.yaml", replace(six, "pitch: 0.05", "pitch: steep"), "pitch");
  bad("malformed.yaml", "x: [1, 2\ny: {\n", "is not closed");
  bad("unterminated.yaml", "%YAML:1.0\n---\nx: \"0.1\n", "valid OpenCV");  // OpenCV's own error
  bad("estimated_unknown.yaml", six + "estimated: [x, height]\n", "height");
  bad("estimated_twice.yaml", six + "estimated: [x, x]\n", "twice");
  bad("estimated_scalar.yaml", six + "estimated: 3\n", "estimated");
  bad("cov5.yaml", six + "covariance: !!opencv-matrix\n   rows: 1\n   cols: 1\n   dt: d\n   data: [ 1. ]\n",
      "covariance");

  // A T_robot_camera that disagrees with the six values (here: that of another yaw).
  Extrinsics other{0.1, -0.2, 0.3, 0.1, 0.05, -1.0 + 1e-3};
  const Eigen::Matrix4d T = other.T_vc();
  std::string t = six + "T_robot_camera: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: d\n   data: [";
  for (int i = 0; i < 16; ++i) t += (i ? ", " : " ") + std::to_string(T(i / 4, i % 4));
  bad("t_disagrees.yaml", t + " ]\n", "disagrees");

  // ...while one that agrees (to the printed precision of std::to_string, 1e-6) is accepted.
  const Eigen::Matrix4d T_same = Extrinsics{0.1, -0.2, 0.3, 0.1, 0.05, -1.0}.T_vc();
  char buf[64];
  std::string same = six + "T_robot_camera: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: d\n   data: [";
  for (int i = 0; i < 16; ++i) {
    std::snprintf(buf, sizeof buf, "%.10f", T_same(i / 4, i % 4));
    same += (i ? ", " : " ") + std::string(buf);
  }
  write_text(dir / "t_agrees.yaml", same + " ]\n");
  EXPECT_NO_THROW(io::read_extrinsics_yaml((dir / "t_agrees.yaml").string()));
}

// ---------------------------------------------------------------------------------------------
// TUM

TEST(IoTum, WriteThenReadIsExact) {
  ScratchDir dir;
  std::vector<StampedPose> poses;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-50, 50);
  double t = 1700000000.123456;
  // Angles across the whole circle, including both sides of +-pi.
  const double angles[] = {0.0, 1e-12, -M_PI / 2, M_PI - 1e-9, -M_PI + 1e-9, M_PI, 2.5, -3.1};
  for (double a : angles) {
    poses.push_back({t, SE2(u(rng), u(rng), a)});
    t += 0.033333333;
  }
  const std::string path = (dir / "traj.txt").string();
  io::write_tum(path, poses);
  const auto back = io::read_tum(path);
  ASSERT_EQ(back.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(back[i].t, poses[i].t, 1e-9 * std::abs(poses[i].t) + 1e-9);
    EXPECT_EQ(back[i].pose.x, poses[i].pose.x);
    EXPECT_EQ(back[i].pose.y, poses[i].pose.y);
    EXPECT_NEAR(wrap_angle(back[i].pose.theta - poses[i].pose.theta), 0.0, 1e-9);
  }
}

TEST(IoTum, ReadsCommentsBlankLinesAndAnyQuaternionScaleOrSign) {
  ScratchDir dir;
  const double s = std::sin(M_PI / 8), c = std::cos(M_PI / 8);  // yaw pi/4
  write_text(dir / "t.txt",
             "# timestamp tx ty tz qx qy qz qw\n\n"
             "0.5 1 2 0 0 0 0 1\r\n"
             "   # an indented comment\n"
             "0.75 -1.5 2.5 0.0 0 0 " + num(2 * s) + " " + num(2 * c) + "\n"
             "1.0\t3\t4\t0\t0\t0\t" + num(-s) + "\t" + num(-c) + "\n"
             "1.25 0 0 0 0 0 1 0\n");
  const auto p = io::read_tum((dir / "t.txt").string());
  ASSERT_EQ(p.size(), 4u);
  EXPECT_EQ(p[0].t, 0.5);
  EXPECT_EQ(p[0].pose.x, 1.0);
  EXPECT_EQ(p[0].pose.theta, 0.0);
  EXPECT_EQ(p[1].pose.x, -1.5);
  EXPECT_NEAR(p[1].pose.theta, M_PI / 4, 1e-14);  // an unnormalised quaternion
  EXPECT_NEAR(p[2].pose.theta, M_PI / 4, 1e-14);  // -q is the same rotation
  EXPECT_NEAR(std::abs(p[3].pose.theta), M_PI, 1e-12);
}

TEST(IoTum, MalformedLinesNameFileAndLine) {
  ScratchDir dir;
  const std::string good = "# header\n0.0 0 0 0 0 0 0 1\n";  // content on line 2
  const auto bad = [&](const std::string& name, const std::string& line3, const char* says) {
    SCOPED_TRACE(name);
    const std::string path = (dir / name).string();
    write_text(path, good + line3 + "\n5.0 0 0 0 0 0 0 1\n");
    const std::string msg = expect_invalid_input([&] { io::read_tum(path); }, path, 3);
    EXPECT_THAT(msg, HasSubstr(says));
  };
  bad("fields.txt", "1.0 0 0 0 0 0 1", "8 fields");
  bad("fields9.txt", "1.0 0 0 0 0 0 0 1 7", "8 fields");
  bad("number.txt", "1.0 0 0x 0 0 0 0 1", "not a number");
  bad("comma.txt", "1.0 0,5 0 0 0 0 0 1", "not a number");
  bad("nan.txt", "1.0 nan 0 0 0 0 0 1", "not finite");
  bad("inf.txt", "1.0 0 -inf 0 0 0 0 1", "not finite");
  bad("nan_t.txt", "NaN 0 0 0 0 0 0 1", "not finite");
  bad("same_time.txt", "0.0 1 0 0 0 0 0 1", "not after");
  bad("earlier.txt", "-1.0 1 0 0 0 0 0 1", "not after");
  bad("z.txt", "1.0 0 0 0.01 0 0 0 1", "planar");
  bad("tilt.txt", "1.0 0 0 0 0.01 0 0 1", "about z");
  bad("tilt_y.txt", "1.0 0 0 0 0 -0.001 0.7 0.7", "about z");
  bad("zero_q.txt", "1.0 0 0 0 0 0 0 0", "zero length");
  // Beyond 1e6 m: a corrupt value or another unit (issue 27: 1e308 in odometry.txt ended in a
  // factor's "information matrix must be finite" after the whole run, with no file or line).
  bad("far_x.txt", "1.0 1e308 0 0 0 0 0 1", "beyond");
  bad("far_y.txt", "1.0 0 -1000000.5 0 0 0 0 1", "beyond");
  const std::string missing = (dir / "missing.txt").string();
  expect_invalid_input([&] { io::read_tum(missing); }, missing);
  // Just inside the bound reads.
  write_text(dir / "near.txt", good + "1.0 999999.5 -1e6 0 0 0 0 1\n");
  const auto near = io::read_tum((dir / "near.txt").string());
  ASSERT_EQ(near.size(), 2u);
  EXPECT_EQ(near[1].pose.x, 999999.5);
  EXPECT_EQ(near[1].pose.y, -1e6);
}

// An input path that is a directory or a named pipe is named as such, and a pipe is never opened
// (a reader would block until something writes to it). Issue 27: a directory read as "does not
// exist" or "cannot be decoded".
TEST(IoFiles, DirectoriesAndPipesAreNamedAsSuchAndNeverOpened) {
  ScratchDir dir;
  const std::string folder = (dir / "folder").string(), pipe = (dir / "pipe").string();
  fs::create_directory(folder);
  ASSERT_EQ(mkfifo(pipe.c_str(), 0600), 0);
  EXPECT_EQ(io::detail::input_file_problem(folder), "is a directory, not a file");
  EXPECT_EQ(io::detail::input_file_problem(pipe), "is a named pipe (FIFO), not a regular file");
  EXPECT_EQ(io::detail::input_file_problem((dir / "none").string()), "does not exist");
  EXPECT_EQ(io::detail::input_file_problem((dir / "none" / "x").string()), "does not exist");
  write_text(dir / "file.txt", "x\n");
  EXPECT_EQ(io::detail::input_file_problem((dir / "file.txt").string()), "");
  for (const std::string& path : {folder, pipe}) {
    SCOPED_TRACE(path);
    EXPECT_THAT(expect_invalid_input([&] { io::read_tum(path); }, path), HasSubstr(path == folder ? "directory" : "pipe"));
    EXPECT_THAT(expect_invalid_input([&] { io::read_camera_yaml(path); }, path), HasSubstr(path == folder ? "directory" : "pipe"));
    EXPECT_THAT(expect_invalid_input([&] { io::read_frames(path); }, path), HasSubstr(path == folder ? "directory" : "pipe"));
  }
}

TEST(IoTum, ToleratesRoundingOfZAndTilt) {
  ScratchDir dir;
  write_text(dir / "t.txt", "0 1 2 1e-9 1e-9 -1e-9 0 1\n");
  const auto p = io::read_tum((dir / "t.txt").string());
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NEAR(p[0].pose.theta, 0.0, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// direction.txt and frames.txt

TEST(IoDirection, WriteThenReadAndHandWritten) {
  ScratchDir dir;
  const std::vector<DirectionLabel> labels = {{0.1, 1}, {0.2, -1}, {0.35, 0}, {1.0, 1}};
  const std::string path = (dir / "direction.txt").string();
  io::write_direction(path, labels);
  const auto back = io::read_direction(path);
  ASSERT_EQ(back.size(), labels.size());
  for (size_t i = 0; i < labels.size(); ++i) {
    EXPECT_NEAR(back[i].t, labels[i].t, 1e-12);
    EXPECT_EQ(back[i].sign, labels[i].sign);
  }
  write_text(dir / "hand.txt", "# t s\n1 +1\n2 -1\n3 0\n4 1.0\n5 -0\n");
  const auto h = io::read_direction((dir / "hand.txt").string());
  ASSERT_EQ(h.size(), 5u);
  EXPECT_EQ(h[0].sign, 1);
  EXPECT_EQ(h[1].sign, -1);
  EXPECT_EQ(h[2].sign, 0);
  EXPECT_EQ(h[3].sign, 1);
  EXPECT_EQ(h[4].sign, 0);
}

TEST(IoDirection, MalformedLinesNameFileAndLine) {
  ScratchDir dir;
  const auto bad = [&](const std::string& name, const std::string& line2, const char* says) {
    SCOPED_TRACE(name);
    const std::string path = (dir / name).string();
    write_text(path, "0.0 1\n" + line2 + "\n9 0\n");
    const std::string msg = expect_invalid_input([&] { io::read_direction(path); }, path, 2);
    EXPECT_THAT(msg, HasSubstr(says));
  };
  bad("two.txt", "1.0 2", "not one of");
  bad("half.txt", "1.0 0.5", "not one of");
  bad("word.txt", "1.0 forward", "not a number");
  bad("fields.txt", "1.0", "2 fields");
  bad("fields3.txt", "1.0 1 1", "2 fields");
  bad("time.txt", "0.0 1", "not after");
  bad("inf.txt", "inf 1", "not finite");
}

// plane.txt (the body's attitude relative to the local ground plane)
TEST(IoPlane, WriteThenReadExactlyAndHandWritten) {
  ScratchDir dir;
  const std::vector<io::PlaneAttitude> a = {{0.0, 0.0123456789012345, -0.17453292519943295, 1e-4, 2.5e-4},
                                            {0.033333333, -1.5e-9, 0.0, 0.0, 0.0},
                                            {1700000000.5, 1.5, -1.5, 0.25, 3.0}};
  const std::string path = (dir / "plane.txt").string();
  io::write_plane(path, a);
  const auto back = io::read_plane(path);
  ASSERT_EQ(back.size(), a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(back[i].t, a[i].t, 1e-9);
    EXPECT_EQ(back[i].roll, a[i].roll);  // angles and sigma round-trip exactly
    EXPECT_EQ(back[i].pitch, a[i].pitch);
    EXPECT_EQ(back[i].sigma_roll, a[i].sigma_roll);
    EXPECT_EQ(back[i].sigma_pitch, a[i].sigma_pitch);
  }
  write_text(dir / "hand.txt", "# t roll pitch sr sp\n1\t0.01 -0.02 0 0\n  2 1e-3 2e-3 1e-4 1e-4  \n");
  const auto h = io::read_plane((dir / "hand.txt").string());
  ASSERT_EQ(h.size(), 2u);
  EXPECT_EQ(h[1].t, 2.0);
  EXPECT_EQ(h[1].pitch, 2e-3);
}

TEST(IoPlane, MalformedLinesNameFileAndLine) {
  ScratchDir dir;
  const auto bad = [&](const std::string& name, const std::string& line2, const char* says) {
    SCOPED_TRACE(name);
    const std::string path = (dir / name).string();
    write_text(path, "0.0 0 0 0 0\n" + line2 + "\n9 0 0 0 0\n");
    const std::string msg = expect_invalid_input([&] { io::read_plane(path); }, path, 2);
    EXPECT_THAT(msg, HasSubstr(says));
  };
  bad("degrees.txt", "1.0 2.5 0 0 0", "radians");
  bad("degrees_pitch.txt", "1.0 0 -10 0 0", "radians");
  bad("sigma.txt", "1.0 0 0 -0.1 0", "negative");
  bad("fields.txt", "1.0 0 0 0", "5 fields");
  bad("time.txt", "0.0 0 0 0 0", "not after");
  bad("nan.txt", "1.0 nan 0 0 0", "not finite");
  const std::string p = (dir / "w.txt").string();
  expect_error([&] { io::write_plane(p, {{0.0, NAN, 0.0, 0.0, 0.0}}); }, ErrorCode::InvalidArgument, p);
  expect_error([&] { io::write_plane(p, {{0.0, 0.0, 0.0, -1.0, 0.0}}); }, ErrorCode::InvalidArgument, p);
  expect_error([&] { io::write_plane(p, {{1.0, 0, 0, 0, 0}, {1.0, 0, 0, 0, 0}}); }, ErrorCode::InvalidArgument, p);
}

TEST(IoFrames, WriteThenReadWithSpacesInPaths) {
  ScratchDir dir;
  const std::vector<FrameEntry> frames = {{0.0, "images/0000.png"},
                                          {0.033333333, "images/with space/0001 a.png"},
                                          {1700000000.5, "images/0002.png"}};
  const std::string path = (dir / "frames.txt").string();
  io::write_frames(path, frames);
  const auto back = io::read_frames(path);
  ASSERT_EQ(back.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(back[i].t, frames[i].t, 1e-9);
    EXPECT_EQ(back[i].path, frames[i].path);
  }
  EXPECT_EQ(back[0].line, 2);  // after the header comment

  write_text(dir / "hand.txt", "# t path\n 1.5 \t  images/a b.png  \r\n\n2 x.png\n");
  const auto h = io::read_frames((dir / "hand.txt").string());
  ASSERT_EQ(h.size(), 2u);
  EXPECT_EQ(h[0].path, "images/a b.png");
  EXPECT_EQ(h[0].line, 2);
  EXPECT_EQ(h[1].path, "x.png");
  EXPECT_EQ(h[1].line, 4);
}

TEST(IoFrames, MalformedLinesNameFileAndLine) {
  ScratchDir dir;
  const auto bad = [&](const std::string& name, const std::string& line2, const char* says) {
    SCOPED_TRACE(name);
    const std::string path = (dir / name).string();
    write_text(path, "0.0 a.png\n" + line2 + "\n9 z.png\n");
    const std::string msg = expect_invalid_input([&] { io::read_frames(path); }, path, 2);
    EXPECT_THAT(msg, HasSubstr(says));
  };
  bad("one.txt", "1.0", "one field");
  bad("number.txt", "1.0s b.png", "not a number");
  bad("nan.txt", "nan b.png", "not finite");
  bad("time.txt", "0.0 b.png", "not after");
}

TEST(IoWriters, FailedWritesAreIoErrorsNamingTheFile) {
  ScratchDir dir;
  const std::string p = (dir / "no_such_dir" / "out.txt").string();
  expect_error([&] { io::write_tum(p, {{0.0, SE2()}}); }, ErrorCode::Io, p);
  expect_error([&] { io::write_direction(p, {{0.0, 1}}); }, ErrorCode::Io, p);
  expect_error([&] { io::write_frames(p, {{0.0, "a.png"}}); }, ErrorCode::Io, p);
  expect_error([&] { io::write_camera_yaml(p, test_camera()); }, ErrorCode::Io, p);
  expect_error([&] { io::write_extrinsics_yaml(p, ExtrinsicsEstimate{}); }, ErrorCode::Io, p);
  expect_error([&] { io::StatsWriter w(p); }, ErrorCode::Io, p);
}

TEST(IoWriters, RefuseWhatTheReadersWouldReject) {
  ScratchDir dir;
  const std::string p = (dir / "out.txt").string();
  expect_error([&] { io::write_tum(p, {{1.0, SE2()}, {1.0, SE2()}}); }, ErrorCode::InvalidArgument, p);
  expect_error([&] { io::write_tum(p, {{0.0, SE2(std::nan(""), 0, 0)}}); }, ErrorCode::InvalidArgument, p);
  expect_error([&] { io::write_direction(p, {{0.0, 2}}); }, ErrorCode::InvalidArgument, p);
  expect_error([&] { io::write_frames(p, {{0.0, " lead.png"}}); }, ErrorCode::InvalidArgument, p);
  CameraModel bad = test_camera();
  bad.fx = 0;
  expect_error([&] { io::write_camera_yaml(p, bad); }, ErrorCode::InvalidArgument, p);
}

// ---------------------------------------------------------------------------------------------
// statistics CSV

TEST(IoStats, HeaderRowsAndFlushedAsItGoes) {
  ScratchDir dir;
  const std::string path = (dir / "stats.csv").string();
  io::StatsWriter w(path);
  const std::string partial = w.temporary_path();  // where the rows go until close()
  EXPECT_EQ(partial.rfind(path + OutputFile::kSuffix + "-", 0), 0u) << partial;
  EXPECT_EQ(test::read_text(partial),
            "timestamp,vx,vy,omega,iterations,final_cost,inlier_fraction,ms,status,roll,pitch,sigma_roll,"
            "sigma_pitch,mounting_changed\n");
  EXPECT_FALSE(std::filesystem::exists(path));
  io::FrameStats r;
  r.timestamp = 12.5;
  r.vx = 0.25;
  r.vy = -1e-3;
  r.omega = 0.1;
  r.iterations = 17;
  r.final_cost = 3.5;
  r.inlier_fraction = 0.875;
  r.ms = 1.25;
  r.status = "ok";
  w.add(r);
  r.timestamp = 12.6;
  r.status = "lost, \"really\"";
  r.final_cost = std::numeric_limits<double>::quiet_NaN();
  w.add(r);
  // Read while the writer is still open: the rows must already be in the partial file.
  const std::string text = test::read_text(partial);
  EXPECT_THAT(text, HasSubstr("\n12.500000000,0.25,-0.001,0.1,17,3.5,0.875,1.25,ok,,,,,\n"));
  EXPECT_THAT(text, HasSubstr("\n12.600000000,0.25,-0.001,0.1,17,nan,0.875,1.25,\"lost, \"\"really\"\"\",,,,,\n"));
  // With the local plane: the attitude, its sigma, and the mounting's change flag.
  r.status = "ok";
  r.has_attitude = true;
  r.roll = 0.015625;
  r.pitch = -0.25;
  r.sigma_roll = 0.001;
  r.sigma_pitch = 0.002;
  r.mounting_changed = true;
  w.add(r);
  const std::string all = test::read_text(partial);
  EXPECT_THAT(all, HasSubstr(",1.25,ok,0.015625,-0.25,0.001,0.002,1\n"));
  w.close();
  EXPECT_EQ(test::read_text(path), all);
  EXPECT_FALSE(std::filesystem::exists(partial));
}

// A writer destroyed before close() (a command that stopped on an error) leaves an existing
// file byte for byte as it was and no partial file; one that completes replaces it.
TEST(IoWriters, AFileIsCompleteOrUntouched) {
  ScratchDir dir;
  const std::string path = (dir / "stats.csv").string();
  test::write_text(path, "the user's earlier file\n");
  std::string partial;
  {
    io::StatsWriter w(path);
    w.add(io::FrameStats{});
    partial = w.temporary_path();
    EXPECT_TRUE(std::filesystem::exists(partial));
  }
  EXPECT_EQ(test::read_text(path), "the user's earlier file\n");
  EXPECT_FALSE(std::filesystem::exists(partial));
  {
    io::StatsWriter w(path);
    w.close();
  }
  EXPECT_EQ(test::read_text(path), std::string(io::StatsWriter::kHeader) + "\n");
  // The whole-file writers too: a complete write replaces, and nothing partial is left.
  io::write_tum(path, {{0.5, SE2(1, 2, 0.25)}});
  EXPECT_EQ(io::read_tum(path).size(), 1u);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1)
      << "only " << path << " is left";
}

// Two writers of one destination (two processes given the same --stats FILE): each writes a
// temporary of its own, and the file is the last one committed, whole; the first's rows are not
// spliced into it (issue 27: both wrote FILE.partial, and the second kept writing into the file
// the first had renamed).
TEST(IoWriters, TwoWritersOfOneFileLeaveOneWholeFile) {
  ScratchDir dir;
  const std::string path = (dir / "stats.csv").string();
  io::StatsWriter a(path), b(path);
  EXPECT_NE(a.temporary_path(), b.temporary_path());
  io::FrameStats r;
  r.status = "a";
  a.add(r);
  r.status = "b";
  b.add(r);
  a.close();
  b.add(r);
  b.close();
  const std::string header = std::string(io::StatsWriter::kHeader) + "\n";
  const std::string row_b = "0.000000000,0,0,0,0,0,0,0,b,,,,,\n";
  EXPECT_EQ(test::read_text(path), header + row_b + row_b);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1);
}

// A symbolic link planted where the temporary used to be (PATH.partial) in a shared directory:
// its target is not written, and the output is a regular file (issue 27: a root run overwrote
// the link's target, and PATH became a link to it).
TEST(IoWriters, ALinkAtTheTemporaryNameIsNotFollowed) {
  ScratchDir dir;
  const std::string path = (dir / "traj.txt").string();
  const std::string target = (dir / "precious").string();
  test::write_text(target, "keep me\n");
  std::filesystem::create_symlink(target, path + OutputFile::kSuffix);
  io::write_tum(path, {{0.5, SE2(1, 2, 0.25)}});
  EXPECT_EQ(test::read_text(target), "keep me\n");
  EXPECT_FALSE(std::filesystem::is_symlink(path));
  EXPECT_EQ(io::read_tum(path).size(), 1u);
}

// A destination that is not a regular file (a device) is written directly: nothing to rename.
TEST(IoWriters, ADeviceIsWrittenDirectly) {
  io::write_tum("/dev/null", {{0.5, SE2(1, 2, 0.25)}});
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));
}

}  // namespace
}  // namespace planarvo
