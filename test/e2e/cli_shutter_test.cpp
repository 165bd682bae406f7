// `planarvo simulate --readout-time --exposure` and camera.yaml's rolling_shutter_readout and
// exposure_time as a user meets them: bad values are exit code 2 naming the option or the file; a
// rolling-shutter data set carries its readout and exposure in camera.yaml and simulation.yaml,
// and `info` prints them.
#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/test_util.h"
#include "io/formats.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::run_cli;
using test::ScratchDir;
using ::testing::HasSubstr;

const std::string kSmall = " --quiet --seconds 0.3 --width 96 --height 64";

TEST(CliShutter, BadReadoutOrExposureIsExitCodeTwoNamingTheOption) {
  ScratchDir d;
  const auto refused = [&](const std::string& args, const char* says) {
    SCOPED_TRACE(args);
    const auto r = run_cli("simulate --out " + (d / "never").string() + kSmall + " " + args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(says));
  };
  refused("--readout-time -1", "readout_time");
  refused("--readout-time 0.04", "readout_time");  // longer than 1/30 s
  refused("--exposure -0.001", "exposure_time");
  refused("--exposure 0.05", "exposure_time");
  refused("--readout-time fast", "--readout-time");
  EXPECT_FALSE(fs::exists(d / "never" / "frames.txt"));
  // calibrate takes "estimate" besides seconds, and nothing else.
  const auto r = run_cli("calibrate " + (d / "none").string() + " --readout-time soon");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--readout-time"));
}

TEST(CliShutter, ReadoutIsWrittenToCameraYamlAndPrintedByInfo) {
  ScratchDir d;
  const std::string out = (d / "rs").string();
  auto r = run_cli("simulate --out " + out + kSmall + " --readout-time 0.025 --exposure 0.004");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string camera = test::read_file(fs::path(out) / "camera.yaml");
  EXPECT_THAT(camera, HasSubstr("rolling_shutter_readout"));
  const std::string sim = test::read_file(fs::path(out) / "simulation.yaml");
  EXPECT_THAT(sim, HasSubstr("readout_time: 2.5"));
  EXPECT_THAT(sim, HasSubstr("exposure_time: 4."));
  // The camera file read back holds the values rendered.
  const CameraModel cam = io::read_camera_yaml((fs::path(out) / "camera.yaml").string());
  EXPECT_EQ(cam.rolling_shutter_readout, 0.025);
  EXPECT_EQ(cam.exposure_time, 0.004);
  r = run_cli("info --verify " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("shutter     rolling, 25.000 ms"));

  // A global-shutter data set says nothing of a shutter.
  const std::string global = (d / "gs").string();
  ASSERT_EQ(run_cli("simulate --out " + global + kSmall).exit_code, 0);
  EXPECT_THAT(test::read_file(fs::path(global) / "camera.yaml"), ::testing::Not(HasSubstr("rolling_shutter")));
  r = run_cli("info " + global);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, ::testing::Not(HasSubstr("shutter")));
}

// track and calibrate take --readout-time for one run: a bad value is exit code 2 naming the
// option; a camera.yaml whose readout is longer than the frame interval (a value in milliseconds)
// is exit code 2 naming the file, for every command that opens the data set.
TEST(CliShutter, ReadoutTimeOptionAndFileAreChecked) {
  ScratchDir d;
  const std::string out = (d / "ds").string();
  ASSERT_EQ(run_cli("simulate --out " + out + kSmall + " --readout-time 0.02").exit_code, 0);
  for (const char* cmd : {"track", "calibrate"})
    for (const char* bad : {"-0.01", "nan", "0.2"}) {
      SCOPED_TRACE(std::string(cmd) + " --readout-time " + bad);
      const std::string ext = std::string(cmd) == "track" ? " --extrinsics " + out + "/extrinsics_gt.yaml" : "";
      const auto r = run_cli(std::string(cmd) + " " + out + ext + " --quiet --readout-time " + bad);
      EXPECT_EQ(r.exit_code, 2) << r.output;
      EXPECT_THAT(r.output, HasSubstr("--readout-time"));
    }
  // Milliseconds written as seconds' number.
  std::string camera = test::read_file(fs::path(out) / "camera.yaml");
  const size_t at = camera.find("rolling_shutter_readout");
  ASSERT_NE(at, std::string::npos);
  camera = camera.substr(0, at) + "rolling_shutter_readout: 20\n";
  {
    std::ofstream f(fs::path(out) / "camera.yaml");
    f << camera;
  }
  for (const char* cmd : {"info", "track"}) {
    SCOPED_TRACE(cmd);
    const auto r = run_cli(std::string(cmd) + " " + out + (std::string(cmd) == "track" ? " --extrinsics " + out + "/extrinsics_gt.yaml" : std::string()));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr("camera.yaml"));
    EXPECT_THAT(r.output, HasSubstr("longer than the frames' interval"));
  }
}

TEST(CliShutter, NegativeReadoutInCameraYamlIsExitCodeTwoNamingTheFile) {
  ScratchDir d;
  const std::string out = (d / "ds").string();
  ASSERT_EQ(run_cli("simulate --out " + out + kSmall).exit_code, 0);
  const fs::path camera = fs::path(out) / "camera.yaml";
  {
    std::ofstream f(camera, std::ios::app);
    f << "rolling_shutter_readout: -0.01\n";
  }
  const auto r = run_cli("info " + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("camera.yaml"));
  EXPECT_THAT(r.output, HasSubstr("rolling_shutter_readout"));
}

// An exposure_time that is negative, not a number, or longer than the frame interval (4 for 4 ms)
// is exit code 2 naming the file, for every command that opens the data set.
TEST(CliShutter, BadExposureInCameraYamlIsExitCodeTwoNamingTheFile) {
  ScratchDir d;
  const std::string out = (d / "ds").string();
  ASSERT_EQ(run_cli("simulate --out " + out + kSmall).exit_code, 0);
  const fs::path camera = fs::path(out) / "camera.yaml";
  const std::string original = test::read_file(camera);
  for (const char* bad : {"-0.001", "fast", "4"}) {
    {
      std::ofstream f(camera);
      f << original << "exposure_time: " << bad << "\n";
    }
    for (const char* cmd : {"info", "track"}) {
      SCOPED_TRACE(std::string(cmd) + " with exposure_time " + bad);
      const auto r = run_cli(std::string(cmd) + " " + out +
                             (std::string(cmd) == "track" ? " --extrinsics " + out + "/extrinsics_gt.yaml" : std::string()));
      EXPECT_EQ(r.exit_code, 2) << r.output;
      EXPECT_THAT(r.output, HasSubstr("camera.yaml"));
      EXPECT_THAT(r.output, HasSubstr("exposure"));
    }
  }
}

}  // namespace
}  // namespace planarvo
