// The floor mosaic's builder: frame selection, the grid, tiles, gains, blending (mosaic.h).
#include "mosaic/mosaic.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <iomanip>
#include <locale>
#include <sstream>
#include <limits>
#include <memory>

#include <Eigen/Dense>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "core/output_file.h"

namespace planarvo::mosaic {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

constexpr double kTurnForNewFrame = 5.0 * M_PI / 180.0;
// The fewest pixels across a frame's footprint on the ground that a resolution may give.
constexpr int kMinFootprintPixels = 4;

// v with `decimals` digits after the point (decimals < 0: the shortest general form, 3 digits).
std::string num(double v, int decimals) {
  std::ostringstream s;
  s.imbue(std::locale::classic());
  if (decimals >= 0) s << std::fixed << std::setprecision(decimals) << v;
  else s << std::setprecision(3) << v;
  return s.str();
}

// The ground the camera sees, in the robot frame: points on the boundary of the region of
// interest's ground footprint, clipped to the range limit, and the points of the range circle
// that the camera sees. Their bounding box bounds every pixel the warp can give weight to.
std::vector<Eigen::Vector2d> footprint(const WarpSetup& s) {
  const CameraModel& cam = s.camera;
  const Eigen::Matrix3d R = s.extrinsics.R_vc();
  const Eigen::Vector3d t = s.extrinsics.t_vc();
  const Eigen::Vector2d foot = t.head<2>();
  std::vector<Eigen::Vector2d> pts;
  const PixelRegion r = cam.region();
  const auto add_pixel = [&](double u, double v) {
    const Eigen::Vector2d n = cam.unproject({u, v});
    const Eigen::Vector3d d = R * Eigen::Vector3d(n.x(), n.y(), 1.0);
    Eigen::Vector2d dir = d.head<2>();
    if (dir.norm() < 1e-12) dir = Eigen::Vector2d(1, 0);
    if (d.z() < 0) {
      const Eigen::Vector2d p = (t + (-t.z() / d.z()) * d).head<2>();
      if ((p - foot).norm() <= s.max_range) {
        pts.push_back(p);
        return;
      }
    }
    pts.push_back(foot + s.max_range * dir.normalized());
  };
  for_each_border_pixel(r, 4, add_pixel);
  add_pixel(r.x + r.width - 1, r.y + r.height - 1);
  // The range circle where the camera sees it.
  const Eigen::Matrix3d R_cv = R.transpose();
  for (int k = 0; k < 360; ++k) {
    const double a = 2.0 * M_PI * k / 360.0;
    const Eigen::Vector2d g = foot + s.max_range * Eigen::Vector2d(std::cos(a), std::sin(a));
    const Eigen::Vector3d pc = R_cv * (Eigen::Vector3d(g.x(), g.y(), 0.0) - t);
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d n(pc.x() / pc.z(), pc.y() / pc.z());
    if (n.squaredNorm() > s.max_radius2) continue;
    const Eigen::Vector2d px = cam.project(pc);
    if (px.x() >= r.x && px.y() >= r.y && px.x() <= r.x + r.width - 1 && px.y() <= r.y + r.height - 1) pts.push_back(g);
  }
  return pts;
}

struct Box {
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0;
  double x1 = -std::numeric_limits<double>::infinity(), y1 = x1;
  void add(const Eigen::Vector2d& p) {
    x0 = std::min(x0, p.x());
    y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x());
    y1 = std::max(y1, p.y());
  }
  void add(const Box& b) {
    x0 = std::min(x0, b.x0);
    y0 = std::min(y0, b.y0);
    x1 = std::max(x1, b.x1);
    y1 = std::max(y1, b.y1);
  }
};

Box frame_box(const std::vector<Eigen::Vector2d>& fp, const SE2& pose) {
  Box b;
  for (const Eigen::Vector2d& p : fp) b.add(pose * p);
  return b;
}

// The robot's poses of frame k's first, middle and last rows' images (a rolling shutter's reads,
// each less half the exposure: CameraModel::row_time): the trajectory's motion from pose k to the
// next held constant over the interval, an arc on SE(2) (the tracker's and the simulator's
// model); after the last pose, the last interval's velocity continued. Rows that all stand for
// the stamp, or a single pose: the frame's pose three times.
std::array<SE2, 3> readout_poses(const std::vector<PosedFrame>& frames, const std::vector<double>& times,
                                 size_t k, const CameraModel& camera) {
  const SE2& pose = frames[k].pose;
  std::array<SE2, 3> out{pose, pose, pose};
  if (!camera.timed_rows() || frames.size() < 2) return out;
  const size_t a = k + 1 < frames.size() ? k : k - 1;
  const double dt = times[a + 1] - times[a];
  if (!(dt > 0)) return out;
  const Eigen::Vector3d velocity = (frames[a].pose.inverse() * frames[a + 1].pose).log() / dt;
  const double last = camera.height - 1.0;
  out[0] = pose * SE2::exp(velocity * camera.row_time(0.0));
  out[1] = pose * SE2::exp(velocity * camera.row_time(0.5 * last));
  out[2] = pose * SE2::exp(velocity * camera.row_time(last));
  return out;
}

// The frames to use: the first, then each whose camera foot point has moved `spacing` or whose
// heading has turned kTurnForNewFrame since the last one used, and the last.
std::vector<size_t> select_frames(const std::vector<PosedFrame>& frames, const Eigen::Vector2d& foot, double spacing) {
  std::vector<size_t> used;
  for (size_t i = 0; i < frames.size(); ++i) {
    if (used.empty() || spacing < 0 || i + 1 == frames.size()) {
      used.push_back(i);
      continue;
    }
    const SE2& a = frames[used.back()].pose;
    const SE2& b = frames[i].pose;
    const double moved = ((b * foot) - (a * foot)).norm();
    const double turned = std::abs(std::remainder(b.theta - a.theta, 2.0 * M_PI));
    if (moved >= spacing || turned >= kTurnForNewFrame) used.push_back(i);
  }
  return used;
}

// Float accumulators of one tile: the gain-corrected weighted sum and the weight.
struct Tile {
  std::vector<float> sum, weight;
};

class Blender {
 public:
  Blender(const MosaicGrid& grid, int tile, const std::vector<Window>& windows)
      : grid_(grid), tile_(tile), nx_((grid.width + tile - 1) / tile), ny_((grid.height + tile - 1) / tile) {
    tiles_.resize(static_cast<size_t>(nx_) * static_cast<size_t>(ny_));
    // Each tile is finished after the last frame whose window touches it.
    std::vector<int64_t> last_use(tiles_.size(), -1);
    for (size_t k = 0; k < windows.size(); ++k)
      for_tiles(windows[k], [&](size_t t) { last_use[t] = static_cast<int64_t>(k); });
    finish_at_.resize(windows.size());
    for (size_t t = 0; t < tiles_.size(); ++t)
      if (last_use[t] >= 0) finish_at_[static_cast<size_t>(last_use[t])].push_back(t);
    image_ = cv::Mat::zeros(grid.height, grid.width, CV_8UC1);
  }

  // The gain that brings this frame's samples to the mosaic's values where the mosaic is already
  // well covered (total weight at least 1): the ratio of the weighted means. NaN when too few
  // pixels overlap (under 5% of the frame's).
  double gain(const cv::Mat& samples, const Window& w) {
    double sm = 0, sf = 0;
    int64_t seen = 0, overlap = 0;
    for (int r = 0; r < w.height; ++r) {
      const cv::Vec2f* s = samples.ptr<cv::Vec2f>(r);
      for_row_runs(w.y + r, w.x, w.width, [&](Tile& t, size_t i0, int c0, int n) {
        for (int c = c0; c < c0 + n; ++c) {
          const float wt = s[c][1];
          if (wt <= 0.0f) continue;
          ++seen;
          if (t.sum.empty()) continue;
          const size_t i = i0 + static_cast<size_t>(c - c0);
          if (t.weight[i] < 1.0f) continue;
          ++overlap;
          sm += wt * (t.sum[i] / t.weight[i]);
          sf += wt * s[c][0];
        }
      });
    }
    if (overlap < seen / 20 || overlap == 0 || !(sf > 0)) return std::nan("");
    return sm / sf;
  }

  void add(const cv::Mat& samples, const Window& w, float gain) {
    for (int r = 0; r < w.height; ++r) {
      const cv::Vec2f* s = samples.ptr<cv::Vec2f>(r);
      for_row_runs(w.y + r, w.x, w.width, [&](Tile& t, size_t i0, int c0, int n) {
        float* sum = nullptr;
        float* weight = nullptr;
        for (int c = c0; c < c0 + n; ++c) {
          const float wt = s[c][1];
          if (wt <= 0.0f) continue;
          if (!sum) {
            if (t.sum.empty()) allocate(t);
            sum = t.sum.data() + i0 - static_cast<size_t>(c0);
            weight = t.weight.data() + i0 - static_cast<size_t>(c0);
          }
          sum[c] += wt * gain * s[c][0];
          weight[c] += wt;
        }
      });
    }
  }

  // Finishes (to 8 bits) and frees the tiles no later frame touches.
  void finish_after(size_t k, int64_t* covered) {
    for (const size_t ti : finish_at_[k]) {
      Tile& t = tiles_[ti];
      if (t.sum.empty()) continue;
      const int tx = static_cast<int>(ti % static_cast<size_t>(nx_)), ty = static_cast<int>(ti / static_cast<size_t>(nx_));
      const int x0 = tx * tile_, y0 = ty * tile_;
      const int x1 = std::min(x0 + tile_, grid_.width), y1 = std::min(y0 + tile_, grid_.height);
      for (int y = y0; y < y1; ++y) {
        uint8_t* out = image_.ptr<uint8_t>(y);
        for (int x = x0; x < x1; ++x) {
          const size_t i = index_in_tile(x, y);
          if (!(t.weight[i] > 0.0f)) continue;
          const float v = std::round(t.sum[i] / t.weight[i]);
          out[x] = static_cast<uint8_t>(std::clamp(v, 1.0f, 255.0f));
          ++*covered;
        }
      }
      held_ -= 2 * static_cast<int64_t>(t.sum.size() * sizeof(float));
      std::vector<float>().swap(t.sum);
      std::vector<float>().swap(t.weight);
    }
  }

  cv::Mat& image() { return image_; }
  int64_t peak_bytes() const { return peak_; }

 private:
  // f(tile, index of the run's first pixel in the tile, first window column, length) for each
  // run of window row gy (mosaic row) from mosaic column x0, width columns, within one tile.
  template <class F>
  void for_row_runs(int gy, int x0, int width, F f) {
    const size_t row = static_cast<size_t>(gy / tile_) * static_cast<size_t>(nx_);
    const size_t in_row = static_cast<size_t>(gy % tile_) * static_cast<size_t>(tile_);
    for (int c = 0; c < width;) {
      const int gx = x0 + c;
      const int tx = gx / tile_;
      const int n = std::min(width - c, (tx + 1) * tile_ - gx);
      f(tiles_[row + static_cast<size_t>(tx)], in_row + static_cast<size_t>(gx % tile_), c, n);
      c += n;
    }
  }
  template <class F>
  void for_tiles(const Window& w, F f) const {
    if (w.empty()) return;
    for (int ty = w.y / tile_; ty <= (w.y + w.height - 1) / tile_; ++ty)
      for (int tx = w.x / tile_; tx <= (w.x + w.width - 1) / tile_; ++tx)
        f(static_cast<size_t>(ty) * static_cast<size_t>(nx_) + static_cast<size_t>(tx));
  }
  size_t index_in_tile(int x, int y) const {
    return static_cast<size_t>(y % tile_) * static_cast<size_t>(tile_) + static_cast<size_t>(x % tile_);
  }
  void allocate(Tile& t) {
    const size_t n = static_cast<size_t>(tile_) * static_cast<size_t>(tile_);
    t.sum.assign(n, 0.0f);
    t.weight.assign(n, 0.0f);
    held_ += 2 * static_cast<int64_t>(n * sizeof(float));
    peak_ = std::max(peak_, held_);
  }

  MosaicGrid grid_;
  int tile_, nx_, ny_;
  std::vector<Tile> tiles_;
  std::vector<std::vector<size_t>> finish_at_;  // per frame used, the tiles it is the last to touch
  cv::Mat image_;
  int64_t held_ = 0, peak_ = 0;
};

void check_options(const MosaicOptions& o) {
  if (!(o.resolution > 0) || !std::isfinite(o.resolution))
    throw_invalid_argument("mosaic: the resolution must be a positive number of metres per pixel");
  if (!(o.max_range >= 0) || !std::isfinite(o.max_range)) throw_invalid_argument("mosaic: max_range must be >= 0");
  if (!std::isfinite(o.frame_spacing)) throw_invalid_argument("mosaic: frame_spacing must be finite");
  if (!(o.feather > 0 && o.feather <= 0.5)) throw_invalid_argument("mosaic: feather must lie in (0, 0.5]");
  if (o.max_side < 1) throw_invalid_argument("mosaic: max_side must be positive");
  if (o.tile_size < 16 || o.tile_size > 4096) throw_invalid_argument("mosaic: tile_size must lie in 16..4096");
}

// The grid over the union of the boxes, snapped to whole pixels of the resolution.
MosaicGrid make_grid(const Box& all, const MosaicOptions& o) {
  const double r = o.resolution;
  MosaicGrid g;
  g.resolution = r;
  const double cx0 = std::floor(all.x0 / r), cy0 = std::floor(all.y0 / r);
  const double cx1 = std::ceil(all.x1 / r), cy1 = std::ceil(all.y1 / r);
  const double w = std::max(1.0, cx1 - cx0), h = std::max(1.0, cy1 - cy0);
  if (w > o.max_side || h > o.max_side)
    throw_invalid_input("the mosaic would be " + num(w, 0) + " x " + num(h, 0) + " pixels (" +
                        num(all.x1 - all.x0, 2) + " m x " + num(all.y1 - all.y0, 2) + " m at " +
                        num(r, -1) + " m/px), more than " + std::to_string(o.max_side) +
                        " on a side; give a coarser resolution (" +
                        num(r * std::max(w, h) / o.max_side * 1.001, -1) + " m/px or more)");
  g.origin = Eigen::Vector2d(cx0 * r, cy0 * r);
  g.width = static_cast<int>(w);
  g.height = static_cast<int>(h);
  return g;
}

Window window_of(const Box& b, const MosaicGrid& g) {
  const double r = g.resolution;
  const int c0 = std::max(0, static_cast<int>(std::floor((b.x0 - g.origin.x()) / r)) - 1);
  const int c1 = std::min(g.width, static_cast<int>(std::ceil((b.x1 - g.origin.x()) / r)) + 1);
  const int r0 = std::max(0, static_cast<int>(std::floor(g.height - (b.y1 - g.origin.y()) / r)) - 1);
  const int r1 = std::min(g.height, static_cast<int>(std::ceil(g.height - (b.y0 - g.origin.y()) / r)) + 1);
  return {c0, r0, std::max(0, c1 - c0), std::max(0, r1 - r0)};
}

// The shortest decimal form that reads back to the same double.
std::string shortest(double v) {
  for (int precision = 1; precision <= 17; ++precision) {
    std::ostringstream s;
    s.imbue(std::locale::classic());
    s << std::setprecision(precision) << v;
    if (std::stod(s.str()) == v) return s.str();
  }
  return std::to_string(v);
}

}  // namespace

std::vector<int64_t> match_frames(const std::vector<double>& frame_times, const std::vector<double>& times) {
  if (times.empty()) throw_invalid_input("the trajectory is empty: it has no pose to place a frame with");
  double shortest = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < frame_times.size(); ++i) shortest = std::min(shortest, frame_times[i] - frame_times[i - 1]);
  const double tol = std::min(1e-3, 0.25 * shortest);
  std::vector<int64_t> out;
  out.reserve(times.size());
  for (size_t k = 0; k < times.size(); ++k) {
    const double t = times[k];
    const auto it = std::lower_bound(frame_times.begin(), frame_times.end(), t);
    int64_t best = -1;
    double d = std::numeric_limits<double>::infinity();
    for (auto c : {it, it == frame_times.begin() ? it : it - 1}) {
      if (c == frame_times.end()) continue;
      if (std::abs(*c - t) < d) {
        d = std::abs(*c - t);
        best = c - frame_times.begin();
      }
    }
    if (!(d <= tol))
      throw_invalid_input("trajectory pose " + std::to_string(k + 1) + " (t = " + num(t, 6) +
                          " s) has no frame within " + num(tol * 1e3, -1) + " ms" +
                          (best >= 0 ? "; the nearest is frame " + std::to_string(best) + " at t = " +
                                           num(frame_times[static_cast<size_t>(best)], 6) + " s"
                                     : std::string()) +
                          " (is the trajectory from this data set?)");
    out.push_back(best);
  }
  return out;
}

namespace {

// Every pose names a frame of the data set and is a finite place within reach of the origin.
void check_frames(const io::Dataset& dataset, const std::vector<PosedFrame>& frames) {
  for (const PosedFrame& f : frames) {
    if (f.frame < 0 || f.frame >= dataset.frame_count())
      throw_invalid_argument("mosaic: frame " + std::to_string(f.frame) + " is not in the data set (it has " +
                             std::to_string(dataset.frame_count()) + ")");
    if (!std::isfinite(f.pose.x) || !std::isfinite(f.pose.y) || !std::isfinite(f.pose.theta))
      throw_invalid_input("mosaic: the pose of frame " + std::to_string(f.frame) + " is not finite");
    if (std::max(std::abs(f.pose.x), std::abs(f.pose.y)) > kMaxPositionMetres)
      throw_invalid_input("mosaic: the pose of frame " + std::to_string(f.frame) + " (x " + num(f.pose.x, -1) +
                          ", y " + num(f.pose.y, -1) + " m) is beyond " + num(kMaxPositionMetres, -1) +
                          " m from the origin: a corrupt trajectory or another unit");
  }
}

// A frame must cover pixels: at a resolution coarser than a few pixels per footprint, every frame
// would fall between pixel centres and the image would be empty.
void check_resolution(const Box& robot_box, const MosaicOptions& options) {
  const double footprint_side = std::min(robot_box.x1 - robot_box.x0, robot_box.y1 - robot_box.y0);
  if (!(footprint_side / options.resolution >= kMinFootprintPixels))
    throw_invalid_argument("mosaic: the resolution " + num(options.resolution, -1) +
                           " m per pixel is too coarse for the camera's footprint on the ground (" +
                           num(footprint_side, -1) + " m across): a frame would cover fewer than " +
                           std::to_string(kMinFootprintPixels) + " pixels across; give " +
                           num(footprint_side / kMinFootprintPixels, -1) + " m per pixel or finer");
}

// Each used frame warped onto its window of the mosaic and blended in (gains matched to what is
// already there), decoded one ahead on a second thread (the only user of the data set meanwhile)
// so that decoding overlaps the warp and the blending. The seconds spent waiting for frames.
double warp_and_blend(ocl::Runtime& runtime, io::Dataset& dataset, const std::vector<PosedFrame>& frames,
                      const std::vector<size_t>& used, const std::vector<std::array<SE2, 3>>& row_poses,
                      const std::vector<Window>& windows, const WarpSetup& setup, const MosaicOptions& options,
                      Mosaic& m) {
  const CameraModel& cam = dataset.camera();
  MosaicWarp warp(runtime, cam.width, cam.height);
  Blender blender(m.grid, options.tile_size, windows);
  cv::Mat samples;
  double last_gain = 1.0;
  double decode_seconds = 0;  // the decoding thread's, read after each get()
  const auto decode = [&](size_t k) {
    const Clock::time_point t = Clock::now();
    cv::Mat f = windows[k].empty() ? cv::Mat() : dataset.frame(frames[used[k]].frame);
    decode_seconds += seconds_since(t);
    return f;
  };
  std::future<cv::Mat> next = std::async(std::launch::async, decode, size_t{0});
  for (size_t k = 0; k < used.size(); ++k) {
    if (options.progress && !options.progress(static_cast<double>(k) / static_cast<double>(used.size()), "mosaic"))
      throw Error(ErrorCode::Cancelled, "mosaic: cancelled");
    const cv::Mat frame = next.get();
    if (k + 1 < used.size()) next = std::async(std::launch::async, decode, k + 1);
    const Window& w = windows[k];
    if (w.empty()) continue;
    Clock::time_point t = Clock::now();
    warp.run(frame, warp_params(setup, row_poses[k], m.grid, w), w.width, w.height, &samples);
    m.stats.seconds_warp += seconds_since(t);
    t = Clock::now();
    double g = 1.0;
    if (options.estimate_gain && k > 0) {
      g = blender.gain(samples, w);
      g = std::isfinite(g) ? std::clamp(g, 0.25, 4.0) : last_gain;
    }
    last_gain = g;
    m.stats.gain_min = std::min(m.stats.gain_min, g);
    m.stats.gain_max = std::max(m.stats.gain_max, g);
    blender.add(samples, w, static_cast<float>(g));
    blender.finish_after(k, &m.stats.covered_pixels);
    m.stats.seconds_blend += seconds_since(t);
  }
  m.image = blender.image();
  m.stats.peak_tile_bytes = blender.peak_bytes();
  return decode_seconds;
}

}  // namespace

Mosaic build_mosaic(ocl::Runtime& runtime, io::Dataset& dataset, const Extrinsics& extrinsics,
                    const std::vector<PosedFrame>& frames, const MosaicOptions& options) {
  const Clock::time_point t0 = Clock::now();
  check_options(options);
  if (!extrinsics.finite() || !(extrinsics.z > 0))
    throw_invalid_argument("mosaic: the extrinsics must be finite numbers with a height z > 0");
  if (!options.accept_unusual_extrinsics) check_plausible_extrinsics(extrinsics, "mosaic: the extrinsics");
  if (frames.empty()) throw_invalid_input("mosaic: no poses: the trajectory is empty");
  check_frames(dataset, frames);
  const CameraModel& cam = dataset.camera();
  const PixelRegion region = cam.region();
  const double max_range = options.max_range > 0 ? options.max_range : 4.0 * extrinsics.z;
  const WarpSetup setup =
      make_warp_setup(cam, extrinsics, max_range, options.feather * std::min(region.width, region.height));
  const std::vector<Eigen::Vector2d> fp = footprint(setup);
  if (fp.empty()) throw_invalid_input("mosaic: the camera sees no ground within the range limit");
  Box robot_box;
  for (const Eigen::Vector2d& p : fp) robot_box.add(p);
  check_resolution(robot_box, options);
  const double spacing = options.frame_spacing != 0
                             ? options.frame_spacing
                             : std::min(robot_box.x1 - robot_box.x0, robot_box.y1 - robot_box.y0) / 8.0;
  const std::vector<size_t> used = select_frames(frames, extrinsics.t_vc().head<2>(), spacing);

  // Each frame's poses while its rows were read (all three its pose for a global shutter); its
  // window holds the ground seen from any of them.
  std::vector<double> times(frames.size());
  for (size_t k = 0; k < frames.size(); ++k) times[k] = dataset.timestamp(frames[k].frame);
  std::vector<std::array<SE2, 3>> row_poses;
  std::vector<Box> boxes;
  Box all;
  for (size_t k : used) {
    row_poses.push_back(readout_poses(frames, times, k, cam));
    Box b;
    for (const SE2& pose : row_poses.back()) b.add(frame_box(fp, pose));
    boxes.push_back(b);
    all.add(boxes.back());
  }
  Mosaic m;
  m.grid = make_grid(all, options);
  std::vector<Window> windows;
  for (const Box& b : boxes) windows.push_back(window_of(b, m.grid));

  m.stats.frames_given = static_cast<int64_t>(frames.size());
  m.stats.frames_used = static_cast<int64_t>(used.size());
  m.stats.gain_min = m.stats.gain_max = 1.0;
  const double decode_seconds = warp_and_blend(runtime, dataset, frames, used, row_poses, windows, setup, options, m);
  m.stats.seconds_decode = decode_seconds;
  if (options.progress) options.progress(1.0, "mosaic");
  if (m.stats.covered_pixels == 0)
    throw Error(ErrorCode::Failed, "mosaic: no frame covered a pixel of the mosaic (" + std::to_string(used.size()) +
                                       " frames placed), so there is no image to write");
  m.stats.seconds_total = seconds_since(t0);
  return m;
}

namespace {

// An image encoded by its path's extension and written through OutputFile, complete or not at
// all: InvalidArgument for a format OpenCV cannot write, Io naming the file when writing fails.
void write_image(const std::string& path, const cv::Mat& image, const std::vector<int>& params) {
  const std::string extension = std::filesystem::path(path).extension().string();
  std::vector<uint8_t> bytes;
  try {
    if (!cv::imencode(extension, image, bytes, params)) throw Error(ErrorCode::Io, "cannot encode " + path);
  } catch (const cv::Exception& e) {
    throw_invalid_argument("mosaic: cannot write an image as " + extension + " (" + path + "): " + e.what());
  }
  OutputFile file(path);
  if (std::fwrite(bytes.data(), 1, bytes.size(), file.stream()) != bytes.size())
    throw Error(ErrorCode::Io, "cannot write " + path);
  file.commit();
}

}  // namespace

void save_mosaic(const Mosaic& mosaic, const std::string& image_path) {
  namespace fs = std::filesystem;
  const fs::path img(image_path);
  if (img.extension().empty())
    throw_invalid_argument("mosaic: the image path " + image_path + " has no extension (.png, say)");
  const fs::path yaml = fs::path(img).replace_extension(".yaml");
  if (yaml == img) throw_invalid_argument("mosaic: the image cannot be a .yaml file");
  // Both files through OutputFile: each appears complete or not at all, the image first, so a
  // YAML never names a missing or partial image. PNG at zlib level 1 (OpenCV's default is 3):
  // the mosaic of the 20-s simulated drive is 17% larger, and written faster.
  write_image(image_path, mosaic.image, {cv::IMWRITE_PNG_COMPRESSION, 1});
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << "# planarvo mosaic: the ground under the trajectory, placed as ROS map_server reads a map.\n"
      << "# origin: the lower-left corner of the lower-left pixel [x, y, yaw] in the trajectory's frame;\n"
      << "# row 0 of the image is its top (+y), columns run along +x. 0: unseen; 1..255: the ground.\n";
  out << "image: " << img.filename().string() << "\n";
  out << "resolution: " << shortest(mosaic.grid.resolution) << "\n";
  out << "origin: [" << shortest(mosaic.grid.origin.x()) << ", " << shortest(mosaic.grid.origin.y()) << ", 0.0]\n";
  // Loaded as a map (map_server, nav2's map_server: occ = (255 - p) / 255 with negate 0, occupied
  // when occ > occupied_thresh, free when occ < free_thresh, else unknown in trinary mode): a seen
  // pixel (1..255: occ <= 254/255 = 0.99608) is free, an unseen one (0: occ = 1) unknown, never
  // occupied (occ is never over 1). The image stays the floor's picture.
  out << "mode: trinary\nnegate: 0\noccupied_thresh: 1.0\nfree_thresh: 0.998\n";
  const std::string text = out.str();
  OutputFile yaml_file(yaml.string());
  if (std::fwrite(text.data(), 1, text.size(), yaml_file.stream()) != text.size())
    throw Error(ErrorCode::Io, "cannot write " + yaml.string());
  yaml_file.commit();
}

cv::Mat contrast_preview(const cv::Mat& image) {
  if (image.type() != CV_8UC1) throw_invalid_argument("mosaic preview: needs an 8-bit grey image");
  // The seen pixels' grey levels from their 1st to their 99th percentile stretched over 1..255.
  int histogram[256] = {};
  int64_t seen = 0;
  for (int r = 0; r < image.rows; ++r) {
    const uint8_t* p = image.ptr<uint8_t>(r);
    for (int c = 0; c < image.cols; ++c) {
      ++histogram[p[c]];
      seen += p[c] != 0;
    }
  }
  cv::Mat out = image.clone();
  if (seen == 0) return out;
  int lo = 1, hi = 255;
  int64_t below = 0;
  for (int v = 1; v < 256; ++v) {
    below += histogram[v];
    if (below <= seen / 100) lo = v + 1;
    if (below < seen - seen / 100) hi = v + 1;
  }
  lo = std::min(lo, 255);
  hi = std::max(std::min(hi, 255), lo + 1);
  uint8_t lut[256];
  lut[0] = 0;
  for (int v = 1; v < 256; ++v) {
    const double t = (static_cast<double>(v) - lo) / (hi - lo);
    lut[v] = static_cast<uint8_t>(std::lround(1.0 + 254.0 * std::min(1.0, std::max(0.0, t))));
  }
  for (int r = 0; r < out.rows; ++r) {
    uint8_t* p = out.ptr<uint8_t>(r);
    for (int c = 0; c < out.cols; ++c) p[c] = lut[p[c]];
  }
  return out;
}

void save_preview(const Mosaic& mosaic, const std::string& path) {
  write_image(path, contrast_preview(mosaic.image), {});
}

}  // namespace planarvo::mosaic
