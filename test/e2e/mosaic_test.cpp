// The floor mosaic end to end: a simulated drive tracked through the C API, its mosaic built at
// 1 mm/px, written with its map_server YAML, read back and compared, pixel by pixel at the place
// the YAML gives, with the simulator's own ground texture (normalised cross-correlation); a
// wrong calibration must show. `planarvo mosaic` as a user runs it gives the same image; bad
// input is exit code 2.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/capi_util.h"
#include "common/mosaic_check.h"
#include "common/test_util.h"
#include "io/formats.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::run_cli;
using test::ScratchDir;

struct MosaicDeleter {
  void operator()(planarvo_mosaic* m) const { planarvo_mosaic_destroy(m); }
};
using ApiMosaic = std::unique_ptr<planarvo_mosaic, MosaicDeleter>;

using test::Ground;
using test::MapYaml;
using test::read_map_yaml;

double ncc_against_ground(const fs::path& image_path, const Ground& ground, const planarvo_se2& first_true_pose,
                          int64_t* seen = nullptr) {
  const MapYaml y = read_map_yaml(fs::path(image_path).replace_extension(".yaml"));
  EXPECT_TRUE(y.ok);
  EXPECT_EQ(y.image, image_path.filename().string());
  EXPECT_EQ(y.yaw, 0.0);
  return test::ncc_against_ground(image_path, ground, first_true_pose.x, first_true_pose.y, first_true_pose.theta, seen);
}

ApiMosaic build(planarvo_context* ctx, planarvo_dataset* ds, const planarvo_extrinsics& e,
                const std::vector<test::TrackedFrame>& frames, double resolution) {
  std::vector<double> t;
  std::vector<planarvo_se2> poses;
  for (const auto& f : frames) {
    t.push_back(f.data.timestamp);
    poses.push_back(f.result.pose);
  }
  planarvo_mosaic_options o;
  planarvo_mosaic_options_init(&o);
  o.resolution = resolution;
  planarvo_mosaic* m = nullptr;
  EXPECT_EQ(planarvo_mosaic_build(ctx, ds, &e, t.data(), poses.data(), t.size(), &o, &m), PLANARVO_OK)
      << planarvo_last_error();
  return ApiMosaic(m);
}

TEST(Mosaic, MatchesTheGroundTextureWhereItsYamlPlacesIt) {
  ScratchDir dir;
  const std::string seq = (dir / "drive").string();
  ASSERT_EQ(run_cli("simulate --quiet --out " + seq + " --seconds 3 --seed 11").exit_code, 0);
  planarvo_dataset_info info{};
  planarvo_extrinsics e{};
  ASSERT_EQ(planarvo_extrinsics_load((seq + "/extrinsics_gt.yaml").c_str(), &e), PLANARVO_OK);
  const std::vector<test::TrackedFrame> frames = test::track_through_api(seq, e, nullptr, &info);
  ASSERT_EQ(frames.size(), 90u);
  test::ApiContext ctx = test::api_context();
  test::ApiDataset ds = test::api_dataset(seq);
  const double texel = 0.0004;  // simulate's default (simulation.yaml)
  const Ground ground(test::source_dir() / "data" / "textures" / "asphalt_01.png", texel, 0.001);

  ApiMosaic mosaic = build(ctx.get(), ds.get(), e, frames, 0.001);
  ASSERT_TRUE(mosaic);
  const fs::path png = dir / "floor.png";
  ASSERT_EQ(planarvo_mosaic_save(mosaic.get(), png.c_str()), PLANARVO_OK) << planarvo_last_error();
  planarvo_mosaic_info mi{};
  mi.struct_size = sizeof mi;
  ASSERT_EQ(planarvo_mosaic_info_get(mosaic.get(), &mi), PLANARVO_OK);
  int64_t seen = 0;
  const double ncc = ncc_against_ground(png, ground, frames[0].data.groundtruth, &seen);
  EXPECT_GT(ncc, 0.9);
  EXPECT_EQ(seen, mi.covered_pixels);
  EXPECT_GT(seen, 200000);  // over 0.2 m^2 of ground seen
  // The image in memory is the file's.
  planarvo_image im{};
  ASSERT_EQ(planarvo_mosaic_image(mosaic.get(), &im), PLANARVO_OK);
  const cv::Mat file = cv::imread(png.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(file.cols, im.width);
  ASSERT_EQ(file.rows, im.height);
  EXPECT_EQ(cv::norm(file, cv::Mat(im.height, im.width, CV_8UC1, const_cast<void*>(im.data), im.stride), cv::NORM_INF),
            0.0);

  // Displaced by a whole number of pixels, the same image no longer matches: the placement is
  // what the NCC measures, not the texture's statistics.
  {
    const MapYaml y = read_map_yaml(dir / "floor.yaml");
    std::ofstream(dir / "shifted.yaml") << "# shifted\nimage: shifted.png\nresolution: " << y.resolution << "\norigin: ["
                                        << y.x + 3 * y.resolution << ", " << y.y << ", 0.0]\n";
    fs::copy_file(png, dir / "shifted.png");
    const double ncc_shifted = ncc_against_ground(dir / "shifted.png", ground, frames[0].data.groundtruth);
    std::printf("NCC against the ground: %.3f; moved by 3 pixels: %.3f\n", ncc, ncc_shifted);
    EXPECT_LT(ncc_shifted, 0.6);
  }

  // A wrong calibration (yaw 3 degrees and x 15 mm off) blurs and doubles the texture.
  planarvo_extrinsics wrong = e;
  wrong.yaw += 3 * M_PI / 180;
  wrong.x += 0.015;
  ApiMosaic bad = build(ctx.get(), ds.get(), wrong, frames, 0.001);
  ASSERT_TRUE(bad);
  ASSERT_EQ(planarvo_mosaic_save(bad.get(), (dir / "wrong.png").c_str()), PLANARVO_OK);
  const double ncc_wrong = ncc_against_ground(dir / "wrong.png", ground, frames[0].data.groundtruth);
  std::printf("NCC with a wrong calibration: %.3f\n", ncc_wrong);
  EXPECT_LT(ncc_wrong, ncc - 0.3) << "true " << ncc << ", wrong " << ncc_wrong;

  // The tool, from the trajectory `track` wrote, makes the same image and YAML.
  ASSERT_EQ(run_cli("track --quiet " + seq + " --extrinsics " + seq + "/extrinsics_gt.yaml -o " + (dir / "traj.txt").string())
                .exit_code,
            0);
  const auto r = run_cli("mosaic --quiet " + seq + " --trajectory " + (dir / "traj.txt").string() + " --extrinsics " +
                         seq + "/extrinsics_gt.yaml -o " + (dir / "cli.png").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const cv::Mat cli = cv::imread((dir / "cli.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(cli.size(), file.size());
  // The trajectory file holds the poses to 17 significant digits, so the same warps; at most a
  // rounding of the 8-bit value apart.
  EXPECT_LE(cv::norm(cli, file, cv::NORM_INF), 1.0);
  const MapYaml a = read_map_yaml(dir / "cli.yaml"), b = read_map_yaml(dir / "floor.yaml");
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.resolution, b.resolution);
}

// A rolling shutter read out over 30 ms at 2 m/s (6 cm from the first row's read to the last's),
// mosaicked from the simulator's ground truth: with the readout (camera.yaml's) each row is warped
// from the robot's pose when it was read, and the mosaic matches the ground as the same drive's
// through a global shutter does; taken as a global shutter (--readout-time 0), it does not.
TEST(Mosaic, ARollingShutterIsWarpedRowByRow) {
  ScratchDir dir;
  const std::string drive = " --seconds 1.5 --width 320 --height 240 --motion straight --max-speed 2 --seed 5";
  const std::string rs = (dir / "rs").string(), gs = (dir / "gs").string();
  ASSERT_EQ(run_cli("simulate --quiet --out " + rs + drive + " --readout-time 0.03").exit_code, 0);
  ASSERT_EQ(run_cli("simulate --quiet --out " + gs + drive).exit_code, 0);
  const Ground ground(test::source_dir() / "data" / "textures" / "asphalt_01.png", 0.0004, 0.001);
  // The ground truth is in the simulator's world frame: the mosaic's frame is the ground's.
  const auto mosaic_ncc = [&](const std::string& seq, const std::string& name, const std::string& extra) {
    const fs::path png = dir / (name + ".png");
    const auto r = run_cli("mosaic --quiet " + seq + " --trajectory " + seq + "/groundtruth.txt --extrinsics " + seq +
                           "/extrinsics_gt.yaml -o " + png.string() + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    int64_t seen = 0;
    const double ncc = test::ncc_against_ground(png, ground, 0.0, 0.0, 0.0, &seen);
    EXPECT_GT(seen, 100000) << name;
    return ncc;
  };
  const double global = mosaic_ncc(gs, "global", "");
  const double rows = mosaic_ncc(rs, "rows", "");
  const double ignored = mosaic_ncc(rs, "ignored", " --readout-time 0");
  std::printf("NCC against the ground: global shutter %.3f; rolling shutter row by row %.3f, taken as global %.3f\n",
              global, rows, ignored);
  // 320x240 frames at 1 mm per mosaic pixel: about a frame pixel per mosaic pixel, so a lower NCC
  // than the 640x480 drive's above (measured 0.860 global, 0.865 row by row, 0.306 ignored).
  EXPECT_GT(global, 0.8);
  EXPECT_GT(rows, global - 0.02);
  EXPECT_LT(ignored, rows - 0.3);
}

TEST(Mosaic, BadInputIsExitCode2) {
  ScratchDir dir;
  const std::string seq = (dir / "tiny").string();
  ASSERT_EQ(run_cli("simulate --quiet --out " + seq + " --seconds 0.5 --width 96 --height 64 --seed 3").exit_code, 0);
  const std::string traj = (dir / "traj.txt").string();
  ASSERT_EQ(run_cli("track --quiet " + seq + " --extrinsics " + seq + "/extrinsics_gt.yaml -o " + traj).exit_code, 0);
  const std::string common = "mosaic --quiet " + seq + " --extrinsics " + seq + "/extrinsics_gt.yaml ";
  const fs::path png = dir / "m.png";
  const std::string out = " -o " + png.string();
  ASSERT_EQ(run_cli(common + "--trajectory " + traj + out).exit_code, 0);
  ASSERT_TRUE(fs::exists(png));
  fs::remove(png);
  fs::remove(dir / "m.yaml");
  // Each bad run below exits with 2 and writes neither the image nor its YAML.
  const auto refused = [&](const std::string& args) {
    const auto r = run_cli(common + args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_FALSE(fs::exists(png)) << args;
    EXPECT_FALSE(fs::exists(dir / "m.yaml")) << args;
    return r;
  };

  // A pose at a time that is no frame's (the 5th line moved by 10 ms).
  std::vector<io::StampedPose> poses = io::read_tum(traj);
  std::vector<io::StampedPose> moved = poses;
  moved[4].t += 0.010;
  io::write_tum((dir / "moved.txt").string(), moved);
  refused("--trajectory " + (dir / "moved.txt").string() + out);
  // An empty trajectory (the header only).
  std::ofstream(dir / "empty.txt") << "# timestamp x y z qx qy qz qw\n";
  refused("--trajectory " + (dir / "empty.txt").string() + out);
  // A resolution that would make the image over 20000 pixels on a side; the size it would be is
  // printed: the drive's extent over the resolution.
  refused("--trajectory " + traj + " --resolution 0.00001" + out);
  // A resolution so coarse that no frame covers a pixel (issue 27: an empty image, exit 0).
  refused("--trajectory " + traj + " --resolution 1e300" + out);
  // A trajectory 1e17 m away (issue 27: an empty image, exit 0): refused at its line.
  std::vector<io::StampedPose> far = poses;
  for (auto& s : far) s.pose.x += 1e17;
  io::write_tum((dir / "far.txt").string(), far);
  const auto far_run = refused("--trajectory " + (dir / "far.txt").string() + out);
  EXPECT_NE(far_run.output.find((dir / "far.txt").string() + ":2:"), std::string::npos) << far_run.output;
  // Bad options.
  refused("--trajectory " + traj + " --resolution -1" + out);
  refused(out);                        // no trajectory
  refused("--trajectory " + traj);     // no output
  refused("--trajectory " + (dir / "missing.txt").string() + out);

  // Through the C API: the first mismatch is INVALID_INPUT; so is an empty trajectory.
  test::ApiContext ctx = test::api_context();
  test::ApiDataset ds = test::api_dataset(seq);
  planarvo_extrinsics e{};
  ASSERT_EQ(planarvo_extrinsics_load((seq + "/extrinsics_gt.yaml").c_str(), &e), PLANARVO_OK);
  std::vector<double> t;
  std::vector<planarvo_se2> p;
  for (const auto& s : moved) {
    t.push_back(s.t);
    p.push_back({s.pose.x, s.pose.y, s.pose.theta});
  }
  planarvo_mosaic* m = nullptr;
  EXPECT_EQ(planarvo_mosaic_build(ctx.get(), ds.get(), &e, t.data(), p.data(), t.size(), nullptr, &m),
            PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_EQ(m, nullptr);
  EXPECT_EQ(planarvo_mosaic_build(ctx.get(), ds.get(), &e, t.data(), p.data(), 0, nullptr, &m),
            PLANARVO_ERROR_INVALID_INPUT);
  // A trajectory may leave frames out.
  t.erase(t.begin() + 4);
  p.erase(p.begin() + 4);
  // Extrinsics that are not finite, or a camera under the ground (issue 27: every frame was
  // left out and an empty mosaic returned).
  for (const double bad : {std::nan(""), HUGE_VAL}) {
    planarvo_extrinsics b = e;
    b.pitch = bad;
    EXPECT_EQ(planarvo_mosaic_build(ctx.get(), ds.get(), &b, t.data(), p.data(), t.size(), nullptr, &m),
              PLANARVO_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(m, nullptr);
  }
  planarvo_extrinsics under = e;
  under.z = -0.1;
  EXPECT_EQ(planarvo_mosaic_build(ctx.get(), ds.get(), &under, t.data(), p.data(), t.size(), nullptr, &m),
            PLANARVO_ERROR_INVALID_ARGUMENT);
  // Poses 1e17 m away, and a resolution coarser than a frame (issue 27: empty mosaics).
  std::vector<planarvo_se2> far_poses = p;
  for (auto& q : far_poses) q.x += 1e17;
  EXPECT_EQ(planarvo_mosaic_build(ctx.get(), ds.get(), &e, t.data(), far_poses.data(), t.size(), nullptr, &m),
            PLANARVO_ERROR_INVALID_INPUT);
  planarvo_mosaic_options coarse;
  planarvo_mosaic_options_init(&coarse);
  coarse.resolution = 1e300;
  EXPECT_EQ(planarvo_mosaic_build(ctx.get(), ds.get(), &e, t.data(), p.data(), t.size(), &coarse, &m),
            PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(m, nullptr);
  EXPECT_EQ(planarvo_mosaic_build(ctx.get(), ds.get(), &e, t.data(), p.data(), t.size(), nullptr, &m), PLANARVO_OK)
      << planarvo_last_error();
  planarvo_mosaic_destroy(m);
  planarvo_mosaic_destroy(nullptr);
}

}  // namespace
}  // namespace planarvo
