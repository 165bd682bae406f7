// Data set reading. Images are decoded on demand (all of them at open with verify_images).
//
// Video: frames come from cv::VideoCapture. Opening scans the whole file once with grab(), to
// count the frames and take each frame's time (CAP_PROP_POS_MSEC; index / fps when the
// container has no usable times); FFmpeg decodes in grab(), so opening costs about one decode
// of the video. Frames read in order (i, i+1, ...) cost one decode each, and the last
// kVideoCacheSize decoded frames are kept, so that re-reading a recent frame is free. Reading
// an earlier frame that is no longer cached reopens the file and grabs forward to it: O(i)
// decodes. Seeking (CAP_PROP_POS_FRAMES) is not used, because it is inexact for codecs with
// inter frames in some backends.
#include "io/dataset/dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <tuple>
#include <utility>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "core/error.h"
#include "io/bag/bag.h"
#include "io/dataset/frame_image.h"
#include "io/text.h"

namespace planarvo::io {

namespace fs = std::filesystem;

using detail::BagSource;
using detail::to_grey_checked;

namespace {

// The frames' median interval, seconds; 0 when there is none.
double median_period(const std::vector<FrameEntry>& frames) {
  std::vector<double> dt;
  for (size_t i = 1; i < frames.size(); ++i)
    if (frames[i].t > frames[i - 1].t) dt.push_back(frames[i].t - frames[i - 1].t);
  if (dt.empty()) return 0.0;
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  return dt[dt.size() / 2];
}

// A readout (or an exposure) longer than the frame interval would read a row of the next frame
// before this one's last: no camera does that, and it is what seconds given in milliseconds look
// like.
void check_shutter_time(double seconds, const char* what, const std::vector<FrameEntry>& frames,
                        const std::string& where) {
  char got[64];
  std::snprintf(got, sizeof got, "%g", seconds);
  if (!std::isfinite(seconds) || seconds < 0)
    throw_invalid_input(where + ": the " + what + " must be a finite number of seconds >= 0, not " + got);
  const double period = median_period(frames);
  if (period > 0 && seconds > period) {
    char msg[160];
    std::snprintf(msg, sizeof msg, "%s s is longer than the frames' interval, %g s (the median; seconds, not "
                  "milliseconds)", got, period);
    throw_invalid_input(where + ": the " + what + " " + msg);
  }
}

void check_readout(double readout, const std::vector<FrameEntry>& frames, const std::string& where) {
  check_shutter_time(readout, "rolling shutter readout", frames, where);
}

constexpr size_t kVideoCacheSize = 4;

class Progress {
 public:
  explicit Progress(const ProgressCallback& cb) : cb_(cb) {}
  void report(double fraction, const char* stage) const {
    if (cb_ && !cb_(std::clamp(fraction, 0.0, 1.0), stage))
      throw Error(ErrorCode::Cancelled, std::string("opening the data set was cancelled while ") + stage);
  }

 private:
  const ProgressCallback& cb_;
};

cv::Mat read_image(const fs::path& file, const CameraModel& camera, const std::string& context) {
  const std::string name = file.string();
  if (const std::string problem = detail::input_file_problem(name); !problem.empty())
    throw_invalid_input(name + ": the image " + problem + " (" + context + ")");
  // Read once: the bytes are checked (cut short, a declared size that is not the camera's) and
  // then decoded from memory.
  std::ifstream in(name, std::ios::binary);
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) throw_invalid_input(name + ": the image cannot be read (" + context + ")");
  if (const std::string problem = detail::encoded_image_problem(bytes.data(), bytes.size(), camera); !problem.empty())
    throw_invalid_input(name + ": " + problem + " (" + context + ")");
  cv::Mat img;
  try {
    // ANYDEPTH so that 16-bit images are seen (and rejected) rather than silently scaled;
    // ANYCOLOR keeps grey images one channel. EXIF orientation is applied, as by cv::imread's
    // default, so images look as they did to the calibration.
    if (!bytes.empty()) img = cv::imdecode(bytes, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
  } catch (const cv::Exception& e) {
    throw_invalid_input(name + ": the image cannot be decoded (" + context + "): " + e.err);
  }
  if (img.empty())
    throw_invalid_input(name + ": the image cannot be decoded (" + context + ")");
  return to_grey_checked(img, camera, name, context);
}

// The frames of a video file, with the cost model described at the top of this file.
class VideoSource {
 public:
  VideoSource(std::string path, const CameraModel& camera, bool verify, const Progress& progress,
              double progress_from)
      : path_(std::move(path)), camera_(camera) {
    if (const std::string problem = detail::input_file_problem(path_); !problem.empty())
      throw_invalid_input(path_ + ": the video " + problem);
    open_first_backend();
    const int64_t packets = find_cut_jpeg_frames();
    const double fps = cap_.get(cv::CAP_PROP_FPS);
    const double count_hint = cap_.get(cv::CAP_PROP_FRAME_COUNT);
    // OpenCV's own MJPEG reader reports the time after the grabbed frame, not its start.
    const bool time_after_frame = cap_.getBackendName() == "CV_MJPEG";
    std::vector<double> msec;
    while (cap_.grab()) {
      const int64_t i = static_cast<int64_t>(msec.size());
      msec.push_back(cap_.get(cv::CAP_PROP_POS_MSEC));
      // The first frame is always decoded: a size mismatch is found at open, and it is cached
      // for the first read.
      if (verify || i == 0) remember(i, retrieve(i));
      // The container's frame count is a hint (it may be missing or wrong), so never 1 here.
      const double done = count_hint > 0 ? std::min(0.99, static_cast<double>(i + 1) / count_hint) : 0.0;
      progress.report(progress_from + (1.0 - progress_from) * done,
                      verify ? "decoding video" : "scanning video");
    }
    next_ = static_cast<int64_t>(msec.size());
    if (msec.empty()) throw_invalid_input(path_ + ": the video has no frames that can be read");
    // Packets and frames are one to one for JPEG frames; if they are not, the indices say nothing.
    if (packets != next_) cut_frames_.clear();

    bool usable = true;
    for (size_t i = 0; i < msec.size(); ++i)
      if (!std::isfinite(msec[i]) || (i > 0 && !(msec[i] > msec[i - 1]))) usable = false;
    if (usable) {
      const double shift = time_after_frame && fps > 0 ? 1000.0 / fps : 0.0;
      for (double m : msec) times_.push_back((m - shift) / 1000.0);
    } else if (std::isfinite(fps) && fps > 0) {
      for (size_t i = 0; i < msec.size(); ++i) times_.push_back(static_cast<double>(i) / fps);
    } else {
      throw_invalid_input(path_ + ": the video has neither increasing frame times nor a frame rate");
    }
  }

  const std::vector<double>& times() const { return times_; }

  cv::Mat frame(int64_t i) {
    for (const auto& [index, image] : cache_)
      if (index == i) return image;
    if (i < next_) {
      open(api_);
      next_ = 0;
    }
    for (; next_ < i; ++next_)
      if (!cap_.grab()) fail_read(next_);
    if (!cap_.grab()) fail_read(i);
    next_ = i + 1;
    cv::Mat grey = retrieve(i);
    remember(i, grey);
    return grey;
  }

  std::string name(int64_t i) const { return path_ + " frame " + std::to_string(i); }

 private:
  // FFmpeg, else OpenCV's own MJPEG reader; other backends only when neither is built in.
  // (CAP_ANY would also try GStreamer and image sequences, which log errors for a bad file.)
  void open_first_backend() {
    std::vector<int> apis;
    for (cv::VideoCaptureAPIs api : {cv::CAP_FFMPEG, cv::CAP_OPENCV_MJPEG})
      if (cv::videoio_registry::hasBackend(api)) apis.push_back(api);
    if (apis.empty()) apis.push_back(cv::CAP_ANY);
    for (int api : apis)
      if (try_open(api)) {
        api_ = api == cv::CAP_ANY ? static_cast<int>(cap_.get(cv::CAP_PROP_BACKEND)) : api;
        return;
      }
    throw_invalid_input(path_ + ": the video cannot be opened (not a video OpenCV's FFmpeg or "
                        "MJPEG reader can decode)");
  }

  bool try_open(int api) {
    cap_.release();
    try {
      return cap_.open(path_, api) && cap_.isOpened();
    } catch (const cv::Exception&) {
      return false;
    }
  }

  void open(int api) {
    if (!try_open(api)) throw_invalid_input(path_ + ": the video cannot be opened again");
  }

  // An MJPEG video's frames are JPEG images, and FFmpeg decodes one that was cut short with only
  // a warning and grey rows where its data stop (issue 27). In FFmpeg's raw mode the packets
  // come undecoded, so each is checked as an image file is (truncation_problem): one pass that
  // only demuxes, at open. Returns the number of packets, or -1 when the check does not apply:
  // not FFmpeg (OpenCV's own MJPEG reader has no raw mode), or frames that are not JPEG images
  // (other codecs are left to their decoders).
  int64_t find_cut_jpeg_frames() {
    if (api_ != cv::CAP_FFMPEG) return -1;
    cv::VideoCapture raw;
    try {
      if (!raw.open(path_, cv::CAP_FFMPEG) || !raw.set(cv::CAP_PROP_FORMAT, -1)) return -1;
      cv::Mat packet;
      int64_t i = 0;
      for (; raw.grab(); ++i) {
        if (!raw.retrieve(packet) || packet.empty() || !packet.isContinuous()) return -1;
        const auto* p = packet.ptr<unsigned char>();
        const size_t n = packet.total() * packet.elemSize();
        if (i == 0 && !(n >= 3 && p[0] == 0xFF && p[1] == 0xD8 && p[2] == 0xFF)) return -1;
        if (std::string cut = detail::truncation_problem(p, n); !cut.empty()) cut_frames_.emplace_back(i, cut);
      }
      return i;
    } catch (const cv::Exception&) {
      cut_frames_.clear();
      return -1;
    }
  }

  cv::Mat retrieve(int64_t i) {
    for (const auto& [index, cut] : cut_frames_)
      if (index == i) throw_invalid_input(path_ + ": frame " + std::to_string(i) + " of the video: " + cut);
    cv::Mat img;
    if (!cap_.retrieve(img) || img.empty())
      throw_invalid_input(path_ + ": frame " + std::to_string(i) + " of the video cannot be decoded");
    cv::Mat grey = to_grey_checked(img, camera_, path_, "frame " + std::to_string(i));
    return grey.data == img.data ? grey.clone() : grey;  // the capture reuses its buffer
  }

  void remember(int64_t i, const cv::Mat& image) {
    if (cache_.size() == kVideoCacheSize) cache_.pop_front();
    cache_.emplace_back(i, image);
  }

  [[noreturn]] void fail_read(int64_t i) const {
    throw_invalid_input(path_ + ": frame " + std::to_string(i) +
                        " of the video cannot be read (did the file change after it was opened?)");
  }

  std::string path_;
  CameraModel camera_;
  cv::VideoCapture cap_;
  int api_ = cv::CAP_ANY;
  int64_t next_ = 0;  // the index the next grab() returns
  std::vector<double> times_;
  std::deque<std::pair<int64_t, cv::Mat>> cache_;
  std::vector<std::pair<int64_t, std::string>> cut_frames_;  // JPEG frames cut short, and why
};

}  // namespace

std::optional<SE2> interpolate_pose(const std::vector<StampedPose>& samples, double t) {
  if (samples.empty() || !(t >= samples.front().t) || !(t <= samples.back().t)) return std::nullopt;
  const auto it = std::lower_bound(samples.begin(), samples.end(), t,
                                   [](const StampedPose& s, double v) { return s.t < v; });
  if (it->t == t) return it->pose;
  const StampedPose& a = *(it - 1);
  const StampedPose& b = *it;
  // Finite samples give a finite pose, however far apart (found by fuzzing: x = -1e308 and 1e308
  // gave inf): the fraction from halved times when the span overflows, and x, y as a convex
  // combination rather than a + f (b - a), whose difference overflows.
  const double span = b.t - a.t;
  double f = std::isfinite(span) ? (t - a.t) / span : (0.5 * t - 0.5 * a.t) / (0.5 * b.t - 0.5 * a.t);
  f = std::clamp(f, 0.0, 1.0);
  return SE2((1.0 - f) * a.pose.x + f * b.pose.x, (1.0 - f) * a.pose.y + f * b.pose.y,
             interpolate_linear(a.pose, b.pose, f).theta);
}

std::optional<int> direction_at(const std::vector<DirectionLabel>& labels, double t) {
  // The first label with t_k >= t: its interval (t_{k-1}, t_k] contains t.
  const auto it = std::lower_bound(labels.begin(), labels.end(), t,
                                   [](const DirectionLabel& l, double v) { return l.t < v; });
  if (it == labels.end()) return std::nullopt;
  return it->sign;
}

struct Dataset::Impl {
  std::string directory;
  fs::path dir;
  CameraModel camera;
  std::vector<FrameEntry> frames;
  std::string frames_file;
  bool has_odometry = false, has_groundtruth = false, has_direction = false;
  bool readout_given = false;  // the camera file or set_rolling_shutter_readout gave it
  std::vector<StampedPose> odometry, groundtruth;
  std::vector<DirectionLabel> direction;
  std::optional<ExtrinsicsEstimate> extrinsics, extrinsics_gt;
  std::unique_ptr<VideoSource> video;
  std::unique_ptr<BagSource> bag;

  // Read-ahead of image files: while frames are asked for in order, the next one is decoded on a
  // worker thread beside the caller's work (PNG decoding was a quarter of a 20-s calibration).
  // The worker holds copies of what it reads, so nothing here is shared with it.
  int64_t last_index = -1, ahead_index = -1;
  std::future<cv::Mat> ahead;

  std::string context(int64_t i) const {
    return "frame " + std::to_string(i) + ", " + detail::where(frames_file, frames[static_cast<size_t>(i)].line);
  }
  cv::Mat read(int64_t i) const { return read_image(dir / frames[static_cast<size_t>(i)].path, camera, context(i)); }
  void read_ahead(int64_t i) {
    ahead = std::async(std::launch::async, [path = dir / frames[static_cast<size_t>(i)].path, cam = camera,
                                            where = context(i)] { return read_image(path, cam, where); });
    ahead_index = i;
  }
  // Waits for a read-ahead no longer wanted and forgets it, its error too (the frame it failed
  // on was not asked for).
  void drop_ahead() {
    if (ahead.valid()) {
      try {
        ahead.get();
      } catch (...) {  // NOLINT(bugprone-empty-catch): reported when that frame is asked for
      }
    }
    ahead_index = -1;
  }
  ~Impl() { drop_ahead(); }
};

namespace {

// Samples (poses or labels, in time order) that apply to no frame are almost always a clock or
// unit mismatch: InvalidInput "<what> [first, last] apply to no frame; <hint>".
template <typename T, typename Applies>
void require_some_frame(const std::vector<T>& samples, Applies applies, int64_t frame_count, const std::string& what,
                        const char* hint) {
  for (int64_t i = 0; i < frame_count; ++i)
    if (applies(i)) return;
  throw_invalid_input(what + " [" + detail::format_exact(samples.front().t) + ", " +
                      detail::format_exact(samples.back().t) + "] apply to no frame; " + hint);
}

// Optional trajectory/label files: absent is fine; present must be valid, non-empty and must
// apply to at least one frame (a file that applies to none is almost always a clock or unit
// mismatch, e.g. milliseconds against seconds).
template <typename T, typename Reader, typename Applies>
bool read_optional(const fs::path& file, std::vector<T>& out, Reader reader, Applies applies,
                   int64_t frame_count, const char* what) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return false;
  out = reader(file.string());
  if (out.empty()) throw_invalid_input(file.string() + ": has no " + what + " (only comments or blank lines)");
  require_some_frame(out, applies, frame_count, file.string() + ": its times",
                     "are they on the frames' clock, in seconds?");
  return true;
}

}  // namespace

Dataset::Dataset(const std::string& directory, DatasetOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  const Progress progress(options.progress);
  progress.report(0.0, "reading data set files");
  d.directory = directory;
  d.dir = fs::path(directory);
  std::error_code ec;
  if (!fs::exists(d.dir, ec)) throw_invalid_input(directory + ": the data set directory does not exist");
  if (const std::optional<std::string> bag_file = bag_file_for(directory)) {
    open_bag(*bag_file, options);
    return;
  }
  if (!fs::is_directory(d.dir, ec))
    throw_invalid_input(directory + ": neither a data set directory nor a ROS 1 bag or MCAP file");
  const BagDatasetOptions& b = options.bag;
  if (!b.image_topic.empty() || !b.camera_info_topic.empty() || !b.camera_yaml.empty() ||
      !b.odometry_topic.empty() || !b.groundtruth_topic.empty() || b.use_receive_time)
    throw_invalid_input(directory + ": a data set directory, but topics, a camera file or receive times were given, "
                        "which apply to bags only");

  d.camera = read_camera_yaml((d.dir / "camera.yaml").string(), &d.readout_given);

  // The text files first, so that a typo is reported before the long part.
  constexpr double kTextShare = 0.05;
  if (options.video.empty()) {
    d.frames_file = (d.dir / "frames.txt").string();
    if (!fs::exists(d.frames_file, ec))
      throw_invalid_input(d.frames_file + ": does not exist (a data set needs frames.txt and "
                          "images/, or a video)");
    d.frames = read_frames(d.frames_file);
    if (d.frames.empty()) throw_invalid_input(d.frames_file + ": lists no frames");
    // A stat per image is cheap and finds a misspelt path now, not an hour into a run.
    for (size_t i = 0; i < d.frames.size() && !options.allow_missing_images; ++i) {
      const std::string file = (d.dir / d.frames[i].path).string();
      if (const std::string problem = detail::input_file_problem(file); !problem.empty())
        throw_invalid_input(file + ": the image " + problem + " (" + d.context(static_cast<int64_t>(i)) + ")");
    }
  } else {
    d.video = std::make_unique<VideoSource>(options.video, d.camera, options.verify_images,
                                            progress, kTextShare);
    for (double t : d.video->times()) d.frames.push_back({t, std::string(), 0});
  }
  const int64_t n = static_cast<int64_t>(d.frames.size());
  check_readout(d.camera.rolling_shutter_readout, d.frames, (d.dir / "camera.yaml").string());
  check_shutter_time(d.camera.exposure_time, "exposure time", d.frames, (d.dir / "camera.yaml").string());

  d.has_odometry = read_optional(
      d.dir / "odometry.txt", d.odometry, read_tum,
      [&](int64_t i) { return interpolate_pose(d.odometry, d.frames[static_cast<size_t>(i)].t).has_value(); },
      n, "poses");
  d.has_groundtruth = read_optional(
      d.dir / "groundtruth.txt", d.groundtruth, read_tum,
      [&](int64_t i) { return interpolate_pose(d.groundtruth, d.frames[static_cast<size_t>(i)].t).has_value(); },
      n, "poses");
  // With one frame there is no interval for a label to apply to.
  d.has_direction = read_optional(
      d.dir / "direction.txt", d.direction, read_direction,
      [&](int64_t i) {
        if (n == 1) return true;
        if (i == 0) return false;
        const auto& f = d.frames;
        return direction_at(d.direction, 0.5 * (f[size_t(i) - 1].t + f[size_t(i)].t)).has_value();
      },
      n, "labels");
  if (fs::exists(d.dir / "extrinsics.yaml", ec))
    d.extrinsics = read_extrinsics_yaml((d.dir / "extrinsics.yaml").string());
  if (fs::exists(d.dir / "extrinsics_gt.yaml", ec))
    d.extrinsics_gt = read_extrinsics_yaml((d.dir / "extrinsics_gt.yaml").string());

  if (options.verify_images && !d.video) {
    for (int64_t i = 0; i < n; ++i) {
      progress.report(kTextShare + (1.0 - kTextShare) * static_cast<double>(i) / static_cast<double>(n),
                      "verifying images");
      d.read(i);
    }
  }
  progress.report(1.0, "done");
}

void Dataset::open_bag(const std::string& file, const DatasetOptions& options) {
  Impl& d = *impl_;
  const Progress progress(options.progress);
  d.bag = std::make_unique<BagSource>(file, options.bag, options.verify_images,
                                      [&](double f, const char* stage) { progress.report(f, stage); });
  d.camera = d.bag->camera();
  d.readout_given = d.bag->readout_given();
  d.frames = d.bag->frames();
  const std::string camera_source = options.bag.camera_yaml.empty() ? file + ": the camera" : options.bag.camera_yaml;
  check_readout(d.camera.rolling_shutter_readout, d.frames, camera_source);
  check_shutter_time(d.camera.exposure_time, "exposure time", d.frames, camera_source);
  d.odometry = d.bag->odometry();
  d.groundtruth = d.bag->groundtruth();
  const int64_t n = static_cast<int64_t>(d.frames.size());
  for (auto [samples, has, option] : {std::tuple{&d.odometry, &d.has_odometry, "--odom-topic"},
                                      std::tuple{&d.groundtruth, &d.has_groundtruth, "--groundtruth-topic"}}) {
    *has = !samples->empty();
    if (!*has) continue;
    // A lambda may not capture a structured binding before C++20 (clang 14 refuses it).
    const std::vector<StampedPose>& poses = *samples;
    require_some_frame(
        poses, [&](int64_t i) { return interpolate_pose(poses, d.frames[static_cast<size_t>(i)].t).has_value(); },
        n, d.directory + ": the " + option + " messages' times (s after the first frame)",
        "are both stamped on the same clock?");
  }
  progress.report(1.0, "done");
}

Dataset::~Dataset() = default;
Dataset::Dataset(Dataset&&) noexcept = default;
Dataset& Dataset::operator=(Dataset&&) noexcept = default;

void Dataset::check_index(int64_t i, const char* what) const {
  if (i < 0 || i >= frame_count())
    throw_invalid_argument(std::string(what) + ": frame index " + std::to_string(i) +
                           " is outside [0, " + std::to_string(frame_count()) + ")");
}

const std::string& Dataset::directory() const { return impl_->directory; }
const CameraModel& Dataset::camera() const { return impl_->camera; }

void Dataset::set_rolling_shutter_readout(double seconds, const std::string& where) {
  check_readout(seconds, impl_->frames, where);
  impl_->camera.rolling_shutter_readout = seconds;
  impl_->readout_given = true;
}

void Dataset::set_region_of_interest(const PixelRegion& roi) {
  CameraModel c = impl_->camera;
  c.roi = roi;
  c.validate("the data set's camera");
  impl_->camera = c;
}
bool Dataset::is_video() const { return impl_->video != nullptr; }
bool Dataset::is_bag() const { return impl_->bag != nullptr; }
int64_t Dataset::time_origin_ns() const { return impl_->bag ? impl_->bag->time_origin_ns() : 0; }
int64_t Dataset::frame_count() const { return static_cast<int64_t>(impl_->frames.size()); }
const std::vector<FrameEntry>& Dataset::frames() const { return impl_->frames; }

double Dataset::timestamp(int64_t i) const {
  check_index(i, "Dataset::timestamp");
  return impl_->frames[static_cast<size_t>(i)].t;
}

std::string Dataset::frame_source(int64_t i) const {
  check_index(i, "Dataset::frame_source");
  if (impl_->video) return impl_->video->name(i);
  if (impl_->bag) return impl_->bag->name(i);
  return (impl_->dir / impl_->frames[static_cast<size_t>(i)].path).string();
}

cv::Mat Dataset::frame(int64_t i) {
  check_index(i, "Dataset::frame");
  if (impl_->video) return impl_->video->frame(i);
  if (impl_->bag) return impl_->bag->frame(i);
  Impl& d = *impl_;
  cv::Mat f;
  if (d.ahead.valid() && d.ahead_index == i) {
    d.ahead_index = -1;
    f = d.ahead.get();  // its error, if decoding failed
  } else {
    d.drop_ahead();
    f = d.read(i);
  }
  const bool in_order = i == d.last_index + 1;
  d.last_index = i;
  if (in_order && i + 1 < frame_count()) d.read_ahead(i + 1);
  return f;
}

bool Dataset::has_odometry() const { return impl_->has_odometry; }
bool Dataset::readout_given() const { return impl_->readout_given; }
const std::vector<StampedPose>& Dataset::odometry() const { return impl_->odometry; }
std::optional<SE2> Dataset::odometry_at(int64_t i) const {
  return interpolate_pose(impl_->odometry, timestamp(i));
}

bool Dataset::has_groundtruth() const { return impl_->has_groundtruth; }
const std::vector<StampedPose>& Dataset::groundtruth() const { return impl_->groundtruth; }
std::optional<SE2> Dataset::groundtruth_at(int64_t i) const {
  return interpolate_pose(impl_->groundtruth, timestamp(i));
}

bool Dataset::has_direction() const { return impl_->has_direction; }
const std::vector<DirectionLabel>& Dataset::direction_labels() const { return impl_->direction; }
std::optional<int> Dataset::direction_for_interval(int64_t i) const {
  check_index(i, "Dataset::direction_for_interval");
  if (i == 0) return std::nullopt;
  const auto& f = impl_->frames;
  return direction_at(impl_->direction, 0.5 * (f[static_cast<size_t>(i) - 1].t + f[static_cast<size_t>(i)].t));
}

const std::optional<ExtrinsicsEstimate>& Dataset::extrinsics() const { return impl_->extrinsics; }
const std::optional<ExtrinsicsEstimate>& Dataset::extrinsics_gt() const { return impl_->extrinsics_gt; }

}  // namespace planarvo::io
