// The tracker's residual image (track/residual_image.h, Tracker::residuals): the DEBUG_OUTPUT
// pass's per-pixel values against a host computation in double from the downloaded pyramids and
// the image's own warp, brightness and threshold; an occluding blob pasted into the live frame
// is what the robust norm down-weights (compared with where the true motion puts the blob);
// asking for residuals leaves tracking bit-identical; a frame that became the keyframe is still
// compared with the keyframe it was aligned with; the errors.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "core/error.h"
#include "core/extrinsics.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"
#include "track/texture_residual.h"
#include "track/tracker.h"
#include "unit/track_test_pyramid.h"

namespace planarvo::track {
namespace {

// The code of the planarvo::Error that f throws (Internal when it throws none).
template <class F>
ErrorCode error_code(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::Internal;
}

// The blob in the live frame (level-0 pixels, inclusive-exclusive).
constexpr int kBlobX0 = 300, kBlobX1 = 330, kBlobY0 = 260, kBlobY1 = 284;

class ResidualImageTest : public ::testing::Test {
 protected:
  ResidualImageTest() {
    options_.texture = test::texture("asphalt_01.png").string();
    options_.camera = sim::default_camera(640, 480);
    options_.camera.k1 = options_.camera.k2 = 0.0;
    renderer_ = std::make_unique<sim::Renderer>(rt_, cv::imread(options_.texture, cv::IMREAD_GRAYSCALE), options_);
  }

  // 0.3 m/s forwards and 0.6 rad/s: frame k at k / 30 s.
  static SE2 truth(double t) { return SE2::exp(Eigen::Vector3d(0.3 * t, 0.0, 0.6 * t)); }

  std::vector<cv::Mat> host(int k, bool blob) {
    cv::Mat u8 = sim::apply_camera(renderer_->render_float(truth(k / 30.0)), {}, 1.0, 11 + static_cast<uint64_t>(k));
    // A mild occluder (+40 grey levels on 0.2 % of the image), one the alignment keeps its warp
    // through, so that what is tested is the residual image, not the tracker's robustness.
    if (blob) u8(cv::Rect(kBlobX0, kBlobY0, kBlobX1 - kBlobX0, kBlobY1 - kBlobY0)) += cv::Scalar(40);
    return test::test_pyramid(u8, nullptr, 4);
  }

  ocl::Runtime rt_;
  sim::Options options_;
  std::unique_ptr<sim::Renderer> renderer_;
};

// Residual and weight of keyframe pixel (x, y) from host levels (CV_32FC4) in double; false where
// the pair is not valid (the kernel's rule: four valid live neighbours inside the level).
bool host_residual(const cv::Mat& ref, const cv::Mat& live, const ResidualImage& im, int x, int y, double* r,
                   double* w) {
  const cv::Vec4f R = ref.at<cv::Vec4f>(y, x);
  if (R[3] == 0.0f) return false;
  const Eigen::Vector3d q = im.H * Eigen::Vector3d(x, y, 1.0);
  if (!(q.z() > 0)) return false;
  const double u = q.x() / q.z(), v = q.y() / q.z();
  const double bu = std::floor(u), bv = std::floor(v);
  if (bu < 0 || bv < 0 || bu >= live.cols - 1 || bv >= live.rows - 1) return false;
  const int iu = static_cast<int>(bu), iv = static_cast<int>(bv);
  const cv::Vec4f a = live.at<cv::Vec4f>(iv, iu), b = live.at<cv::Vec4f>(iv, iu + 1);
  const cv::Vec4f c = live.at<cv::Vec4f>(iv + 1, iu), d = live.at<cv::Vec4f>(iv + 1, iu + 1);
  if (a[3] == 0 || b[3] == 0 || c[3] == 0 || d[3] == 0) return false;
  const double ax = u - bu, ay = v - bv;
  const double I = (1 - ax) * (1 - ay) * a[0] + ax * (1 - ay) * b[0] + (1 - ax) * ay * c[0] + ax * ay * d[0];
  *r = im.gain * I + im.bias - R[0];
  *w = std::abs(*r) <= im.huber_k ? 1.0 : im.huber_k / std::abs(*r);
  return true;
}

TEST_F(ResidualImageTest, KernelAgreesWithHostAndFindsThePastedBlob) {
  Tracker tracker(rt_, options_.camera, options_.extrinsics);
  const std::vector<cv::Mat> key = host(0, false), live = host(2, true);
  ASSERT_EQ(tracker.track(test::test_upload(rt_, key), 0.0).status, FrameResult::Status::First);
  const Pyramid live_dev = test::test_upload(rt_, live);
  const FrameResult fr = tracker.track(live_dev, 2 / 30.0);
  ASSERT_NE(fr.status, FrameResult::Status::Lost) << fr.reason;
  const Eigen::Matrix3d K0 = options_.camera.K();
  const Eigen::Matrix4d true_motion = (truth(0).inverse() * truth(2 / 30.0)).matrix3d();

  for (int level : {0, 1}) {
    const ResidualImage im = tracker.residuals(level);
    ASSERT_EQ(im.level, level);
    ASSERT_EQ(im.width, key[static_cast<size_t>(level)].cols);
    ASSERT_EQ(im.height, key[static_cast<size_t>(level)].rows);
    EXPECT_EQ(im.tracked_level, 0);  // 640 x 480: level 1, then level 0 at 1/9
    EXPECT_NEAR(im.huber_k / (2.0 * fr.sigma), 1.0, 0.25 + 1e-9);  // k = 2 sigma, sigma within 25 %
    // The image's warp is the true one (the alignment worked) at this level: within 0.3 px.
    const Eigen::Matrix3d Kl = level_camera_matrix(K0, level);
    const Eigen::Matrix3d Ht = ground_homography(Kl, options_.extrinsics, true_motion);
    const cv::Mat& R = key[static_cast<size_t>(level)];
    const cv::Mat& L = live[static_cast<size_t>(level)];
    const double s = std::ldexp(1.0, -level);
    size_t n = 0, mismatched_valid = 0, in_blob = 0, in_blob_out = 0, clear = 0, clear_out = 0, valid = 0;
    double worst_r = 0, worst_w = 0, warp_px = 0;
    std::vector<double> clear_abs;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x, ++n) {
        double r = 0, w = 0;
        const bool ok = host_residual(R, L, im, x, y, &r, &w);
        const bool kv = im.weight[n] > 0;
        if (!kv) {
          ASSERT_EQ(im.residual[n], 0.0f);
        }
        EXPECT_EQ(std::isnan(im.intensity[n]), R.at<cv::Vec4f>(y, x)[3] == 0);
        if (!std::isnan(im.intensity[n])) {
          ASSERT_EQ(im.intensity[n], R.at<cv::Vec4f>(y, x)[0]);
        }
        if (ok != kv) {
          ++mismatched_valid;
          continue;
        }
        if (!ok) continue;
        ++valid;
        worst_r = std::max(worst_r, std::abs(im.residual[n] - r) / (1.0 + std::abs(r)));
        worst_w = std::max(worst_w, std::abs(im.weight[n] - w));
        const Eigen::Vector3d qt = Ht * Eigen::Vector3d(x, y, 1.0), qe = im.H * Eigen::Vector3d(x, y, 1.0);
        warp_px = std::max(warp_px, (qt.hnormalized() - qe.hnormalized()).norm());
        // Where the true motion puts the keyframe pixel in the live frame (level-0 pixels).
        const double u0 = (qt.x() / qt.z() + 0.5) / s - 0.5, v0 = (qt.y() / qt.z() + 0.5) / s - 0.5;
        const double m_in = 2.0 / s, m_out = 4.0 / s;  // blur and bilinear reach, in level-0 pixels
        if (u0 >= kBlobX0 + m_in && u0 <= kBlobX1 - 1 - m_in && v0 >= kBlobY0 + m_in && v0 <= kBlobY1 - 1 - m_in) {
          ++in_blob;
          in_blob_out += im.weight[n] < 1 ? 1 : 0;
        } else if (u0 < kBlobX0 - m_out || u0 > kBlobX1 - 1 + m_out || v0 < kBlobY0 - m_out || v0 > kBlobY1 - 1 + m_out) {
          ++clear;
          clear_out += im.weight[n] < 1 ? 1 : 0;
          clear_abs.push_back(std::abs(im.residual[n]));
        }
      }
    SCOPED_TRACE("level " + std::to_string(level));
    EXPECT_LE(mismatched_valid, 2u + valid / 10000);  // a float rounding from a cell border
    // The kernel warps in float: about 1e-4 px at 640 px, times gradients up to ~40 grey levels/px.
    EXPECT_LT(worst_r, 5e-3);
    EXPECT_LT(worst_w, 1e-3);
    EXPECT_LT(warp_px, 0.3);
    EXPECT_NEAR(im.valid, static_cast<double>(valid), 2.0 + valid / 10000.0);
    // The blob: nearly all of it down-weighted; elsewhere few pixels, and residuals of pixel noise.
    ASSERT_GT(in_blob, level == 0 ? 300u : 50u);  // 30 x 24 px less the blur margins
    EXPECT_GT(static_cast<double>(in_blob_out) / in_blob, 0.97);
    ASSERT_GT(clear, 100000u >> (2 * level));
    EXPECT_LT(static_cast<double>(clear_out) / clear, 0.12);
    std::nth_element(clear_abs.begin(), clear_abs.begin() + clear_abs.size() / 2, clear_abs.end());
    EXPECT_LT(clear_abs[clear_abs.size() / 2], 2.0);
  }
  // The honest-status check's measure, which the tracker reduces on the device
  // (kernels/track/texture_residual.cl), against the host's texture_residual() of the same residual
  // image read back: float sums per pixel against double.
  const int tl = texture_residual_level(options_.camera.width, 4);
  const double host_measure = texture_residual(tracker.residuals(tl));
  ASSERT_TRUE(std::isfinite(host_measure));
  EXPECT_NEAR(fr.texture_residual, host_measure, 1e-4 * host_measure);
}

TEST_F(ResidualImageTest, AskingLeavesTrackingUnchangedAndKeepsTheAlignedKeyframe) {
  TrackerOptions o;
  o.keyframe_overlap = 0.999;  // every tracked frame becomes the keyframe
  Tracker asked(rt_, options_.camera, options_.extrinsics, o), plain(rt_, options_.camera, options_.extrinsics, o);
  EXPECT_EQ(error_code([&] { asked.residuals(0); }), ErrorCode::InvalidArgument);
  std::vector<std::vector<cv::Mat>> frames;
  int key = 0, replaced = 0;
  for (int k = 0; k < 5; ++k) {
    frames.push_back(host(2 * k, k == 3));
    const Pyramid p = test::test_upload(rt_, frames.back());
    const FrameResult a = asked.track(p, 2 * k / 30.0), b = plain.track(p, 2 * k / 30.0);
    EXPECT_EQ(a.motion.value.x, b.motion.value.x);
    EXPECT_EQ(a.motion.value.y, b.motion.value.y);
    EXPECT_EQ(a.motion.value.theta, b.motion.value.theta);
    EXPECT_EQ(a.final_cost, b.final_cost);
    if (k == 0) {
      EXPECT_EQ(error_code([&] { asked.residuals(0); }), ErrorCode::InvalidArgument);  // only a first frame
      continue;
    }
    // The keyframe it was aligned with, also when this frame replaced it.
    for (int level : {0, 2}) {
      const ResidualImage im = asked.residuals(level);
      const cv::Mat& prev = frames[static_cast<size_t>(key)][static_cast<size_t>(level)];
      size_t n = 0, same = 0, compared = 0;
      for (int y = 0; y < prev.rows; ++y)
        for (int x = 0; x < prev.cols; ++x, ++n)
          if (prev.at<cv::Vec4f>(y, x)[3] != 0) {
            ++compared;
            same += im.intensity[n] == prev.at<cv::Vec4f>(y, x)[0] ? 1 : 0;
          }
      EXPECT_EQ(same, compared) << "frame " << k << " level " << level;
    }
    EXPECT_EQ(error_code([&] { asked.residuals(4); }), ErrorCode::InvalidArgument);
    if (a.keyframe) key = k, replaced += 1;
  }
  EXPECT_GE(replaced, 2);
  // A frame of another size is not aligned: Failed.
  const cv::Mat small(240, 320, CV_8UC1, cv::Scalar(128));
  asked.track(test::test_upload(rt_, test::test_pyramid(small, nullptr, 4)), 20 / 30.0);
  EXPECT_EQ(error_code([&] { asked.residuals(0); }), ErrorCode::Failed);
  asked.reset();
  EXPECT_EQ(error_code([&] { asked.residuals(0); }), ErrorCode::InvalidArgument);
}

}  // namespace
}  // namespace planarvo::track
