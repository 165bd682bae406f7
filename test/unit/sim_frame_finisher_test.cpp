// The simulator's frames finished on worker threads (src/sim/frame_finisher.h): the PNGs hold
// exactly what the camera model makes of each frame done one after the other on one thread,
// whatever the threads' order; a frame that cannot be written is Error(Io) naming it.
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "core/error.h"
#include "sim/frame_finisher.h"
#include "sim/simulator.h"

namespace planarvo::sim {
namespace {

Options lamp_options() {
  Options o;
  o.camera.width = 96;
  o.camera.height = 64;
  o.camera.fx = o.camera.fy = 80;
  o.camera.cx = 47.5;
  o.camera.cy = 31.5;
  o.lamp_falloff = 0.4;
  o.reflection = 30;
  o.pixel_noise = 2.0;
  o.seed = 11;
  return o;
}

std::vector<cv::Mat> clean_frames(size_t n) {
  std::vector<cv::Mat> frames;
  for (size_t k = 0; k < n; ++k) {
    cv::Mat f(64, 96, CV_32FC1);
    cv::randu(f, 20.0 + k, 200.0);
    frames.push_back(f);
  }
  return frames;
}

TEST(SimFrameFinisher, FilesAreTheCameraModelOfEachFrameInAnyOrder) {
  test::ScratchDir dir;
  const Options o = lamp_options();
  const Lighting lighting = camera_lighting(o);
  std::vector<double> t;
  for (int k = 0; k < 24; ++k) t.push_back(k / 30.0);
  const std::vector<Exposure> exposure = exposure_series(o, t);
  const std::vector<cv::Mat> frames = clean_frames(t.size());
  {
    FrameFinisher finisher(o, lighting, exposure, 3, 2);
    for (size_t k = 0; k < frames.size(); ++k)
      finisher.submit(k, frames[k].clone(), (dir / (std::to_string(k) + ".png")).string());
    finisher.finish();
    EXPECT_GT(finisher.camera_seconds(), 0.0);
  }
  for (size_t k = 0; k < frames.size(); ++k) {
    cv::Mat clean = frames[k].clone();
    apply_lighting(lighting, clean);
    const cv::Mat expected = apply_camera(clean, exposure[k], o.pixel_noise, derive_seed(o.seed, 1000 + k));
    const cv::Mat written = cv::imread((dir / (std::to_string(k) + ".png")).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(written.type(), CV_8UC1) << k;
    EXPECT_EQ(cv::norm(written, expected, cv::NORM_INF), 0.0) << "frame " << k;
  }
}

TEST(SimFrameFinisher, AFrameThatCannotBeWrittenIsAnIoErrorNamingIt) {
  test::ScratchDir dir;
  const Options o = lamp_options();
  const Lighting lighting = camera_lighting(o);
  const std::vector<Exposure> exposure(8);
  const std::vector<cv::Mat> frames = clean_frames(8);
  const std::string bad = (dir / "missing" / "3.png").string();
  try {
    FrameFinisher finisher(o, lighting, exposure, 2, 2);
    for (size_t k = 0; k < frames.size(); ++k)
      finisher.submit(k, frames[k].clone(), k == 3 ? bad : (dir / (std::to_string(k) + ".png")).string());
    finisher.finish();
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Io);
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace planarvo::sim
