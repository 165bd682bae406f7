#include "common.h"

#include <filesystem>

#include <cmath>
#include <cstdio>
#include <unistd.h>

namespace planarvo::cli {

int ApiError::exit_code() const {
  switch (status) {
    case PLANARVO_ERROR_INVALID_ARGUMENT:
    case PLANARVO_ERROR_INVALID_INPUT:
    case PLANARVO_ERROR_IO:
      return kExitUsage;
    case PLANARVO_ERROR_NO_DEVICE:
      return kExitNoDevice;
    default:
      return kExitFailed;
  }
}

void check(planarvo_status status) {
  if (status != PLANARVO_OK) throw ApiError(status, planarvo_last_error());
}

std::vector<OptionSpec> device_options() {
  return {
      {"device", "SEL", "OpenCL device: index or name substring (see `planarvo devices`)",
       "$PLANARVO_DEVICE, else first GPU/accelerator, else CPU"},
      {"kernel-binaries", "DIR", "load prebuilt kernel binaries from DIR; never compile", ""},
      {"cache-dir", "DIR", "kernel program cache directory",
       "$PLANARVO_CACHE_DIR, else none with PoCL (which caches compiled kernels itself), else ~/.cache/planarvo, "
       "else $TMPDIR/planarvo-UID/programs"},
      {"no-cache", "", "do not use the kernel program cache", ""},
  };
}

ContextPtr make_context(const Args& args) {
  planarvo_context_options o;
  planarvo_context_options_init(&o);
  const std::string device = args.get("device"), bins = args.get("kernel-binaries"),
                    cache = args.get("cache-dir");
  if (!device.empty()) o.device = device.c_str();
  if (!bins.empty()) o.kernel_binaries_dir = bins.c_str();
  if (!cache.empty()) o.cache_dir = cache.c_str();
  o.disable_cache = args.has("no-cache") ? 1 : 0;
  planarvo_context* c = nullptr;
  check(planarvo_context_create(&o, &c));
  // The library stays silent about a cache it could not place (a service user with no home
  // and no usable temp directory); the tool says so once, since every run then compiles.
  planarvo_device_info chosen{};
  chosen.struct_size = sizeof chosen;
  check(planarvo_context_device(c, &chosen));
  if (!o.disable_cache && !o.kernel_binaries_dir && !*planarvo_context_cache_dir(c) && !chosen.driver_caches_kernels)
    std::fprintf(stderr, "planarvo: note: no writable directory for the kernel program cache (HOME, "
                         "XDG_CACHE_HOME, temp directory), so kernels are compiled on every run; set "
                         "PLANARVO_CACHE_DIR or --cache-dir, or --no-cache to silence this\n");
  return ContextPtr(c);
}

std::string device_name(const planarvo_context* context) {
  planarvo_device_info info{};
  info.struct_size = sizeof info;
  check(planarvo_context_device(context, &info));
  return std::string(info.device_name) + " (" + info.platform_name + ")";
}

OptionSpec roi_option(const char* fallback) {
  return {"roi", "x,y,w,h", "region of interest: the only pixels used (leave out the horizon, the bumper, the "
                            "sidewalk); 0,0,0,0 = the whole image", fallback};
}

std::optional<planarvo_region> parse_roi(const Args& args) {
  if (!args.has("roi")) return std::nullopt;
  const std::vector<double> v = args.get_doubles("roi", 4);
  for (double x : v)
    if (x != std::floor(x) || x < 0 || x > 1e6)
      throw UsageError("--roi needs four non-negative integers x,y,width,height, got \"" + args.get("roi") + "\"");
  const planarvo_region r{static_cast<int32_t>(v[0]), static_cast<int32_t>(v[1]), static_cast<int32_t>(v[2]),
                          static_cast<int32_t>(v[3])};
  if ((r.width == 0) != (r.height == 0) || ((r.width == 0) && (r.x != 0 || r.y != 0)))
    throw UsageError("--roi: give a width and a height, or 0,0,0,0 for the whole image, not \"" + args.get("roi") +
                     "\"");
  return r;
}

void apply_roi(const std::optional<planarvo_region>& roi, planarvo_dataset* dataset) {
  if (roi) check(planarvo_dataset_set_roi(dataset, &*roi));
}

OptionSpec force_option() {
  return {"force", "", "accept extrinsics outside the plausible ranges (an offset over 20 m, a height over 5 m, an "
                       "angle over a turn): an unusual rig, not a unit mistake", ""};
}

OptionSpec readout_option() {
  return {"readout-time", "SECONDS", "rolling shutter: seconds from the first row's read to the last's (0: a global "
                                     "shutter); overrides the camera file's rolling_shutter_readout", "camera.yaml's, else 0"};
}

std::optional<double> parse_readout(const Args& args) {
  if (!args.has("readout-time")) return std::nullopt;
  const double v = args.get_double("readout-time", 0.0);
  if (!std::isfinite(v) || v < 0)
    throw UsageError("--readout-time needs a finite number of seconds >= 0, got \"" + args.get("readout-time") + "\"");
  return v;
}

void apply_readout(const std::optional<double>& readout, planarvo_dataset* dataset) {
  if (readout) check(planarvo_dataset_set_readout(dataset, *readout, "--readout-time"));
}

namespace {

// Opens path with the source options in o and the ones every data set takes.
DatasetPtr open_with(const std::string& path, planarvo_dataset_options* o, bool verify, Progress* progress,
                     bool allow_missing) {
  o->verify_images = verify ? 1 : 0;
  o->allow_missing_images = allow_missing ? 1 : 0;
  o->progress = &Progress::callback;
  o->progress_user_data = progress;
  planarvo_dataset* d = nullptr;
  check(planarvo_dataset_open(path.c_str(), o, &d));
  return DatasetPtr(d);
}

}  // namespace

std::vector<OptionSpec> bag_options() {
  return {{"image-topic", "TOPIC", "bag: the images (sensor_msgs/Image or CompressedImage)", "the bag's only image topic"},
          {"camera-info-topic", "TOPIC", "bag: the camera (sensor_msgs/CameraInfo, plumb_bob)",
           "the bag's only CameraInfo topic, unless --camera"},
          {"camera", "FILE", "bag: the camera from an OpenCV calibration YAML instead of a CameraInfo topic", ""},
          {"odom-topic", "TOPIC", "bag: wheel odometry (nav_msgs/Odometry)", "none"},
          {"groundtruth-topic", "TOPIC", "bag: true poses (nav_msgs/Odometry), for accuracy figures", "none"},
          {"receive-time", "", "bag: time messages by when they were recorded, not by their header stamps", ""}};
}

// The library's rule (io::bag_file_for): a file, or a directory with a ROS 2 bag's metadata.yaml.
bool is_bag_path(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  return fs::is_regular_file(path, ec) || (fs::is_directory(path, ec) && fs::exists(fs::path(path) / "metadata.yaml", ec));
}

planarvo_extrinsics extrinsics_for(const Args& args, const std::string& dataset) {
  std::string path = args.get("extrinsics");
  if (path.empty() && is_bag_path(dataset))
    throw UsageError("a bag carries no extrinsics: give --extrinsics FILE (planarvo calibrate writes one)");
  if (path.empty()) {
    path = (std::filesystem::path(dataset) / "extrinsics.yaml").string();
    if (!std::filesystem::exists(path))
      throw UsageError("no --extrinsics given and " + path + " does not exist (calibrate first, or pass the file)");
  }
  planarvo_extrinsics e{};
  check(planarvo_extrinsics_load(path.c_str(), &e));
  return e;
}

DatasetPtr open_dataset(const std::string& path, const Args& args, bool verify, Progress* progress,
                        bool allow_missing) {
  if (!is_bag_path(path)) {
    for (const OptionSpec& b : bag_options())
      if (args.has(b.name))
        throw UsageError("--" + b.name + " applies to a ROS bag or MCAP file, and " + path + " is not a file");
    return open_dataset(path, args.get("video"), verify, progress, allow_missing);
  }
  if (args.has("video")) throw UsageError("--video applies to a data set folder, not to the bag " + path);
  planarvo_dataset_options o;
  planarvo_dataset_options_init(&o);
  const std::string image = args.get("image-topic"), info = args.get("camera-info-topic"),
                    camera = args.get("camera"), odom = args.get("odom-topic"), gt = args.get("groundtruth-topic");
  if (!info.empty() && !camera.empty()) throw UsageError("give --camera-info-topic or --camera, not both");
  o.image_topic = image.empty() ? nullptr : image.c_str();
  o.camera_info_topic = info.empty() ? nullptr : info.c_str();
  o.camera_yaml = camera.empty() ? nullptr : camera.c_str();
  o.odometry_topic = odom.empty() ? nullptr : odom.c_str();
  o.groundtruth_topic = gt.empty() ? nullptr : gt.c_str();
  o.use_receive_time = args.has("receive-time") ? 1 : 0;
  return open_with(path, &o, verify, progress, allow_missing);
}

DatasetPtr open_dataset(const std::string& dir, const std::string& video, bool verify, Progress* progress,
                        bool allow_missing) {
  planarvo_dataset_options o;
  planarvo_dataset_options_init(&o);
  if (!video.empty()) o.video = video.c_str();
  return open_with(dir, &o, verify, progress, allow_missing);
}

planarvo_se2 relative(const planarvo_se2& a, const planarvo_se2& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta), dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, std::remainder(b.theta - a.theta, 2 * M_PI)};
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

Progress::Progress(bool enabled) : enabled_(enabled && stderr_is_terminal()) {}
Progress::~Progress() { finish(); }

int Progress::callback(void* self, double fraction, const char* stage) {
  auto* p = static_cast<Progress*>(self);
  if (!p->enabled_) return 0;
  const int permille = static_cast<int>(fraction * 1000.0 + 0.5);
  const std::string s = stage ? stage : "";
  if (permille == p->last_permille_ && s == p->last_stage_) return 0;
  // A new stage keeps the last one's bar on its own line and starts a bar of its own.
  if (p->drawn_ && s != p->last_stage_) std::fprintf(stderr, "\n");
  p->last_permille_ = permille;
  p->last_stage_ = s;
  const int width = 30, filled = permille * width / 1000;
  std::fprintf(stderr, "\r[%s%s] %5.1f%% %-24.24s", std::string(static_cast<size_t>(filled), '#').c_str(),
               std::string(static_cast<size_t>(width - filled), ' ').c_str(), permille / 10.0, s.c_str());
  std::fflush(stderr);
  p->drawn_ = true;
  return 0;
}

void Progress::warn(const std::string& message) {
  finish();
  last_permille_ = -1;
  std::fprintf(stderr, "%s\n", message.c_str());
}

void Progress::finish() {
  if (drawn_) {
    std::fprintf(stderr, "\r%70s\r", "");
    std::fflush(stderr);
    drawn_ = false;
  }
}

}  // namespace planarvo::cli
