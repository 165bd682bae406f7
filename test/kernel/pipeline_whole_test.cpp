// The whole OpenCL image pipeline (ImagePipeline) against the whole reference
// (pipeline_reference), its geometry on a smooth synthetic scene, its errors, its buffer reuse,
// and the host <-> device pyramid helpers.
//
// Tolerance: as in pipeline_kernels_test.cpp, 1e-3 grey levels (and grey levels per pixel) for
// every component of every pixel, validity exact; each stage's rounding differences (an ulp or
// so) pass through convex combinations and halved differences, which do not grow them.
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>
#include <gtest/gtest.h>

#include "common/test_util.h"
#include "core/error.h"
#include "image/pipeline.h"
#include "image/undistort.h"
#include "ocl/runtime.h"

namespace planarvo {
namespace {

constexpr double kTolerance = 1e-3;

CameraModel camera(int w, int h, double k1, double k2) {
  CameraModel c;
  c.width = w;
  c.height = h;
  c.fx = 0.8 * w;
  c.fy = 0.81 * w;
  c.cx = 0.5 * w + 2.3;
  c.cy = 0.5 * h - 1.7;
  c.k1 = k1;
  c.k2 = k2;
  return c;
}

// Random texture with structure at several scales: blurred noise plus fine noise.
cv::Mat random_frame(int w, int h, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat coarse(h, w, CV_8UC1), fine(h, w, CV_8UC1), out;
  rng.fill(coarse, cv::RNG::UNIFORM, 0, 256);
  rng.fill(fine, cv::RNG::UNIFORM, 0, 64);
  cv::GaussianBlur(coarse, coarse, cv::Size(9, 9), 2.5);
  cv::addWeighted(coarse, 0.8, fine, 1.0, 0.0, out);
  return out;
}

struct Comparison {
  size_t validity = 0, off = 0, valid = 0, invalid_nonzero = 0;
  double worst = 0.0;
};

Comparison compare(const cv::Mat& k, const cv::Mat& r) {
  Comparison c;
  for (int y = 0; y < r.rows; ++y)
    for (int x = 0; x < r.cols; ++x) {
      const cv::Vec4f a = k.at<cv::Vec4f>(y, x), b = r.at<cv::Vec4f>(y, x);
      if (a[3] != b[3]) {
        ++c.validity;
      } else if (b[3] == 0.0f) {
        c.invalid_nonzero += a[0] != 0.0f || a[1] != 0.0f || a[2] != 0.0f;
      } else {
        ++c.valid;
        for (int i = 0; i < 3; ++i) {
          const double d = std::abs(static_cast<double>(a[i]) - b[i]);
          c.worst = std::max(c.worst, d);
          if (!(d <= kTolerance)) ++c.off;
        }
      }
    }
  return c;
}

void expect_matches_reference(ocl::Runtime& rt, const CameraModel& cam, int levels,
                              const ImagePipelineOptions& options = {}) {
  const std::string what = std::to_string(cam.width) + "x" + std::to_string(cam.height) + ", " +
                           std::to_string(levels) + " levels";
  ImagePipeline pipe(rt, cam, levels, options);
  // Poisoned output: every element must be written.
  std::vector<cv::Mat> poison;
  for (int l = 0; l < levels; ++l)
    poison.emplace_back(level_size(cam.height, l), level_size(cam.width, l), CV_32FC4,
                        cv::Scalar::all(-77777.0));
  Pyramid out = upload_pyramid(rt, poison);
  const std::vector<cl::Buffer> buffers = [&] {
    std::vector<cl::Buffer> b;
    for (auto& l : out.levels) b.push_back(l.data);
    return b;
  }();
  for (uint64_t frame_no = 0; frame_no < 2; ++frame_no) {
    const cv::Mat gray = random_frame(cam.width, cam.height, 1234 + frame_no);
    pipe.process(gray, out);
    const std::vector<cv::Mat> k = download_pyramid(rt, out), r = pipeline_reference(gray, pipe.map(), levels, options.prefilter);
    ASSERT_EQ(k.size(), static_cast<size_t>(levels));
    for (int l = 0; l < levels; ++l) {
      const size_t li = static_cast<size_t>(l);
      ASSERT_EQ(k[li].size(), r[li].size()) << what << " level " << l;
      const Comparison c = compare(k[li], r[li]);
      EXPECT_EQ(c.validity, 0u) << what << " level " << l;
      EXPECT_EQ(c.invalid_nonzero, 0u) << what << " level " << l;
      EXPECT_EQ(c.off, 0u) << what << " level " << l << ": worst " << c.worst;
      if (k[li].total() >= 2000) {
        EXPECT_GT(c.valid, k[li].total() / 2) << what << " level " << l << ": too few valid pixels to test";
      }
      // The pyramid's buffers were the caller's, reused, not reallocated.
      EXPECT_EQ(out.levels[li].data(), buffers[li]()) << what << " level " << l;
    }
  }
}

TEST(ImagePipeline, MatchesReference640x480) {
  ocl::Runtime rt;
  expect_matches_reference(rt, camera(640, 480, -0.12, 0.03), 4);
}

TEST(ImagePipeline, MatchesReferenceAtSizesNotAMultipleOfTheLevels) {
  ocl::Runtime rt;
  expect_matches_reference(rt, camera(643, 479, -0.12, 0.03), 4);
  // Pincushion leaves the corners without a source; odd sizes down to a few pixels.
  expect_matches_reference(rt, camera(101, 37, 0.15, 0.02), 5);
}

// A region of interest: the pipeline still matches its reference, and no pixel of level 0 whose
// source (in the whole image's undistortion map, computed without the region) lies outside the
// region is valid, so nothing outside it reaches the tracker.
TEST(ImagePipeline, NothingOutsideTheRegionOfInterestIsValid) {
  ocl::Runtime rt;
  CameraModel cam = camera(320, 240, -0.12, 0.03);
  const UndistortMap whole = compute_undistort_map(cam);
  cam.roi = PixelRegion{20, 0, 280, 190};
  expect_matches_reference(rt, cam, 3);
  ImagePipeline pipe(rt, cam, 3);
  Pyramid out;
  pipe.process(random_frame(cam.width, cam.height, 99), out);
  const std::vector<cv::Mat> k = download_pyramid(rt, out);
  size_t valid = 0, outside_valid = 0;
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(cam.width) + static_cast<size_t>(u);
      const bool inside = whole.map_x[i] >= 20.0f && whole.map_x[i] <= 299.0f && whole.map_y[i] >= 0.0f &&
                          whole.map_y[i] <= 189.0f;
      const bool is_valid = k[0].at<cv::Vec4f>(v, u)[3] != 0.0f;
      valid += is_valid;
      outside_valid += is_valid && !inside;
    }
  EXPECT_EQ(outside_valid, 0u);
  EXPECT_GT(valid, 250u * 130u);
}

TEST(ImagePipeline, FastRelaxedMathStaysWithinTolerance) {
  ocl::Runtime rt;
  ImagePipelineOptions o;
  o.fast_math = true;
  expect_matches_reference(rt, camera(203, 150, -0.12, 0.03), 3, o);
}

TEST(ImagePipeline, MatchesReferenceWithoutThePrefilter) {
  ocl::Runtime rt;
  ImagePipelineOptions o;
  o.prefilter = false;
  expect_matches_reference(rt, camera(203, 150, -0.12, 0.03), 3, o);
}

// A frame whose rows are further apart than its width (a region of a larger image).
TEST(ImagePipeline, AcceptsAStride) {
  ocl::Runtime rt;
  const CameraModel cam = camera(120, 90, -0.1, 0.0);
  ImagePipeline pipe(rt, cam, 3);
  const cv::Mat big = random_frame(150, 100, 9);
  const cv::Mat roi = big(cv::Rect(7, 5, 120, 90));
  ASSERT_FALSE(roi.isContinuous());
  Pyramid a, b;
  pipe.process(roi, a);
  pipe.process(roi.clone(), b);
  const auto ka = download_pyramid(rt, a), kb = download_pyramid(rt, b);
  for (size_t l = 0; l < 3; ++l) EXPECT_EQ(cv::norm(ka[l], kb[l], cv::NORM_INF), 0.0) << l;
  ASSERT_EQ(a.num_levels(), 3);
  EXPECT_EQ(a.levels[2].width, 30);
  EXPECT_EQ(a.levels[2].height, 23);
}

// The frame, the undistortion and the pyramid agree with the camera model and pyramid.h: render
// the distorted image of a smooth scene f(undistorted pixel); level-l pixel (u, v) must show f
// at level-0 (2^l (u + 0.5) - 0.5, 2^l (v + 0.5) - 0.5), and its gradient f's derivative times
// 2^l, up to the smoothing of the Gaussian.
TEST(ImagePipeline, LevelsSampleTheSceneAtPyramidPixelCentres) {
  ocl::Runtime rt;
  const CameraModel cam = camera(320, 240, -0.12, 0.03);
  const double ku = 1.0 / 37.0, kv = 1.0 / 29.0;
  const auto f = [&](double u, double v) { return 128.0 + 90.0 * std::sin(ku * u + 0.3) * std::cos(kv * v - 0.2); };
  const auto fu = [&](double u, double v) { return 90.0 * ku * std::cos(ku * u + 0.3) * std::cos(kv * v - 0.2); };
  const auto fv = [&](double u, double v) { return -90.0 * kv * std::sin(ku * u + 0.3) * std::sin(kv * v - 0.2); };
  cv::Mat gray(cam.height, cam.width, CV_8UC1);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const Eigen::Vector2d n = cam.unproject(Eigen::Vector2d(x, y));
      const double value = f(cam.fx * n.x() + cam.cx, cam.fy * n.y() + cam.cy);
      gray.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(value);
    }
  ImagePipeline pipe(rt, cam, 4);
  Pyramid out;
  pipe.process(gray, out);
  const std::vector<cv::Mat> k = download_pyramid(rt, out);
  for (int l = 0; l < 4; ++l) {
    const double s = 1 << l;
    // Errors: 8-bit rounding (0.5), bilinear interpolation of the distorted image (curvature
    // 90 / 29^2 over ~1.1 distorted pixels: ~0.02 x 1.3), and the Gaussian's smoothing: each step
    // adds a variance of 5/4 level pixels, 1.25 (1 + 4 + 16) = 26 level-0 pixels^2 at level 3,
    // which damps f's waves by 1 - exp(-26 (ku^2 + kv^2) / 2) <= 2.5 %: 2.3 grey levels at
    // level 3. A quarter-pixel shift at level 3 (2 level-0 pixels) would err by up to
    // 90 x 2 x 0.034 = 6 grey levels. Slopes (per level pixel, amplitude 90 x 2^l k) are damped
    // alike, and the central difference underestimates them by 1 - sin(2^l k) / (2^l k).
    // Pixels within 3 of the border are left out: clamped taps bend the scene there.
    const double damping = 1.0 - std::exp(-1.25 * (std::pow(4.0, l) - 1) / 3.0 * (ku * ku + kv * kv) / 2.0);
    const double kmax = s * std::max(ku, kv);
    const double value_tol = 0.6 + 90.0 * damping;
    const double slope_tol = 0.6 + 90.0 * kmax * (damping + 1.0 - std::sin(kmax) / kmax);
    double worst_value = 0, worst_slope = 0;
    int checked = 0;
    const cv::Mat& m = k[static_cast<size_t>(l)];
    for (int v = 3; v < m.rows - 3; ++v)
      for (int u = 3; u < m.cols - 3; ++u) {
        const cv::Vec4f p = m.at<cv::Vec4f>(v, u);
        if (p[3] == 0.0f) continue;
        const double u0 = s * (u + 0.5) - 0.5, v0 = s * (v + 0.5) - 0.5;
        worst_value = std::max(worst_value, std::abs(p[0] - f(u0, v0)));
        worst_slope = std::max({worst_slope, std::abs(p[1] - s * fu(u0, v0)),
                                std::abs(p[2] - s * fv(u0, v0))});
        ++checked;
      }
    RecordProperty("worst_value_" + std::to_string(l), std::to_string(worst_value) + " < " + std::to_string(value_tol));
    RecordProperty("worst_slope_" + std::to_string(l), std::to_string(worst_slope) + " < " + std::to_string(slope_tol));
    EXPECT_GT(checked, (m.rows - 6) * (m.cols - 6) * 9 / 10) << "level " << l;
    EXPECT_LT(worst_value, value_tol) << "level " << l;
    EXPECT_LT(worst_slope, slope_tol) << "level " << l;
  }
}

TEST(ImagePipeline, LinearRampGradientsAreExact) {
  ocl::Runtime rt;
  CameraModel cam = camera(96, 64, 0.0, 0.0);
  cam.cx = 47.5;  // no distortion: the map is the identity, to the float rounding of integers
  cam.cy = 31.5;
  cv::Mat gray(64, 96, CV_8UC1);
  for (int v = 0; v < 64; ++v)
    for (int u = 0; u < 96; ++u) gray.at<uint8_t>(v, u) = static_cast<uint8_t>(u + 2 * v + 5);
  ImagePipeline pipe(rt, cam, 3);
  Pyramid out;
  pipe.process(gray, out);
  const std::vector<cv::Mat> k = download_pyramid(rt, out);
  for (int l = 0; l < 3; ++l) {
    const cv::Mat& m = k[static_cast<size_t>(l)];
    const float s = static_cast<float>(1 << l);
    const int margin = l == 0 ? 2 : 3;  // clamped taps (prefilter, pyramid) bend the ramp near the borders
    for (int v = margin; v < m.rows - margin; ++v)
      for (int u = margin; u < m.cols - margin; ++u) {
        const cv::Vec4f p = m.at<cv::Vec4f>(v, u);
        ASSERT_EQ(p[3], 1.0f) << l << ": " << u << "," << v;
        ASSERT_EQ(p[1], s) << l << ": " << u << "," << v;
        ASSERT_EQ(p[2], 2.0f * s) << l << ": " << u << "," << v;
        ASSERT_EQ(p[0], s * (u + 0.5f) - 0.5f + 2.0f * (s * (v + 0.5f) - 0.5f) + 5.0f);
      }
  }
}

TEST(ImagePipeline, AWrongFrameIsAnErrorNotACrash) {
  ocl::Runtime rt;
  ImagePipeline pipe(rt, camera(64, 48, -0.1, 0.0), 2);
  Pyramid out;
  try {
    pipe.process(cv::Mat(48, 63, CV_8UC1, cv::Scalar(0)), out);
    FAIL() << "no error for a frame of the wrong size";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    const std::string msg = e.what();
    EXPECT_NE(msg.find("63x48"), std::string::npos) << msg;
    EXPECT_NE(msg.find("64x48"), std::string::npos) << msg;
  }
  const auto code = [&](const auto& call) {
    try {
      call();
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode::Internal;
  };
  std::vector<uint8_t> bytes(64 * 48);
  EXPECT_EQ(code([&] { pipe.process(nullptr, 64, 48, 64, out); }), ErrorCode::InvalidArgument);
  EXPECT_EQ(code([&] { pipe.process(bytes.data(), 64, 48, 63, out); }), ErrorCode::InvalidArgument);
  EXPECT_EQ(code([&] { pipe.process(bytes.data(), 64, 49, 64, out); }), ErrorCode::InvalidArgument);
  EXPECT_EQ(code([&] { pipe.process(cv::Mat(48, 64, CV_8UC3), out); }), ErrorCode::InvalidArgument);
  EXPECT_EQ(code([&] { pipe.process(cv::Mat(), out); }), ErrorCode::InvalidArgument);
  // The pipeline still works afterwards.
  pipe.process(bytes.data(), 64, 48, 64, out);
  EXPECT_EQ(out.num_levels(), 2);
  EXPECT_EQ(code([&] { ImagePipeline(rt, camera(64, 48, 0, 0), 0); }), ErrorCode::InvalidArgument);
  CameraModel bad = camera(64, 48, 0, 0);
  bad.fx = -1;
  EXPECT_EQ(code([&] { ImagePipeline(rt, bad, 2); }), ErrorCode::InvalidArgument);
}

TEST(ImagePipeline, PyramidUploadDownloadRoundTrip) {
  ocl::Runtime rt;
  std::vector<cv::Mat> levels;
  cv::RNG rng(3);
  for (int l = 0; l < 3; ++l) {
    cv::Mat m(level_size(45, l), level_size(31, l), CV_32FC4);
    rng.fill(m, cv::RNG::UNIFORM, -100.0, 100.0);
    levels.push_back(m);
  }
  const Pyramid p = upload_pyramid(rt, levels);
  ASSERT_EQ(p.num_levels(), 3);
  EXPECT_EQ(p.levels[1].width, 16);
  EXPECT_EQ(p.levels[1].height, 23);
  const std::vector<cv::Mat> back = download_pyramid(rt, p);
  for (size_t l = 0; l < 3; ++l) EXPECT_EQ(cv::norm(levels[l], back[l], cv::NORM_INF), 0.0);

  // Levels that do not halve, or of the wrong type, are refused.
  std::vector<cv::Mat> bad = levels;
  bad[2] = cv::Mat(5, 5, CV_32FC4);
  EXPECT_THROW(upload_pyramid(rt, bad), Error);
  bad = levels;
  bad[1] = cv::Mat(23, 16, CV_32FC1);
  EXPECT_THROW(upload_pyramid(rt, bad), Error);
  EXPECT_THROW(upload_pyramid(rt, {}), Error);
}

// The option sets the pipeline registers are the ones it uses: with only the exported binaries
// (as on an FPGA), a default pipeline runs without compiling and gives the same pyramid.
TEST(ImagePipeline, RunsFromExportedBinaries) {
  test::ScratchDir dir;
  const CameraModel cam = camera(96, 72, -0.12, 0.03);
  const cv::Mat gray = random_frame(96, 72, 4);
  std::vector<cv::Mat> compiled;
  {
    ocl::Runtime rt;
    ImagePipeline pipe(rt, cam, 3);
    Pyramid out;
    pipe.process(gray, out);
    compiled = download_pyramid(rt, out);
    rt.export_binaries(dir.path().string());
  }
  ocl::RuntimeOptions o;
  o.binaries_dir = dir.path().string();
  ocl::Runtime rt(o);
  ImagePipeline pipe(rt, cam, 3);
  Pyramid out;
  pipe.process(gray, out);
  const std::vector<cv::Mat> loaded = download_pyramid(rt, out);
  EXPECT_EQ(rt.stats().built_from_source, 0);
  EXPECT_EQ(rt.stats().loaded_from_binaries, 2);
  for (size_t l = 0; l < 3; ++l) EXPECT_EQ(cv::norm(compiled[l], loaded[l], cv::NORM_INF), 0.0) << l;
}

}  // namespace
}  // namespace planarvo
