// Plausible extrinsics (core/extrinsics.h): what a camera on a vehicle can be, the unit mistake
// named when a value is outside, and the checks in the tracker, the simulator and the camera
// calibration through the C API, each with its option to let an unusual rig through.
#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "core/extrinsics.h"
#include "planarvo/planarvo.h"

namespace planarvo {
namespace {

using ::testing::HasSubstr;

const Extrinsics kGood{0.2441, -0.0185, 0.1787, 0.2164, 0.3072, -0.1606};

TEST(PlausibleExtrinsics, RangesAndTheUnitMistakeNamed) {
  EXPECT_EQ(implausible_extrinsics(kGood), "");
  // The ranges' ends pass; just past them does not.
  EXPECT_EQ(implausible_extrinsics({20.0, -20.0, 5.0, 2 * M_PI, -2 * M_PI, 2 * M_PI}), "");
  EXPECT_NE(implausible_extrinsics({20.001, 0, 1, 0, 0, 0}), "");
  EXPECT_NE(implausible_extrinsics({0, 0, 5.001, 0, 0, 0}), "");
  EXPECT_NE(implausible_extrinsics({0, 0, 1, 0, 0, 2 * M_PI + 1e-9}), "");

  Extrinsics mm = kGood;
  mm.z = 178.7;
  EXPECT_THAT(implausible_extrinsics(mm), HasSubstr("z = 178.7 m is over 5 m: millimetres by mistake?"));
  mm = kGood;
  mm.x = 244.1;
  EXPECT_THAT(implausible_extrinsics(mm), HasSubstr("x = 244.1 m is more than 20 m: millimetres by mistake?"));
  Extrinsics deg = kGood;
  deg.roll = 12.4;
  EXPECT_THAT(implausible_extrinsics(deg), HasSubstr("roll = 12.4 rad is more than a turn: degrees by mistake?"));
  deg = kGood;
  deg.yaw = -9.2;
  EXPECT_THAT(implausible_extrinsics(deg), HasSubstr("yaw = -9.2 rad"));
  // The hint only where the value in millimetres would be plausible: 40 (mm: 0.04 m) has it,
  // a height of 90 km (90 m in millimetres, still too high) does not.
  EXPECT_THAT(implausible_extrinsics({0, 40.0, 1, 0, 0, 0}), HasSubstr("millimetres by mistake?"));
  EXPECT_THAT(implausible_extrinsics({0, 0, 90000.0, 0, 0, 0}), ::testing::Not(HasSubstr("millimetres")));
  // Below the ground, or no height: refused unless the height is optional there.
  EXPECT_NE(implausible_extrinsics({0, 0, -0.2, 0, 0, 0}), "");
  EXPECT_NE(implausible_extrinsics({0, 0, 0, 0, 0, 0}), "");
  EXPECT_EQ(implausible_extrinsics({0, 0, 0, 0.1, 0.2, 0}, false), "");
  EXPECT_THROW(check_plausible_height(178.7, "height"), Error);
  EXPECT_NO_THROW(check_plausible_height(0.1787, "height"));
}

planarvo_camera camera() {
  planarvo_camera c{};
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 250;
  c.cx = 159.5;
  c.cy = 119.5;
  return c;
}

TEST(PlausibleExtrinsics, TheTrackerRefusesUnlessTheOptionLetsThemThrough) {
  planarvo_context* ctx = nullptr;
  ASSERT_EQ(planarvo_context_create(nullptr, &ctx), PLANARVO_OK) << planarvo_last_error();
  const planarvo_camera c = camera();
  const planarvo_extrinsics degrees{0.2441, -0.0185, 0.1787, 12.4, 17.6, -9.2};  // angles in degrees
  planarvo_tracker_options o;
  planarvo_tracker_options_init(&o);
  EXPECT_EQ(o.accept_unusual_extrinsics, 0);
  planarvo_tracker* t = nullptr;
  EXPECT_EQ(planarvo_tracker_create(ctx, &c, &degrees, &o, &t), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_THAT(planarvo_last_error(), HasSubstr("degrees by mistake?"));
  EXPECT_THAT(planarvo_last_error(), HasSubstr("accept_unusual_extrinsics"));
  EXPECT_EQ(t, nullptr);
  o.accept_unusual_extrinsics = 1;
  ASSERT_EQ(planarvo_tracker_create(ctx, &c, &degrees, &o, &t), PLANARVO_OK) << planarvo_last_error();
  planarvo_tracker_destroy(t);
  planarvo_context_destroy(ctx);
}

TEST(PlausibleExtrinsics, TheSimulatorAndTheCalibrationRefuseUnlessTheirOptionLetsThemThrough) {
  planarvo_sim_options s;
  planarvo_sim_options_init(&s);
  EXPECT_EQ(s.accept_unusual_extrinsics, 0);
  s.extrinsics.z = 178.7;
  planarvo_context* ctx = nullptr;
  ASSERT_EQ(planarvo_context_create(nullptr, &ctx), PLANARVO_OK) << planarvo_last_error();
  s.texture = "/nonexistent/texture.png";  // the options are checked before the texture is read
  EXPECT_EQ(planarvo_simulate(ctx, &s, "/nonexistent/out"), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_THAT(planarvo_last_error(), HasSubstr("millimetres by mistake?"));
  s.accept_unusual_extrinsics = 1;
  EXPECT_NE(planarvo_simulate(ctx, &s, "/nonexistent/out"), PLANARVO_ERROR_INVALID_ARGUMENT)
      << planarvo_last_error();  // now the texture is what is wrong
  planarvo_context_destroy(ctx);

  planarvo_camera_calibration_options co;
  planarvo_camera_calibration_options_init(&co);
  EXPECT_EQ(co.accept_unusual_extrinsics, 0);
}

}  // namespace
}  // namespace planarvo
