// Known and saved flat fields as a user meets them: `planarvo track --flat-field` refusing a bad
// file (exit 2 naming it), `--save-flat-field` writing the learnt light of a simulated lamp (a
// 16-bit PNG of the camera's size, brightest where the simulator put the lamp) that `--flat-field`
// reads back; through the C API, a known flat field saved again unchanged, and no model to save
// before one is learnt.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/capi_util.h"
#include "common/test_util.h"

namespace planarvo {
namespace {

using test::run_cli;
using test::ScratchDir;

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(CliFlatField, ABadFlatFieldIsExit2NamingTheFile) {
  ScratchDir d;
  const std::string seq = (d / "seq").string();
  auto r = run_cli("simulate --quiet --out " + seq + " --seconds 0.3 --lamp 0.6 --width 320 --height 240");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string bad = (d / "bad.png").string();
  ASSERT_TRUE(cv::imwrite(bad, cv::Mat(100, 100, CV_8UC1, cv::Scalar(255))));  // not 320x240
  r = run_cli("track --quiet " + seq + " --extrinsics " + seq + "/extrinsics_gt.yaml --flat-field " + bad);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(has(r.output, bad) && has(r.output, "100x100") && has(r.output, "320x240")) << r.output;
  cv::Mat zero(240, 320, CV_8UC1, cv::Scalar(255));
  zero.at<uint8_t>(7, 11) = 0;
  ASSERT_TRUE(cv::imwrite(bad, zero));
  r = run_cli("track --quiet " + seq + " --extrinsics " + seq + "/extrinsics_gt.yaml --flat-field " + bad);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(has(r.output, bad) && has(r.output, "(11, 7)")) << r.output;
}

TEST(CliFlatField, NothingLearntIsAWarningAndNoFile) {
  ScratchDir d;
  const std::string seq = (d / "seq").string();
  auto r = run_cli("simulate --quiet --out " + seq + " --seconds 0.5 --width 320 --height 240");  // even light
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string ff = (d / "ff.png").string();
  r = run_cli("track --quiet " + seq + " --extrinsics " + seq + "/extrinsics_gt.yaml --save-flat-field " + ff);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(has(r.output, "warning") && has(r.output, "learnt") && has(r.output, ff)) << r.output;
  EXPECT_FALSE(std::filesystem::exists(ff));
  EXPECT_FALSE(std::filesystem::exists(ff + ".partial"));
}

TEST(CliFlatField, TheLearntLampIsSavedAndReadBack) {
  ScratchDir d;
  const std::string seq = (d / "seq").string();
  auto r = run_cli("simulate --quiet --out " + seq + " --seconds 4 --lamp 0.6 --width 320 --height 240");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string ff = (d / "ff.png").string(), ext = seq + "/extrinsics_gt.yaml";
  r = run_cli("track --quiet " + seq + " --extrinsics " + ext + " --save-flat-field " + ff + " --max-lost 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_FALSE(has(r.output, "warning")) << r.output;
  const cv::Mat raw = cv::imread(ff, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(raw.type(), CV_16UC1);
  ASSERT_EQ(raw.cols, 320);
  ASSERT_EQ(raw.rows, 240);
  double lo = 0, hi = 0;
  cv::minMaxLoc(raw, &lo, &hi);
  EXPECT_EQ(hi, 65535);
  EXPECT_GT(lo, 0);  // no zeros: the file is a flat field that reads back
  // The simulator's lamp is centred at 58 % of the width, 42 % of the height.
  cv::Mat blurred;
  raw.convertTo(blurred, CV_32F);
  cv::GaussianBlur(blurred, blurred, cv::Size(0, 0), 10.0);
  cv::Point at;
  cv::minMaxLoc(blurred, nullptr, nullptr, nullptr, &at);
  EXPECT_NEAR(at.x, 0.58 * 319, 0.15 * 320) << at;
  EXPECT_NEAR(at.y, 0.42 * 239, 0.15 * 240) << at;
  // The lamp's falloff (0.6 of the light at the darkest corner) is in the file: its corners are
  // well below its brightest point.
  const double corners = (blurred.at<float>(15, 15) + blurred.at<float>(15, 304) + blurred.at<float>(224, 15) +
                          blurred.at<float>(224, 304)) / 4.0;
  EXPECT_LT(corners, 0.85 * 65535) << corners;
  // Against the lamp itself (sim/simulator.h, camera_lighting: gain (1 + rho^2)^(-3/2), rho the
  // distance from the lamp's centre scaled so that the farthest corner gets 1 - 0.6), relative to
  // its brightest point, away from the border (whose columns have no undistorted source and take
  // the nearest value): measured within 0.991..1.017.
  const double lx = 0.58 * 319, ly = 0.42 * 239;
  double far = 0;
  for (double cx : {0.0, 319.0})
    for (double cy : {0.0, 239.0}) far = std::max(far, std::hypot(cx - lx, cy - ly));
  const double inv_s2 = (std::pow(0.4, -2.0 / 3.0) - 1.0) / (far * far);
  double lo_ratio = 1e9, hi_ratio = 0;
  for (int y = 30; y < 210; ++y)
    for (int x = 30; x < 290; ++x) {
      const double lamp = std::pow(1.0 + ((x - lx) * (x - lx) + (y - ly) * (y - ly)) * inv_s2, -1.5);
      const double ratio = raw.at<uint16_t>(y, x) / 65535.0 / lamp;
      lo_ratio = std::min(lo_ratio, ratio);
      hi_ratio = std::max(hi_ratio, ratio);
    }
  EXPECT_GT(lo_ratio, 0.96);
  EXPECT_LT(hi_ratio, 1.04);

  // Reused: tracking with it as the known flat field runs, and saving gives it back.
  const std::string again = (d / "again.png").string();
  r = run_cli("track --quiet " + seq + " --extrinsics " + ext + " --flat-field " + ff + " --save-flat-field " + again + " --max-lost 100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const cv::Mat back = cv::imread(again, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.type(), CV_16UC1);
  cv::Mat diff;
  cv::absdiff(back(cv::Rect(20, 20, 280, 200)), raw(cv::Rect(20, 20, 280, 200)), diff);
  double worst = 0;
  cv::minMaxLoc(diff, nullptr, &worst);
  EXPECT_LT(worst, 0.01 * 65535);
}

TEST(CApiFlatField, AKnownFlatFieldIsSavedUnchangedAndNothingLearntIsFailed) {
  ScratchDir d;
  const std::string seq = (d / "seq").string();
  auto r = run_cli("simulate --quiet --out " + seq + " --seconds 0.2 --width 320 --height 240");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  test::ApiDataset ds = test::api_dataset(seq);
  const planarvo_dataset_info info = test::api_info(ds.get());
  planarvo_extrinsics e{};
  ASSERT_EQ(planarvo_extrinsics_load((seq + "/extrinsics_gt.yaml").c_str(), &e), PLANARVO_OK) << planarvo_last_error();
  test::ApiContext ctx = test::api_context();

  // A smooth known gain, brightest 1 (16-bit).
  const int w = info.camera.width, h = info.camera.height;
  cv::Mat gain(h, w, CV_16UC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double dx = x - 0.3 * w, dy = y - 0.6 * h;
      gain.at<uint16_t>(y, x) = static_cast<uint16_t>(std::lround(60000.0 / (1.0 + (dx * dx + dy * dy) / (250.0 * 250.0))));
    }
  const std::string known = (d / "known.png").string(), saved = (d / "saved.png").string();
  ASSERT_TRUE(cv::imwrite(known, gain));

  planarvo_tracker_options o;
  planarvo_tracker_options_init(&o);
  EXPECT_EQ(o.flat_field, nullptr);
  planarvo_tracker* t = nullptr;
  // Learning: nothing to save before frames.
  ASSERT_EQ(planarvo_tracker_create(ctx.get(), &info.camera, &e, &o, &t), PLANARVO_OK) << planarvo_last_error();
  test::ApiTracker learning(t);
  EXPECT_EQ(planarvo_tracker_save_flat_field(learning.get(), saved.c_str()), PLANARVO_ERROR_FAILED);
  EXPECT_TRUE(has(planarvo_last_error(), "learnt")) << planarvo_last_error();

  // An older struct_size does not read flat_field (garbage there is ignored).
  o.struct_size = offsetof(planarvo_tracker_options, flat_field);
  o.flat_field = "/nonexistent/flat.png";
  ASSERT_EQ(planarvo_tracker_create(ctx.get(), &info.camera, &e, &o, &t), PLANARVO_OK) << planarvo_last_error();
  planarvo_tracker_destroy(t);
  o.struct_size = sizeof o;
  ASSERT_EQ(planarvo_tracker_create(ctx.get(), &info.camera, &e, &o, &t), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_TRUE(has(planarvo_last_error(), "/nonexistent/flat.png")) << planarvo_last_error();

  o.flat_field = known.c_str();
  ASSERT_EQ(planarvo_tracker_create(ctx.get(), &info.camera, &e, &o, &t), PLANARVO_OK) << planarvo_last_error();
  test::ApiTracker given(t);
  ASSERT_EQ(planarvo_tracker_save_flat_field(given.get(), saved.c_str()), PLANARVO_OK) << planarvo_last_error();
  const cv::Mat back = cv::imread(saved, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.type(), CV_16UC1);
  ASSERT_EQ(back.size(), gain.size());
  // Where the model has a value the gain comes back to 16-bit precision and the two bilinear
  // samplings'; the camera's border columns, which have no undistorted source under its barrel
  // distortion, take the nearest value: close, not exact.
  double inner = 0, border = 0;
  for (int y = 10; y < h - 10; ++y)
    for (int x = 10; x < w - 10; ++x) {
      const double err = std::abs(back.at<uint16_t>(y, x) / 65535.0 - gain.at<uint16_t>(y, x) / 60000.0);
      const bool in = x >= 30 && x < w - 30 && y >= 30 && y < h - 30;
      (in ? inner : border) = std::max(in ? inner : border, err);
    }
  EXPECT_LT(inner, 1e-3);
  EXPECT_LT(border, 0.02);
}

}  // namespace
}  // namespace planarvo
