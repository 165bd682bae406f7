// Each kernel of the image pipeline (kernels/image/undistort.cl, kernels/image/pyramid.cl) against its plain
// C++ reference (src/image/pipeline_reference.cpp), on random input with invalid regions, through
// PipelineKernels (the launch code ImagePipeline uses), with the output buffers poisoned and
// longer than the image so that an unwritten element or a write past the end shows.
//
// Tolerances: the kernels perform the references' float operations in the same order; an
// OpenCL compiler may still contract a * b + c into a fused multiply-add (the OpenCL C default),
// which changes a result by at most an ulp or so of the largest intermediate: 2^-16 grey levels
// for a bilinear sample (values < 256), 2^-5 / 1024 for a pyramid sum (< 1024 x 256, then
// / 1024). kTolerance, 1e-3 grey levels (4e-6 of 255), bounds that with a wide margin, while a
// wrong tap or weight errs by tenths of grey levels on random input. Validity comes from the map
// and from which taps are valid, never from a rounded value, so it must agree exactly: every
// element is checked, all four components of a float4, with no exclusions.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <opencv2/imgproc.hpp>
#include <gtest/gtest.h>

#include "image/pipeline.h"
#include "image/rolling_shutter.h"
#include "ocl/runtime.h"

namespace planarvo {
namespace {

constexpr float kPoison = -77777.0f;  // neither an intensity nor kInvalidIntensity
constexpr double kTolerance = 1e-3;
constexpr size_t kSlack = 64;  // poisoned elements after the image

// Random intensities 0..255 with invalid blobs and isolated invalid pixels.
cv::Mat random_level(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(0.0f, 255.0f);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  cv::Mat m(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      m.at<float>(y, x) = unit(rng) < 0.005 ? kInvalidIntensity : value(rng);
  const int blobs = 1 + (w * h) / 5000;
  for (int b = 0; b < blobs; ++b) {
    const cv::Point c(static_cast<int>(unit(rng) * w), static_cast<int>(unit(rng) * h));
    cv::circle(m, c, 1 + static_cast<int>(unit(rng) * 8), cv::Scalar(kInvalidIntensity), cv::FILLED);
  }
  return m;
}

CameraModel distorted_camera(int w, int h, double k1, double k2) {
  CameraModel c;
  c.width = w;
  c.height = h;
  c.fx = 0.78 * w;
  c.fy = 0.8 * w;
  c.cx = 0.5 * w - 1.3;
  c.cy = 0.5 * h + 2.1;
  c.k1 = k1;
  c.k2 = k2;
  c.p1 = 0.001;
  c.p2 = -0.0007;
  return c;
}

// A device buffer holding `values`, or n poisoned floats plus kSlack.
cl::Buffer upload(ocl::Runtime& rt, const void* data, size_t bytes) {
  return cl::Buffer(rt.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, bytes,
                    const_cast<void*>(data));
}
cl::Buffer poisoned(ocl::Runtime& rt, size_t floats) {
  std::vector<float> p(floats + kSlack, kPoison);
  return upload(rt, p.data(), p.size() * sizeof(float));
}
std::vector<float> download(ocl::Runtime& rt, const cl::Buffer& b, size_t floats) {
  std::vector<float> out(floats + kSlack);
  rt.queue().enqueueReadBuffer(b, CL_TRUE, 0, out.size() * sizeof(float), out.data());
  return out;
}

// Compares a kernel's intensity image (with its slack) with the reference's.
void expect_intensity_matches(const std::vector<float>& k, const cv::Mat& ref, const std::string& what) {
  const size_t n = ref.total();
  size_t unwritten = 0, validity = 0, off = 0, invalid = 0;
  double worst = 0.0;
  for (int y = 0; y < ref.rows; ++y)
    for (int x = 0; x < ref.cols; ++x) {
      const float r = ref.at<float>(y, x), v = k[static_cast<size_t>(y) * ref.cols + x];
      if (v == kPoison) {
        ++unwritten;
      } else if ((r == kInvalidIntensity) != (v == kInvalidIntensity)) {
        ++validity;
      } else if (r == kInvalidIntensity) {
        ++invalid;
      } else {
        const double d = std::abs(static_cast<double>(v) - r);
        worst = std::max(worst, d);
        if (!(d <= kTolerance)) ++off;
      }
    }
  size_t overrun = 0;
  for (size_t i = n; i < k.size(); ++i) overrun += k[i] != kPoison;
  EXPECT_EQ(unwritten, 0u) << what;
  EXPECT_EQ(validity, 0u) << what;
  EXPECT_EQ(off, 0u) << what << ": worst difference " << worst;
  EXPECT_EQ(overrun, 0u) << what << ": written past the image";
  ::testing::Test::RecordProperty("worst_" + what, std::to_string(worst));
}

const int kSizes[][2] = {{1, 1}, {3, 2}, {7, 5}, {8, 3}, {9, 4}, {17, 9}, {33, 19},
                         {97, 61}, {160, 120}, {643, 479}};

TEST(PipelineKernels, UndistortMatchesReference) {
  ocl::Runtime rt;
  PipelineKernels kernels(rt);
  // Barrel, pincushion (corners without a source) and none; sizes that are not multiples of 8.
  const double dist[][2] = {{-0.12, 0.03}, {0.2, 0.05}, {0.0, 0.0}};
  const int sizes[][2] = {{643, 479}, {97, 61}, {20, 13}};
  uint32_t seed = 11;
  for (const auto& s : sizes)
    for (const auto& d : dist) {
      const std::string what = std::to_string(s[0]) + "x" + std::to_string(s[1]) + " k1=" +
                               std::to_string(d[0]);
      const CameraModel cam = distorted_camera(s[0], s[1], d[0], d[1]);
      const UndistortMap map = compute_undistort_map(cam);
      cv::Mat gray(s[1], s[0], CV_8UC1);
      cv::RNG(seed++).fill(gray, cv::RNG::UNIFORM, 0, 256);
      const size_t n = gray.total();
      const PipelineKernels::DeviceMap dm = PipelineKernels::device_map(map);
      ASSERT_EQ(dm.index.size(), n + 8);
      ASSERT_EQ(dm.weights.size(), 2 * (n + 8));
      // The frame buffer's bytes after the frame are random too: they must not matter.
      cv::Mat bytes(1, static_cast<int>(PipelineKernels::frame_buffer_size(s[0], s[1])), CV_8UC1);
      cv::RNG(seed++).fill(bytes, cv::RNG::UNIFORM, 0, 256);
      std::copy(gray.datastart, gray.dataend, bytes.data);
      const cl::Buffer frame = upload(rt, bytes.data, bytes.total()),
                       index = upload(rt, dm.index.data(), dm.index.size() * sizeof(cl_int)),
                       weights = upload(rt, dm.weights.data(), dm.weights.size() * sizeof(float));
      const cl::Buffer dst = poisoned(rt, n);
      kernels.undistort(frame, index, weights, s[0], s[1], dst);
      const cv::Mat ref = undistort_reference(gray, map);
      expect_intensity_matches(download(rt, dst, n), ref, what);
      if (d[0] > 0) {
        EXPECT_LT(map.valid_count(), n) << what << ": the test wants pixels without a source";
      }
    }
}

// The rolling-shutter undistortion against undistort_rolling_reference: the same float
// operations (the grid's interpolation, the map's coordinate plus it, the bilinear sample), so a
// contracted multiply-add moves a coordinate by an ulp or so (1e-5 px at 600 px): on a smooth
// random image (up to about 20 grey levels per pixel) tolerance 0.01 grey levels, and at most 1
// in 10^4 pixels of another validity (a coordinate within an ulp of the region's edge); a wrong
// node, tap or weight errs by grey levels. With the identity warp it is undistort_reference
// exactly (the coordinates of the plain undistortion).
TEST(PipelineKernels, UndistortRollingMatchesReference) {
  ocl::Runtime rt;
  PipelineKernels kernels(rt);
  const double dist[][2] = {{-0.12, 0.03}, {0.2, 0.05}, {0.0, 0.0}};
  const int sizes[][2] = {{643, 479}, {97, 61}, {20, 13}, {1, 1}};
  Extrinsics e;
  e.z = 0.3;
  e.pitch = 0.2;
  e.roll = -0.05;
  uint32_t seed = 71;
  for (const auto& s : sizes)
    for (const auto& d : dist)
      for (int moving = 0; moving < 2; ++moving) {
        const std::string what = std::to_string(s[0]) + "x" + std::to_string(s[1]) + " k1=" + std::to_string(d[0]) +
                                 (moving ? " moving" : " at rest");
        CameraModel cam = distorted_camera(s[0], s[1], d[0], d[1]);
        cam.rolling_shutter_readout = 0.03;
        const UndistortMap map = compute_undistort_map(cam);
        // Fast enough to shift the last row by tens of pixels at 643 px.
        const RowWarp warp = rolling_shutter_warp(cam, e, moving ? Eigen::Vector3d(1.5, -0.3, 1.2) : Eigen::Vector3d::Zero());
        if (s[0] > 1) {
          ASSERT_EQ(warp.identity(), !moving) << what;
        }
        // Smooth random texture, so that a sample's difference measures its coordinate's.
        cv::Mat noise(s[1], s[0], CV_32FC1), gray;
        cv::RNG(seed++).fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
        cv::GaussianBlur(noise, noise, cv::Size(0, 0), 2.0);
        cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
        noise.convertTo(gray, CV_8UC1);
        const size_t n = gray.total();
        cv::Mat bytes(1, static_cast<int>(PipelineKernels::frame_buffer_size(s[0], s[1])), CV_8UC1);
        cv::RNG(seed++).fill(bytes, cv::RNG::UNIFORM, 0, 256);
        std::copy(gray.datastart, gray.dataend, bytes.data);
        std::vector<float> xy(2 * (n + 8), -1e6f);
        for (size_t i = 0; i < n; ++i) {
          xy[2 * i] = map.map_x[i];
          xy[2 * i + 1] = map.map_y[i];
        }
        const PixelRegion r = cam.region();
        const cl_float4 roi = {{static_cast<float>(r.x), static_cast<float>(r.y), static_cast<float>(r.x + r.width - 1),
                                static_cast<float>(r.y + r.height - 1)}};
        const cl::Buffer frame = upload(rt, bytes.data, bytes.total()),
                         mapb = upload(rt, xy.data(), xy.size() * sizeof(float)),
                         grid = upload(rt, warp.delta.data(), warp.delta.size() * sizeof(float));
        const cl::Buffer dst = poisoned(rt, n);
        kernels.undistort_rolling(frame, mapb, grid, warp, roi, dst);
        const std::vector<float> k = download(rt, dst, n);
        const cv::Mat ref = undistort_rolling_reference(gray, cam, map, warp);
        if (!moving) {
          // At rest: the plain undistortion, exactly (reference and kernel).
          EXPECT_EQ(cv::norm(ref, undistort_reference(gray, map), cv::NORM_INF), 0.0) << what;
          expect_intensity_matches(k, ref, what);
          continue;
        }
        size_t unwritten = 0, validity = 0, off = 0, valid = 0, overrun = 0;
        double worst = 0.0;
        for (size_t i = 0; i < n; ++i) {
          const float want = ref.at<float>(static_cast<int>(i / s[0]), static_cast<int>(i % s[0])), got = k[i];
          if (got == kPoison) ++unwritten;
          else if ((want == kInvalidIntensity) != (got == kInvalidIntensity)) ++validity;
          else if (want != kInvalidIntensity) {
            ++valid;
            worst = std::max(worst, std::abs(static_cast<double>(got) - want));
            off += !(std::abs(static_cast<double>(got) - want) <= 0.01);
          }
        }
        for (size_t i = n; i < k.size(); ++i) overrun += k[i] != kPoison;
        EXPECT_EQ(unwritten, 0u) << what;
        EXPECT_EQ(overrun, 0u) << what;
        EXPECT_LE(validity, n / 10000) << what;
        EXPECT_EQ(off, 0u) << what << ": worst difference " << worst;
        if (n > 100) {
          EXPECT_GT(valid, n / 3) << what;
        }
      }
}

TEST(PipelineKernels, DownsampleMatchesReference) {
  ocl::Runtime rt;
  PipelineKernels kernels(rt);
  uint32_t seed = 100;
  for (const auto& s : kSizes) {
    const std::string what = std::to_string(s[0]) + "x" + std::to_string(s[1]);
    const cv::Mat level = random_level(s[0], s[1], seed++);
    const cl::Buffer src = upload(rt, level.ptr(), level.total() * sizeof(float));
    const int dw = level_size(s[0], 1), dh = level_size(s[1], 1);
    const size_t n = static_cast<size_t>(dw) * static_cast<size_t>(dh);
    const cl::Buffer dst = poisoned(rt, n);
    kernels.downsample(src, s[0], s[1], dst);
    expect_intensity_matches(download(rt, dst, n), downsample_reference(level), what);
  }
}

TEST(PipelineKernels, SmoothMatchesReference) {
  ocl::Runtime rt;
  PipelineKernels kernels(rt);
  uint32_t seed = 150;
  for (const auto& s : kSizes) {
    const std::string what = std::to_string(s[0]) + "x" + std::to_string(s[1]);
    const cv::Mat level = random_level(s[0], s[1], seed++);
    const cl::Buffer src = upload(rt, level.ptr(), level.total() * sizeof(float));
    const size_t n = level.total();
    const cl::Buffer dst = poisoned(rt, n);
    kernels.smooth(src, s[0], s[1], dst);
    expect_intensity_matches(download(rt, dst, n), smooth_reference(level), what);
  }
}

TEST(PipelineKernels, GradientMatchesReference) {
  ocl::Runtime rt;
  PipelineKernels kernels(rt);
  uint32_t seed = 200;
  for (const auto& s : kSizes) {
    const std::string what = std::to_string(s[0]) + "x" + std::to_string(s[1]);
    const cv::Mat level = random_level(s[0], s[1], seed++);
    const cl::Buffer src = upload(rt, level.ptr(), level.total() * sizeof(float));
    const size_t n = level.total();
    const cl::Buffer dst = poisoned(rt, 4 * n);
    kernels.gradient(src, s[0], s[1], dst);
    const std::vector<float> k = download(rt, dst, 4 * n);
    const cv::Mat ref = gradient_reference(level);
    size_t unwritten = 0, validity = 0, off = 0, valid = 0, overrun = 0;
    double worst = 0.0;
    for (int y = 0; y < ref.rows; ++y)
      for (int x = 0; x < ref.cols; ++x) {
        const cv::Vec4f r = ref.at<cv::Vec4f>(y, x);
        const float* p = &k[4 * (static_cast<size_t>(y) * ref.cols + x)];
        for (int c = 0; c < 4; ++c) unwritten += p[c] == kPoison;
        if (p[3] != r[3]) {
          ++validity;
          continue;
        }
        if (r[3] == 0.0f) {
          // Invalid: all four components exactly 0.
          off += p[0] != 0.0f || p[1] != 0.0f || p[2] != 0.0f;
          continue;
        }
        ++valid;
        for (int c = 0; c < 3; ++c) {
          const double d = std::abs(static_cast<double>(p[c]) - r[c]);
          worst = std::max(worst, d);
          if (!(d <= kTolerance)) ++off;
        }
      }
    for (size_t i = 4 * n; i < k.size(); ++i) overrun += k[i] != kPoison;
    EXPECT_EQ(unwritten, 0u) << what;
    EXPECT_EQ(validity, 0u) << what;
    EXPECT_EQ(off, 0u) << what << ": worst difference " << worst;
    EXPECT_EQ(overrun, 0u) << what << ": written past the image";
    if (s[0] >= 33 && s[1] >= 19) {
      EXPECT_GT(valid, n / 2) << what << ": the test wants mostly valid pixels";
    }
  }
}

// Other work-group shapes (build options) launch with the shape they were built with and give
// the same results.
TEST(PipelineKernels, OtherWorkGroupShapesAgree) {
  ocl::Runtime rt;
  ImagePipelineOptions o;
  o.undistort_wg_x = 32;
  o.undistort_wg_y = 1;
  o.pyramid_wg_x = 4;
  o.pyramid_wg_y = 8;
  PipelineKernels kernels(rt, o);
  PipelineKernels defaults(rt);
  const cv::Mat level = random_level(161, 77, 5);
  const cl::Buffer src = upload(rt, level.ptr(), level.total() * sizeof(float));
  const int dw = level_size(161, 1), dh = level_size(77, 1);
  const size_t nd = static_cast<size_t>(dw) * static_cast<size_t>(dh);
  const cl::Buffer a = poisoned(rt, nd), b = poisoned(rt, nd);
  kernels.downsample(src, 161, 77, a);
  defaults.downsample(src, 161, 77, b);
  EXPECT_EQ(download(rt, a, nd), download(rt, b, nd));
  const cl::Buffer ga = poisoned(rt, 4 * level.total()), gb = poisoned(rt, 4 * level.total());
  kernels.gradient(src, 161, 77, ga);
  defaults.gradient(src, 161, 77, gb);
  EXPECT_EQ(download(rt, ga, 4 * level.total()), download(rt, gb, 4 * level.total()));

  const CameraModel cam = distorted_camera(161, 77, -0.12, 0.03);
  const UndistortMap map = compute_undistort_map(cam);
  cv::Mat gray(77, 161, CV_8UC1);
  cv::randu(gray, 0, 256);
  const PipelineKernels::DeviceMap dm = PipelineKernels::device_map(map);
  std::vector<uint8_t> bytes(PipelineKernels::frame_buffer_size(161, 77), 0);
  std::copy(gray.datastart, gray.dataend, bytes.begin());
  const cl::Buffer frame = upload(rt, bytes.data(), bytes.size()),
                   index = upload(rt, dm.index.data(), dm.index.size() * sizeof(cl_int)),
                   weights = upload(rt, dm.weights.data(), dm.weights.size() * sizeof(float));
  const cl::Buffer ua = poisoned(rt, gray.total()), ub = poisoned(rt, gray.total());
  kernels.undistort(frame, index, weights, 161, 77, ua);
  defaults.undistort(frame, index, weights, 161, 77, ub);
  EXPECT_EQ(download(rt, ua, gray.total()), download(rt, ub, gray.total()));
}


// The photometric correction against photometric_reference, and the statistics' update against
// photometric_learn_reference, on random raw intensities with invalid pixels and saturated
// values, a random model with pixels that have no value (scale 0), and random running
// statistics.
TEST(PipelineKernels, PhotometricMatchesReference) {
  ocl::Runtime rt;
  PipelineKernels kernels(rt);
  uint32_t seed = 31;
  for (const auto& s : kSizes) {
    for (const float alpha : {1.0f, 0.25f, 1.0f / 300.0f}) {
      const std::string what = std::to_string(s[0]) + "x" + std::to_string(s[1]) + " alpha=" + std::to_string(alpha);
      const cv::Mat raw = random_level(s[0], s[1], seed++);
      std::mt19937 rng(seed++);
      std::uniform_real_distribution<float> unit(0.0f, 1.0f);
      PhotometricFit fit = identity_photometric(s[0], s[1]);
      cv::Mat mean(s[1], s[0], CV_32FC1), var(s[1], s[0], CV_32FC1);
      for (int y = 0; y < s[1]; ++y)
        for (int x = 0; x < s[0]; ++x) {
          fit.scale.at<float>(y, x) = unit(rng) < 0.05f ? 0.0f : 0.3f + 3.0f * unit(rng);
          fit.offset.at<float>(y, x) = -100.0f + 200.0f * unit(rng);
          mean.at<float>(y, x) = 255.0f * unit(rng);
          var.at<float>(y, x) = 2000.0f * unit(rng);
        }
      const size_t n = raw.total();
      std::vector<float> model(2 * n), stats(2 * n);
      std::copy_n(fit.scale.ptr<float>(), n, model.begin());
      std::copy_n(fit.offset.ptr<float>(), n, model.begin() + static_cast<std::ptrdiff_t>(n));
      std::copy_n(mean.ptr<float>(), n, stats.begin());
      std::copy_n(var.ptr<float>(), n, stats.begin() + static_cast<std::ptrdiff_t>(n));
      const cl::Buffer src = upload(rt, raw.ptr(), n * sizeof(float));
      const cl::Buffer m = upload(rt, model.data(), model.size() * sizeof(float));
      const cl::Buffer st = upload(rt, stats.data(), stats.size() * sizeof(float));
      const cl::Buffer dst = poisoned(rt, n);
      kernels.photometric(src, m, 200.0f, s[0], s[1], dst);
      kernels.photometric_learn(src, st, alpha, s[0], s[1]);
      expect_intensity_matches(download(rt, dst, n), photometric_reference(raw, fit, 200.0), what);
      cv::Mat ref_mean = mean.clone(), ref_var = var.clone();
      photometric_learn_reference(raw, alpha, &ref_mean, &ref_var);
      std::vector<float> out(2 * n);
      rt.queue().enqueueReadBuffer(st, CL_TRUE, 0, out.size() * sizeof(float), out.data());
      double worst_mean = 0.0, worst_var = 0.0;
      size_t changed = 0, valid = 0;
      for (size_t i = 0; i < n; ++i) {
        valid += raw.ptr<float>()[i] > 0.5f * kInvalidIntensity;
        worst_mean = std::max(worst_mean, std::abs(static_cast<double>(out[i]) - ref_mean.ptr<float>()[i]));
        worst_var = std::max(worst_var, std::abs(static_cast<double>(out[n + i]) - ref_var.ptr<float>()[i]));
        changed += out[i] != mean.ptr<float>()[i];
      }
      EXPECT_LE(worst_mean, kTolerance) << what;
      // Mean squares reach 255^2: a contracted multiply-add differs by an ulp or two of that (2^-7).
      EXPECT_LE(worst_var, 0.02) << what;
      EXPECT_GE(changed, valid * 9 / 10) << what;  // the statistics were updated at all
    }
  }
}

// The rolling-shutter frame's photometric correction against photometric_rolling_reference: a
// random model (5 % of its pixels without a value) read through the light field of a real row
// warp (tens of pixels at the last rows), and the identity warp, which must be photometric's.
TEST(PipelineKernels, PhotometricRollingMatchesReference) {
  ocl::Runtime rt;
  PipelineKernels kernels(rt);
  Extrinsics e;
  e.z = 0.3;
  e.pitch = 0.2;
  e.roll = -0.05;
  uint32_t seed = 53;
  const int sizes[][2] = {{643, 479}, {97, 61}, {20, 13}};
  for (const auto& s : sizes)
    for (int moving = 0; moving < 2; ++moving) {
      const std::string what = std::to_string(s[0]) + "x" + std::to_string(s[1]) + (moving ? " moving" : " at rest");
      CameraModel cam = distorted_camera(s[0], s[1], -0.12, 0.03);
      cam.rolling_shutter_readout = 0.03;
      const RowWarp warp = rolling_shutter_warp(cam, e, moving ? Eigen::Vector3d(1.5, -0.3, 1.2) : Eigen::Vector3d::Zero());
      double largest = 0.0;
      for (const float l : warp.light) largest = std::max(largest, std::abs(static_cast<double>(l)));
      if (moving) {
        EXPECT_GT(largest, 0.02 * s[1]) << what << ": the test wants the light to move";
      } else {
        EXPECT_EQ(largest, 0.0) << what;
      }
      const cv::Mat raw = random_level(s[0], s[1], seed++);
      std::mt19937 rng(seed++);
      std::uniform_real_distribution<float> unit(0.0f, 1.0f);
      PhotometricFit fit = identity_photometric(s[0], s[1]);
      for (int y = 0; y < s[1]; ++y)
        for (int x = 0; x < s[0]; ++x) {
          fit.scale.at<float>(y, x) = unit(rng) < 0.05f ? 0.0f : 0.3f + 3.0f * unit(rng);
          fit.offset.at<float>(y, x) = -100.0f + 200.0f * unit(rng);
        }
      const size_t n = raw.total();
      std::vector<float> model(2 * n), grid(warp.delta);
      std::copy_n(fit.scale.ptr<float>(), n, model.begin());
      std::copy_n(fit.offset.ptr<float>(), n, model.begin() + static_cast<std::ptrdiff_t>(n));
      grid.insert(grid.end(), warp.light.begin(), warp.light.end());
      const cl::Buffer src = upload(rt, raw.ptr(), n * sizeof(float));
      const cl::Buffer m = upload(rt, model.data(), model.size() * sizeof(float));
      const cl::Buffer g = upload(rt, grid.data(), grid.size() * sizeof(float));
      const cl::Buffer dst = poisoned(rt, n);
      kernels.photometric_rolling(src, m, g, warp, 200.0f, dst);
      const std::vector<float> k = download(rt, dst, n);
      const cv::Mat ref = photometric_rolling_reference(raw, fit, warp, 200.0);
      if (!moving) {
        // At rest the model is read at each pixel itself: photometric's correction exactly.
        EXPECT_EQ(cv::norm(ref, photometric_reference(raw, fit, 200.0), cv::NORM_INF), 0.0) << what;
        expect_intensity_matches(k, ref, what);
        continue;
      }
      // The light field's interpolation may round differently (contracted multiply-adds): the
      // model's coordinate by an ulp (6e-5 px near 640), which moves a rare coordinate across
      // the middle between two pixels, and this random model differs between neighbours.
      size_t unwritten = 0, validity = 0, off = 0, valid = 0, overrun = 0;
      double worst = 0.0;
      for (size_t i = 0; i < n; ++i) {
        const float want = ref.ptr<float>()[i], got = k[i];
        if (got == kPoison) ++unwritten;
        else if ((want == kInvalidIntensity) != (got == kInvalidIntensity)) ++validity;
        else if (want != kInvalidIntensity) {
          ++valid;
          worst = std::max(worst, std::abs(static_cast<double>(got) - want));
          off += !(std::abs(static_cast<double>(got) - want) <= kTolerance);
        }
      }
      for (size_t i = n; i < k.size(); ++i) overrun += k[i] != kPoison;
      EXPECT_EQ(unwritten, 0u) << what;
      EXPECT_EQ(overrun, 0u) << what;
      EXPECT_LE(validity, n / 10000) << what;
      EXPECT_LE(off, n / 10000) << what << ": worst difference " << worst;
      EXPECT_GT(valid, n / 3) << what;
    }
}

}  // namespace
}  // namespace planarvo
