// OpenCV's ECC (findTransformECC) coarse to fine, the peer the tracker is measured against by
// bench_ecc (accuracy) and bench_track speed (time on the same frames). Header-only (each
// bench/*.cpp is its own program).
#pragma once
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "core/camera.h"
#include "image/undistort.h"

namespace planarvo::bench {

// ECC coarse to fine (cv::resize INTER_AREA halvings; pixel u of level l+1 is at 2u + 0.5 of
// level l), from the identity. A level at which OpenCV gives up (StsNoConv) keeps the estimate
// it started from. False when the finest level gave up.
inline bool ecc_pair(const cv::Mat& ref, const cv::Mat& live, const cv::Mat& mask, int levels, cv::Mat* H) {
  std::vector<cv::Mat> r{ref}, l{live}, m{mask};
  for (int i = 1; i < levels; ++i) {
    cv::Mat a, b, c;
    cv::resize(r.back(), a, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    cv::resize(l.back(), b, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    cv::resize(m.back(), c, cv::Size(), 0.5, 0.5, cv::INTER_NEAREST);
    r.push_back(a);
    l.push_back(b);
    m.push_back(c);
  }
  cv::Mat W = cv::Mat::eye(3, 3, CV_32F);
  const cv::Matx33f S(2, 0, 0.5f, 0, 2, 0.5f, 0, 0, 1);
  bool ok = true;
  for (int i = levels - 1; i >= 0; --i) {
    const cv::Mat start = W.clone();
    const auto k = static_cast<size_t>(i);
    try {
      cv::findTransformECC(r[k], l[k], W, cv::MOTION_HOMOGRAPHY,
                           cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-6), m[k], 5);
    } catch (const cv::Exception&) {
      W = start;
      if (i == 0) ok = false;
    }
    if (i > 0) W = cv::Mat(S * cv::Matx33f(W) * S.inv());
  }
  *H = W;
  return ok;
}

// What ECC is given: a camera's frames undistorted with cv::remap (bilinear, float) and the mask
// of the undistorted pixels that have a source.
struct EccFrames {
  explicit EccFrames(const CameraModel& camera)
      : map_(compute_undistort_map(camera)),
        map_x_(camera.height, camera.width, CV_32F, map_.map_x.data()),
        map_y_(camera.height, camera.width, CV_32F, map_.map_y.data()),
        mask(cv::Mat(camera.height, camera.width, CV_8U, map_.valid.data()) * 255) {}
  EccFrames(const EccFrames&) = delete;  // the maps point into map_
  EccFrames& operator=(const EccFrames&) = delete;
  cv::Mat undistort(const cv::Mat& gray) const {
    cv::Mat f, u;
    gray.convertTo(f, CV_32F);
    cv::remap(f, u, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
    return u;
  }

 private:
  UndistortMap map_;
  cv::Mat map_x_, map_y_;

 public:
  cv::Mat mask;
};

}  // namespace planarvo::bench
