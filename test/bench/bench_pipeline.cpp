// The image pipeline's speed: per-stage milliseconds (median over frames, the queue drained
// after each stage), the whole pipeline without stage boundaries (median), and the plain C++
// reference, at 640x480 and 320x240 with 4 and 3 levels, on the default device.
//
//   bench_pipeline [frames=200] [--fast-math] [--no-prefilter] [--wg-undistort X Y] [--wg-pyramid X Y]
// (the undistort column includes the prefilter when it is on, the default)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "image/photometric.h"
#include "image/pipeline.h"
#include "image/rolling_shutter.h"
#include "ocl/runtime.h"

using namespace planarvo;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

CameraModel camera(int w, int h) {
  CameraModel c;
  c.width = w;
  c.height = h;
  c.fx = c.fy = 0.8 * w;
  c.cx = 0.5 * w - 0.5;
  c.cy = 0.5 * h - 0.5;
  c.k1 = -0.12;
  c.k2 = 0.03;
  return c;
}

// A textured frame (smoothed noise), so that timings see realistic data.
cv::Mat frame(int w, int h, unsigned seed) {
  cv::Mat f(h, w, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(f, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(f, f, cv::Size(5, 5), 1.0);
  return f;
}

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The rolling shutter's share of a frame's pipeline at 640x480 with 4 levels (a 25 ms readout,
// the robot camera 0.18 m above the floor at 1.5 m/s and 1.2 rad/s): the host's row warp
// (rolling_shutter_warp), its upload (set_row_warp) and process() + finish() with it, against
// process() + finish() of the global shutter, interleaved frame by frame.
void rolling_shutter_rows(ocl::Runtime& rt, const ImagePipelineOptions& opt, int frames) {
  CameraModel cam = camera(640, 480);
  cam.rolling_shutter_readout = 0.025;
  Extrinsics e;
  e.z = 0.18;
  const Eigen::Vector3d twist(1.5, 0.0, 1.2);
  ImagePipeline global(rt, camera(640, 480), 4, opt), rolling(rt, cam, 4, opt);
  std::vector<cv::Mat> input;
  for (unsigned k = 0; k < 8; ++k) input.push_back(frame(640, 480, 31 + k));
  Pyramid out;
  rolling.set_row_warp(rolling_shutter_warp(cam, e, twist));
  for (int k = 0; k < 10; ++k) {
    global.process(input[static_cast<size_t>(k) % 8], out);
    rolling.process(input[static_cast<size_t>(k) % 8], out);
  }
  rt.queue().finish();
  std::vector<double> grid, upload, with, without, stage_rolling, stage_global;
  for (int k = 0; k < frames; ++k) {
    const cv::Mat& f = input[static_cast<size_t>(k) % 8];
    double t0 = now_ms();
    global.process(f, out);
    rt.queue().finish();
    without.push_back(now_ms() - t0);
    // A twist that changes from frame to frame, as a tracker's does.
    const Eigen::Vector3d tw = twist * (1.0 + 1e-3 * (k % 7));
    t0 = now_ms();
    const RowWarp w = rolling_shutter_warp(cam, e, tw);
    const double t1 = now_ms();
    rolling.set_row_warp(w);
    const double t2 = now_ms();
    rolling.process(f, out);
    rt.queue().finish();
    const double t3 = now_ms();
    grid.push_back(t1 - t0);
    upload.push_back(t2 - t1);
    with.push_back(t3 - t2);
    stage_rolling.push_back(rolling.process_timed(f, out).undistort_ms);
    stage_global.push_back(global.process_timed(f, out).undistort_ms);
  }
  std::printf("\nrolling shutter 25 ms, 640x480, 4 levels (%d nodes every %d px):\n", 
              rolling_shutter_warp(cam, e, twist).nodes_x * rolling_shutter_warp(cam, e, twist).nodes_y, kRowWarpStep);
  std::printf("%10s %10s %12s %14s %10s %18s\n", "grid ms", "upload ms", "process ms", "global ms", "extra",
              "undistort ms r/g");
  std::printf("%10.3f %10.3f %12.3f %14.3f %9.0f%% %9.3f/%.3f\n", median(grid), median(upload), median(with),
              median(without),
              100.0 * (median(grid) + median(upload) + median(with) - median(without)) / median(without),
              median(stage_rolling), median(stage_global));
}

}  // namespace

// The photometric model's fit on the host (fit_photometric, what a refit runs beside the
// tracking): statistics of a lamp's falloff over a texture, young (before the statistics
// settle) and settled, with and without the light.
static void photometric_fit(int frames) {
  std::printf("\nphotometric fit on the host (fit_photometric), median ms\n%-9s %8s %8s %8s %8s\n", "size",
              "young", "settled", "young,even", "settled,even");
  const int sizes[][2] = {{640, 480}, {320, 240}};
  for (const auto& s : sizes) {
    const int w = s[0], h = s[1];
    cv::Mat texture(h, w, CV_32FC1), lamp(h, w, CV_32FC1);
    cv::randu(texture, 40.0, 200.0);
    cv::GaussianBlur(texture, texture, cv::Size(0, 0), 2.0);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double r2 = (std::pow(x - 0.5 * w, 2) + std::pow(y - 0.5 * h, 2)) / (0.25 * w * w);
        lamp.at<float>(y, x) = static_cast<float>(1.0 / (1.0 + r2));
      }
    const cv::Mat valid(h, w, CV_8UC1, cv::Scalar(255));
    double t[4];
    for (int c = 0; c < 4; ++c) {
      const cv::Mat mean = c < 2 ? cv::Mat(texture.mul(lamp)) : texture;
      const cv::Mat square = mean.mul(mean) + 25.0f;
      const int n = c % 2 ? 2 * kPhotometricSettledFrames : kPhotometricFirstFitFrames;
      std::vector<double> ms;
      for (int k = 0; k < std::max(5, frames / 20); ++k) {
        const double t0 = now_ms();
        const PhotometricFit f = fit_photometric(mean, square, valid, n, PhotometricOptions());
        ms.push_back(now_ms() - t0);
        if (f.scale.empty()) std::abort();
      }
      t[c] = median(ms);
    }
    char size[32];
    std::snprintf(size, sizeof size, "%dx%d", w, h);
    std::printf("%-9s %8.2f %8.2f %8.2f %8.2f\n", size, t[0], t[1], t[2], t[3]);
  }
}

int main(int argc, char** argv) {
  int frames = 200;
  ImagePipelineOptions opt;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--fast-math")) {
      opt.fast_math = true;
    } else if (!std::strcmp(argv[i], "--no-prefilter")) {
      opt.prefilter = false;
    } else if (!std::strcmp(argv[i], "--wg-undistort") && i + 2 < argc) {
      opt.undistort_wg_x = std::atoi(argv[++i]);
      opt.undistort_wg_y = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--wg-pyramid") && i + 2 < argc) {
      opt.pyramid_wg_x = std::atoi(argv[++i]);
      opt.pyramid_wg_y = std::atoi(argv[++i]);
    } else {
      frames = std::max(1, std::atoi(argv[i]));
    }
  }
  ocl::Runtime rt;
  std::printf("device: %s / %s; %d frames per row; prefilter %s; options: undistort \"%s\", pyramid \"%s\"\n",
              rt.device_info().platform_name.c_str(), rt.device_info().device_name.c_str(), frames,
              opt.prefilter ? "on" : "off",
              ImagePipeline::undistort_build_options(opt).c_str(),
              ImagePipeline::pyramid_build_options(opt).c_str());
  std::printf("%-9s %6s | %8s %9s %8s %8s %8s | %8s | %8s\n", "size", "levels", "upload",
              "undistort", "pyramid", "gradient", "sum", "pipeline", "C++ ref");
  std::printf("%-9s %6s | %8s %9s %8s %8s %8s | %8s | %8s\n", "", "", "ms", "ms", "ms", "ms", "ms",
              "ms", "ms");
  const int sizes[][2] = {{640, 480}, {320, 240}};
  for (const auto& s : sizes)
    for (int levels : {4, 3}) {
      ImagePipeline pipe(rt, camera(s[0], s[1]), levels, opt);
      std::vector<cv::Mat> input;
      for (unsigned k = 0; k < 8; ++k) input.push_back(frame(s[0], s[1], 17 + k));
      Pyramid out;
      for (int k = 0; k < 10; ++k) pipe.process(input[static_cast<size_t>(k) % 8], out);  // warm up
      rt.queue().finish();
      std::vector<double> up, und, pyr, grad, sum, whole, ref;
      for (int k = 0; k < frames; ++k) {
        const PipelineTimings t = pipe.process_timed(input[static_cast<size_t>(k) % 8], out);
        up.push_back(t.upload_ms);
        und.push_back(t.undistort_ms);
        pyr.push_back(t.pyramid_ms);
        grad.push_back(t.gradient_ms);
        sum.push_back(t.total_ms());
      }
      for (int k = 0; k < frames; ++k) {
        const double t0 = now_ms();
        pipe.process(input[static_cast<size_t>(k) % 8], out);
        rt.queue().finish();
        whole.push_back(now_ms() - t0);
      }
      const int ref_frames = std::max(1, frames / 10);
      for (int k = 0; k < ref_frames; ++k) {
        const double t0 = now_ms();
        const auto levels_ref = pipeline_reference(input[static_cast<size_t>(k) % 8], pipe.map(), levels, opt.prefilter);
        ref.push_back(now_ms() - t0);
      }
      char size[32];
      std::snprintf(size, sizeof size, "%dx%d", s[0], s[1]);
      std::printf("%-9s %6d | %8.3f %9.3f %8.3f %8.3f %8.3f | %8.3f | %8.3f\n", size, levels,
                  median(up), median(und), median(pyr), median(grad), median(sum), median(whole),
                  median(ref));
    }
  std::printf("stage columns: median per stage with the queue drained between stages; sum: median "
              "of their per-frame sums;\npipeline: median of process() + finish() with no stage "
              "boundaries; C++ ref: pipeline_reference, single-threaded.\n");
  rolling_shutter_rows(rt, opt, frames);
  photometric_fit(frames);
  return 0;
}
