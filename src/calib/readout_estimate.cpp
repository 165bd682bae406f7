#include "calib/readout_estimate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include <Eigen/Dense>

#include "core/error.h"
#include "image/pipeline.h"
#include "image/rolling_shutter.h"

namespace planarvo::calib {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Window {
  size_t begin = 0, end = 0;
};

class Evaluator {
 public:
  Evaluator(ocl::Runtime& rt, const CameraModel& camera, const Extrinsics& ext, const std::vector<cv::Mat>& frames,
            const std::vector<double>& stamps, const ReadoutEstimateOptions& o)
      : rt_(rt), camera_(camera), ext_(ext), frames_(frames), stamps_(stamps), opt_(o) {}

  // The first pass: every frame through the tracker told readout r (its own twist model). Keeps
  // each frame's motion from the previous one (none for the first and for frames not tracked)
  // for the twists, and returns each frame's motion size (x, y in units of the height, theta in
  // radians; squared norm) for choosing the windows.
  std::vector<double> first_pass(double r) {
    CameraModel c = camera_;
    c.rolling_shutter_readout = r;
    track::Tracker tracker(rt_, c, ext_, opt_.tracker);
    std::vector<double> size;
    velocity_.assign(frames_.size(), Eigen::Vector3d::Constant(kNaN));
    for (size_t i = 0; i < frames_.size(); ++i) {
      const cv::Mat& f = frames_[i];
      const track::FrameResult res = tracker.track(f.data, f.cols, f.rows, f.step, stamps_[i]);
      const SE2& m = res.motion.value;
      const bool tracked = tracked_status(res) && i > 0 && stamps_[i] > stamps_[i - 1];
      size.push_back(tracked ? m.x * m.x + m.y * m.y + m.theta * m.theta : 0.0);
      if (tracked) velocity_[i] = m.log() / (stamps_[i] - stamps_[i - 1]);
    }
    return size;
  }

  // Frame i's twist over a readout: the first pass's velocities (each at the middle of its
  // interval) interpolated to the frame's mean row time, t_i + m (m = (readout - exposure) / 2,
  // CameraModel::mean_row_time), which lies between the interval ending at frame i and the one
  // starting there. Offline, so the next frame is known:
  // no extrapolation, unlike the tracker's (track/readout_twist.h), whose errors in the twists'
  // differences would read as a readout error.
  Eigen::Vector3d twist(size_t i, double m) const {
    const Eigen::Vector3d& before = velocity_[i];
    const Eigen::Vector3d& after = i + 1 < velocity_.size() ? velocity_[i + 1] : velocity_[i];
    if (!before.allFinite()) return after.allFinite() ? after : Eigen::Vector3d::Zero();
    if (!after.allFinite()) return before;
    const double t0 = 0.5 * (stamps_[i - 1] + stamps_[i]), t1 = 0.5 * (stamps_[i] + stamps_[i + 1]);
    const double w = std::clamp((stamps_[i] + m - t0) / (t1 - t0), 0.0, 1.0);
    return (1.0 - w) * before + w * after;
  }

  // Each window tracked afresh with readout r: every frame undistorted with its twist (above),
  // then the tracker on the pyramids (it takes them as they are). Per frame: the residual
  // variance at the finest level (the robust scale squared; NaN for a window's first frame and
  // a frame not tracked).
  std::vector<double> evaluate(double r, const std::vector<Window>& windows) {
    CameraModel c = camera_;
    c.rolling_shutter_readout = r;
    ImagePipelineOptions po;
    po.prefilter = opt_.tracker.prefilter;
    ImagePipeline pipeline(rt_, c, opt_.tracker.levels, po);
    track::Tracker tracker(rt_, camera_global(), ext_, opt_.tracker);
    Pyramid pyramid;
    std::vector<double> variance;
    for (const Window& w : windows) {
      tracker.reset();
      for (size_t i = w.begin; i < w.end; ++i) {
        pipeline.set_row_warp(rolling_shutter_warp(c, ext_, twist(i, c.mean_row_time())));
        pipeline.process(frames_[i], pyramid);
        const track::FrameResult res = tracker.track(pyramid, stamps_[i]);
        variance.push_back(tracked_status(res) && std::isfinite(res.sigma) ? res.sigma * res.sigma : kNaN);
      }
    }
    return variance;
  }

 private:
  static bool tracked_status(const track::FrameResult& r) {
    return r.status == track::FrameResult::Status::Ok || r.status == track::FrameResult::Status::Degraded;
  }
  // The tracker of the pyramids undistorted here: they stand for their stamps.
  CameraModel camera_global() const {
    CameraModel c = camera_;
    c.rolling_shutter_readout = c.exposure_time = 0.0;
    return c;
  }

  ocl::Runtime& rt_;
  const CameraModel& camera_;
  const Extrinsics& ext_;
  const std::vector<cv::Mat>& frames_;
  const std::vector<double>& stamps_;
  const ReadoutEstimateOptions& opt_;
  std::vector<Eigen::Vector3d> velocity_;  // per frame, from the previous one (NaN: none)
};

// The `count` non-overlapping windows of `length` frames with the most motion (greedy).
std::vector<Window> fastest_windows(const std::vector<double>& motion, size_t length, int count) {
  const size_t n = motion.size();
  if (n <= length) return {Window{0, n}};
  std::vector<double> prefix(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + motion[i];
  std::vector<char> taken(n, 0);
  std::vector<Window> out;
  for (int k = 0; k < count; ++k) {
    double best = -1.0;
    size_t best_start = n;
    for (size_t s = 0; s + length <= n; ++s) {
      if (taken[s] || taken[s + length - 1]) continue;  // windows are contiguous, so the ends decide
      const double score = prefix[s + length] - prefix[s];
      if (score > best) {
        best = score;
        best_start = s;
      }
    }
    if (best_start == n) break;
    std::fill(taken.begin() + static_cast<long>(best_start), taken.begin() + static_cast<long>(best_start + length), 1);
    out.push_back(Window{best_start, best_start + length});
  }
  std::sort(out.begin(), out.end(), [](const Window& a, const Window& b) { return a.begin < b.begin; });
  return out;
}

double median_interval(const std::vector<double>& stamps) {
  std::vector<double> dt;
  for (size_t i = 1; i < stamps.size(); ++i) dt.push_back(stamps[i] - stamps[i - 1]);
  std::nth_element(dt.begin(), dt.begin() + static_cast<long>(dt.size() / 2), dt.end());
  return dt[dt.size() / 2];
}

double finite_mean(const std::vector<double>& v) {
  double s = 0.0;
  int n = 0;
  for (double x : v)
    if (std::isfinite(x)) {
      s += x;
      ++n;
    }
  return n > 0 ? s / n : HUGE_VAL;
}

// Each frame's residual variance as a parabola in r through the three candidates nearest `best`
// (u = (r - best) / scale keeps the system well conditioned); the minimum of their sum and its
// sandwich standard deviation over clusters of consecutive frames within a window.
struct Fit {
  int frames = 0;          // frames with all three variances
  double curvature = 0.0;  // of the sum (positive: a minimum)
  double minimum = 0.0, sigma = 0.0;  // seconds
};

Fit fit_parabolas(std::map<double, std::vector<double>>& at, const std::vector<Window>& windows, double best,
                  double scale, size_t cluster) {
  std::vector<std::pair<double, double>> near;  // (distance, r)
  for (const auto& [r, v] : at) near.push_back({std::abs(r - best), r});
  std::sort(near.begin(), near.end());
  Eigen::Matrix3d A;
  std::array<const std::vector<double>*, 3> y{};
  for (size_t j = 0; j < 3; ++j) {
    const double u = (near[j].second - best) / scale;
    A.row(static_cast<Eigen::Index>(j)) << 1.0, u, u * u;
    y[j] = &at[near[j].second];
  }
  const Eigen::Matrix3d Ainv = A.inverse();
  const size_t n = y[0]->size();
  std::vector<double> slope(n, kNaN), curvature(n, kNaN);
  Fit fit;
  double B = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d v((*y[0])[i], (*y[1])[i], (*y[2])[i]);
    if (!v.allFinite()) continue;
    const Eigen::Vector3d c = Ainv * v;
    slope[i] = c(1);
    curvature[i] = c(2);
    B += c(1);
    fit.curvature += c(2);
    ++fit.frames;
  }
  if (!(fit.curvature > 0)) return fit;
  const double u_hat = -B / (2.0 * fit.curvature);
  fit.minimum = best + u_hat * scale;
  double meat = 0.0;
  size_t i = 0;
  for (const Window& w : windows)
    for (size_t s = w.begin; s < w.end; s += cluster) {
      double g = 0.0;
      for (size_t k = s; k < std::min(w.end, s + cluster); ++k, ++i)
        if (std::isfinite(slope[i])) g += slope[i] + 2.0 * curvature[i] * u_hat;
      meat += g * g;
    }
  fit.sigma = std::sqrt(meat) / (2.0 * fit.curvature) * scale;
  return fit;
}

}  // namespace

ReadoutEstimate estimate_readout(ocl::Runtime& runtime, const CameraModel& camera, const Extrinsics& camera_frame,
                                 const std::vector<cv::Mat>& frames, const std::vector<double>& stamps,
                                 const ReadoutEstimateOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  ReadoutEstimate out;
  auto finish = [&](const std::string& reason) {
    out.reason = reason;
    out.ok = reason.empty();
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };
  if (frames.size() != stamps.size()) throw_invalid_argument("estimate_readout: frames and stamps differ in count");
  if (options.window_frames < 3 || options.windows < 1 || options.cluster_frames < 1)
    throw_invalid_argument("estimate_readout: window_frames >= 3, windows >= 1 and cluster_frames >= 1");
  const size_t min_frames = static_cast<size_t>(options.window_frames);
  if (frames.size() < min_frames)
    return finish("only " + std::to_string(frames.size()) + " frames; the readout estimate needs " +
                  std::to_string(min_frames));
  const double R = options.max_readout > 0 ? options.max_readout : 0.95 * median_interval(stamps);
  if (!(R > 0)) return finish("the frames' stamps do not increase");
  out.max_readout = R;

  Evaluator eval(runtime, camera, camera_frame, frames, stamps, options);
  auto progress = [&](double f) {
    if (options.progress && !options.progress(f)) throw Error(ErrorCode::Cancelled, "calibration cancelled");
  };
  // The first pass, through every frame, finds where the camera moves fastest and its twists.
  progress(0.0);
  const std::vector<double> motion = eval.first_pass(options.guess >= 0 ? std::clamp(options.guess, 0.0, R) : 0.5 * R);
  const std::vector<Window> windows =
      fastest_windows(motion, static_cast<size_t>(options.window_frames), options.windows);
  size_t window_frames = 0;
  for (const Window& w : windows) window_frames += w.end - w.begin;
  const double pass_share = static_cast<double>(frames.size()) / static_cast<double>(frames.size() + 9 * window_frames);
  progress(pass_share);

  // The bracket: 0, R/2, R, then the best one's neighbours at R/4 and R/8.
  std::map<double, std::vector<double>> at;  // candidate readout -> per-frame variance
  auto evaluate = [&](double r) {
    r = std::clamp(r, 0.0, R);
    for (const auto& [q, v] : at)
      if (std::abs(q - r) < 1e-6 * R) return;
    at[r] = eval.evaluate(r, windows);
    ++out.evaluations;
    out.curve.push_back({r, finite_mean(at[r])});
    progress(pass_share + (1.0 - pass_share) * std::min(1.0, out.evaluations / 9.0));
  };
  auto best = [&]() {
    double b = 0.0, cost = HUGE_VAL;
    for (const auto& [r, v] : at)
      if (const double m = finite_mean(v); m < cost) {
        cost = m;
        b = r;
      }
    return b;
  };
  if (options.guess >= 0) {
    // From a guess: its neighbours at R/8, moving on while the best is the last one on a side.
    const double g = std::clamp(options.guess, 0.0, R);
    for (double r : {g - R / 8, g, g + R / 8}) evaluate(r);
    for (int k = 0; k < 4; ++k) {
      const double b = best();
      const double lo = at.begin()->first, hi = at.rbegin()->first;
      if (b == lo && b > 0.0) evaluate(b - R / 8);
      else if (b == hi && b < R) evaluate(b + R / 8);
      else break;
    }
  } else {
    for (double r : {0.0, 0.5 * R, R}) evaluate(r);
    for (double step : {R / 4, R / 8}) {
      const double b = best();
      evaluate(b - step);
      evaluate(b + step);
    }
  }
  std::sort(out.curve.begin(), out.curve.end());

  const Fit fit = fit_parabolas(at, windows, best(), R / 8, static_cast<size_t>(options.cluster_frames));
  out.frames = fit.frames;
  if (out.frames < options.window_frames / 2 || !(fit.curvature > 0))
    return finish("the images do not change with the readout time: the drive is too slow or too short to shear "
                  "them (drive faster, or turn)");
  out.estimate = std::clamp(fit.minimum, 0.0, R);
  out.sigma = fit.sigma;
  out.readout = out.estimate > options.zero_below_sigmas * out.sigma ? out.estimate : 0.0;
  progress(1.0);
  return finish("");
}

}  // namespace planarvo::calib
