// The simulator's body on its suspension (simulator_body.cpp): the roll that follows the yaw
// rate, the pitch over speed bumps, the camera carried by the body about the robot's origin, the
// knock to the mounting, the frames rendered from them and the truth written with a data set.
// References: the yaw rates and distances recomputed from the trajectory's velocities, rotation
// matrices written out by hand, Renderer::render_float at explicitly built extrinsics.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "common/test_util.h"
#include "core/error.h"
#include "io/formats.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"

namespace planarvo::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

Options car_options() {
  Options o;
  o.camera = default_camera(160, 120, 60.0);
  o.extrinsics = Extrinsics{-1.0, 0.0, 0.9, 0.0, 40.0 * kDeg, M_PI};
  o.supersampling = 1;
  o.seconds = 12.0;
  o.motion = MotionProfile::Car;
  o.max_speed = 3.0;
  o.min_turn_radius = 6.0;
  o.seed = 3;
  o.lean = -0.07;
  o.bumps = 10.0 * kDeg;
  return o;
}

Eigen::Matrix3d rx(double a) {
  Eigen::Matrix3d m;
  m << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
  return m;
}
Eigen::Matrix3d ry(double a) {
  Eigen::Matrix3d m;
  m << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return m;
}

TEST(SimBody, RollFollowsTheYawRateSmoothly) {
  const Options o = car_options();
  const Trajectory tr = generate_trajectory(o);
  double largest = 0.0;
  for (size_t k = 0; k + 1 < tr.t.size(); ++k) {
    // At each interval's midpoint the roll is lean times that interval's yaw rate.
    const double mid = 0.5 * (tr.t[k] + tr.t[k + 1]);
    EXPECT_NEAR(body_attitude(o, tr, mid).roll, o.lean * tr.velocity[k].y(), 1e-12) << k;
    largest = std::max(largest, std::abs(o.lean * tr.velocity[k].y()));
    // Continuous at the frames (where the yaw rate steps): no jump across a frame's time.
    const double a = body_attitude(o, tr, tr.t[k + 1] - 1e-7).roll, b = body_attitude(o, tr, tr.t[k + 1] + 1e-7).roll;
    EXPECT_LT(std::abs(a - b), 1e-6) << k;
  }
  // Not vacuous: the car turns, so the body rolls by degrees.
  EXPECT_GT(largest, 1.0 * kDeg);
}

TEST(SimBody, BumpsPitchTheBodyAtTheirPlaces) {
  Options o = car_options();
  o.lean = 0.0;
  const Trajectory tr = generate_trajectory(o);
  // The distance driven, integrated independently at fine steps from the velocities.
  const double step = 1e-3;
  double s = 0.0, top = 0.0, bottom = 0.0;
  int bumps_seen = 0;
  bool in_bump = false;
  for (double t = 0.0; t < tr.t.back(); t += step) {
    const size_t k = std::min(tr.velocity.size() - 1, static_cast<size_t>(t * o.fps));
    const double pitch = body_attitude(o, tr, t).pitch;
    const double into = s - 0.5 * o.bump_spacing - o.bump_spacing * std::floor((s - 0.5 * o.bump_spacing) / o.bump_spacing);
    const bool on = s > 0.5 * o.bump_spacing && into > 0.01 && into < o.bump_length - 0.01;
    const bool off = s < 0.5 * o.bump_spacing - 0.01 || (into > o.bump_length + 0.01 && into < o.bump_spacing - 0.01);
    if (off) {
      EXPECT_EQ(pitch, 0.0) << "t " << t << " s " << s;
    }
    if (on && !in_bump) ++bumps_seen;
    in_bump = on;
    top = std::max(top, pitch);
    bottom = std::min(bottom, pitch);
    s += std::abs(tr.velocity[k].x()) * step;
  }
  EXPECT_GE(bumps_seen, 2);
  EXPECT_NEAR(top, o.bumps, 0.01 * o.bumps);
  EXPECT_NEAR(bottom, -o.bumps, 0.01 * o.bumps);
}

TEST(SimBody, TheCameraTurnsWithTheBodyAboutTheRobotsOrigin) {
  Options o = car_options();
  o.knock_time = 6.0;
  o.knock_roll = 2.0 * kDeg;
  o.knock_pitch = -1.5 * kDeg;
  o.knock_z = 0.01;
  const Trajectory tr = generate_trajectory(o);
  int tilted = 0;
  for (double t = 0.05; t < tr.t.back(); t += 0.37) {
    const BodyAttitude a = body_attitude(o, tr, t);
    Extrinsics mount = o.extrinsics;
    if (t >= o.knock_time) {
      mount.roll += o.knock_roll;
      mount.pitch += o.knock_pitch;
      mount.z += o.knock_z;
    }
    const Eigen::Matrix3d B = rx(a.roll) * ry(a.pitch);
    const Extrinsics e = camera_extrinsics_at(o, tr, t);
    EXPECT_LT((e.t_vc() - B * mount.t_vc()).norm(), 1e-12) << t;
    EXPECT_LT((e.R_vc() - B * mount.R_vc()).norm(), 1e-12) << t;
    // The camera's height above the plane: the mount's rotated about the ground point below the
    // robot's origin.
    EXPECT_NEAR(e.z, B.row(2).dot(mount.t_vc()), 1e-12);
    if (std::abs(a.pitch) > 1 * kDeg || std::abs(a.roll) > 0.5 * kDeg) ++tilted;
  }
  EXPECT_GT(tilted, 3);
  // A rigid body and no knock: the options' extrinsics exactly.
  Options rigid = o;
  rigid.lean = rigid.bumps = 0.0;
  rigid.knock_time = HUGE_VAL;
  const Extrinsics r = camera_extrinsics_at(rigid, tr, 7.3);
  EXPECT_EQ(r.x, o.extrinsics.x);
  EXPECT_EQ(r.pitch, o.extrinsics.pitch);
  EXPECT_EQ(knocked_extrinsics(rigid).z, o.extrinsics.z);
}

TEST(SimBody, FramesAreRenderedWithTheBodysAttitudeRowByRow) {
  ocl::Runtime rt;
  Options o = car_options();
  o.readout_time = 0.03;
  o.texel_size = 0.02;  // 5 m of texture, coarse enough to show at the camera's 1-4 m range
  const Trajectory tr = generate_trajectory(o);
  cv::Mat texture(256, 256, CV_32FC1);
  Random rnd(9);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) texture.at<float>(y, x) = static_cast<float>(255.0 * rnd.uniform());
  Renderer renderer(rt, texture, o);
  // The frame where the body pitches most.
  size_t k = 1;
  double most = 0.0;
  for (size_t i = 1; i + 1 < tr.t.size(); ++i) {
    const double p = std::abs(body_attitude(o, tr, tr.t[i]).pitch);
    if (p > most) most = p, k = i;
  }
  ASSERT_GT(most, 5.0 * kDeg);
  const int H = o.camera.height;
  const cv::Mat frame = render_frame(renderer, o, tr, k);
  for (int r : {0, 1, 40, H - 1}) {
    const double t = tr.t[k] + static_cast<double>(r) / (H - 1) * o.readout_time;
    const BodyAttitude a = body_attitude(o, tr, t);
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = rx(a.roll) * ry(a.pitch);
    const cv::Mat want = renderer.render_float(pose_at(tr, t), Extrinsics::from_matrix(T * o.extrinsics.T_vc()));
    EXPECT_LT(cv::norm(frame.row(r), want.row(r), cv::NORM_INF), 1e-3) << "row " << r;
  }
  // Not vacuous: the rigid camera's render differs.
  const cv::Mat rigid = renderer.render_float(pose_at(tr, tr.t[k] + o.readout_time), o.extrinsics);
  EXPECT_GT(cv::norm(frame.row(H - 1), rigid.row(H - 1), cv::NORM_INF), 20.0);
}

TEST(SimBody, ADataSetCarriesTheTruePlaneAndTheKnockedMount) {
  ocl::Runtime rt;
  test::ScratchDir dir;
  Options o = car_options();
  o.seconds = 1.0;
  o.texture = test::texture("asphalt_01.png").string();
  o.knock_time = 0.5;
  o.knock_z = -0.02;
  o.knock_pitch = 2.0 * kDeg;
  simulate(rt, o, dir.path().string());
  const Trajectory tr = generate_trajectory(o);
  const std::vector<io::PlaneAttitude> plane = io::read_plane((dir.path() / "plane.txt").string());
  ASSERT_EQ(plane.size(), tr.t.size());
  for (size_t k = 0; k < plane.size(); ++k) {
    const BodyAttitude a = body_attitude(o, tr, tr.t[k]);
    EXPECT_EQ(plane[k].roll, a.roll);
    EXPECT_EQ(plane[k].pitch, a.pitch);
    EXPECT_EQ(plane[k].sigma_roll, 0.0);
  }
  const ExtrinsicsEstimate knocked = io::read_extrinsics_yaml((dir.path() / "extrinsics_knocked.yaml").string());
  EXPECT_NEAR(knocked.value.z, o.extrinsics.z - 0.02, 1e-12);
  EXPECT_NEAR(knocked.value.pitch, o.extrinsics.pitch + 2.0 * kDeg, 1e-12);
  EXPECT_NEAR(knocked.value.roll, o.extrinsics.roll, 1e-12);
}

TEST(SimBody, OptionsAreChecked) {
  const auto refused = [](const Options& o, const char* says) {
    try {
      validate(o);
      ADD_FAILURE() << "accepted: " << says;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
      EXPECT_THAT(e.what(), ::testing::HasSubstr(says));
    }
  };
  Options o = car_options();
  Options b = o;
  b.lean = NAN;
  refused(b, "lean");
  b = o;
  b.lean = 7.0;  // degrees per degree/s by mistake of another unit
  refused(b, "lean");
  b = o;
  b.bumps = 30.0 * kDeg;
  refused(b, "bumps");
  b = o;
  b.knock_time = NAN;
  refused(b, "knock_time");
  b = o;
  b.knock_time = 1.0;
  b.knock_roll = 45.0 * kDeg;
  refused(b, "knock");
  b = o;
  b.knock_time = 1.0;
  b.knock_z = -0.85;
  refused(b, "height");
}

}  // namespace
}  // namespace planarvo::sim
