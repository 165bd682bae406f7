// Shared pieces of the planarvo tool's commands: exit codes, the C API call checker, the context
// options every device-using command accepts, and the terminal progress bar.
#pragma once
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "args.h"
#include "planarvo/planarvo.h"

namespace planarvo::cli {

// Exit codes (docs/outputs.md).
enum Exit { kExitOk = 0, kExitFailed = 1, kExitUsage = 2, kExitNoDevice = 3 };

// A failed C API call: main() prints "planarvo: <message>" and exits with exit_code().
struct ApiError : std::runtime_error {
  ApiError(planarvo_status s, const std::string& m) : std::runtime_error(m), status(s) {}
  int exit_code() const;
  planarvo_status status;
};

// Throws ApiError with planarvo_last_error() when status is not PLANARVO_OK.
void check(planarvo_status status);

// --device, --kernel-binaries, --cache-dir, --no-cache.
std::vector<OptionSpec> device_options();
struct ContextDeleter {
  void operator()(planarvo_context* c) const { planarvo_context_destroy(c); }
};
using ContextPtr = std::unique_ptr<planarvo_context, ContextDeleter>;
ContextPtr make_context(const Args& args);
std::string device_name(const planarvo_context* context);

// A progress bar on stderr when it is a terminal and --quiet is not given; silent otherwise.
class Progress {
 public:
  explicit Progress(bool enabled);
  ~Progress();
  static int callback(void* self, double fraction, const char* stage);
  void finish();
  // A warning line on stderr, above the bar (which the next callback redraws).
  void warn(const std::string& message);

 private:
  bool enabled_;
  bool drawn_ = false;
  int last_permille_ = -1;
  std::string last_stage_;
};
bool stderr_is_terminal();

struct DatasetDeleter {
  void operator()(planarvo_dataset* d) const { planarvo_dataset_destroy(d); }
};
using DatasetPtr = std::unique_ptr<planarvo_dataset, DatasetDeleter>;
// --roi x,y,width,height: the camera's region of interest (integers; all zero: the whole image).
OptionSpec roi_option(const char* fallback);
// Parsed and checked for form (the image size is checked where the camera is known); nullopt
// without the option.
std::optional<planarvo_region> parse_roi(const Args& args);
// Applies a parsed --roi, when given, to an open data set's camera.
void apply_roi(const std::optional<planarvo_region>& roi, planarvo_dataset* dataset);
// --readout-time SECONDS: the camera's rolling-shutter readout, overriding camera.yaml's
// rolling_shutter_readout (0: a global shutter).
OptionSpec readout_option();
// --force: extrinsics outside the plausible ranges let through (accept_unusual_extrinsics).
OptionSpec force_option();
// The value when given: UsageError unless a finite number >= 0 (the data set checks it against
// the frame interval in apply_readout, naming the option).
std::optional<double> parse_readout(const Args& args);
void apply_readout(const std::optional<double>& readout, planarvo_dataset* dataset);

// allow_missing: a missing image is found when its frame is read, not at open (--skip-bad-frames).
// The options that read a ROS 1 bag or MCAP file given as DATASET: topics, camera, timing.
std::vector<OptionSpec> bag_options();
// DATASET opened with the options of args that apply to it (--video, bag_options()).
DatasetPtr open_dataset(const std::string& path, const Args& args, bool verify, Progress* progress,
                        bool allow_missing = false);
// True when path is a file (a bag), not a data set folder.
bool is_bag_path(const std::string& path);
// The camera's extrinsics for a command on a data set: --extrinsics FILE, else
// DATASET/extrinsics.yaml (a bag carries none, so it needs the option); UsageError when neither is
// there, ApiError when the file does not read.
planarvo_extrinsics extrinsics_for(const Args& args, const std::string& dataset);
DatasetPtr open_dataset(const std::string& dir, const std::string& video, bool verify, Progress* progress,
                        bool allow_missing = false);

// Tracks every frame of a data set (cmd_track.cpp), for `track` and `demo`.
struct TrackRun {
  int64_t frames = 0, ok = 0, degraded = 0, lost = 0, keyframes = 0;
  int64_t skipped = 0;           // bad images skipped (TrackOutputs::skip_bad_frames); not in frames
  double engine_ms = 0;          // sum of the per-frame engine times
  std::vector<double> ms;        // per frame
  // Lost frames in time: the intervals that end at a Lost frame, in all and the longest run of
  // consecutive ones (its first frame's timestamp).
  double lost_seconds = 0;
  int64_t longest_lost_run = 0;
  double longest_lost_seconds = 0, longest_lost_start = 0;
  // Accuracy against ground truth over every interval (Lost and Degraded included), and per
  // status of the interval's end frame: by_status[0] Ok, [1] Degraded, [2] Lost.
  bool has_accuracy = false;
  planarvo_motion_accuracy accuracy{};
  planarvo_motion_accuracy by_status[3]{};
  // With the local plane: the vehicle's lean fitted over the frames not lost.
  bool has_lean = false;
  planarvo_body_lean lean{};
  // Changes of the camera's mounting found (planarvo_track_result.mounting_changed), each warned of
  // as it came.
  int64_t mounting_changes = 0;
  // Frames (not Lost) whose attitude the images did not separate from the motion.
  int64_t attitude_unobserved = 0;
};
struct TrackOutputs {
  std::string trajectory, stats;  // "" for none
  std::string motions;            // motion-pair CSV of the tracked intervals, "" for none
  // A missing or undecodable image (or one of the wrong size) is a gap: a warning, a "skipped"
  // row in the statistics, no pose; the next frame is tracked against the last good one. When
  // false it is an error (exit 2, naming the frame).
  bool skip_bad_frames = false;
  // The photometric model (the light fixed to the camera) as a flat-field PNG after tracking,
  // "" for none; a warning, not an error, when none was learnt.
  std::string flat_field;
  // The local plane's attitude per tracked frame (plane.txt), "" for none.
  std::string plane;
  // The camera's mounting as the drive ended (extrinsics YAML: the one given, or the last change
  // of it the local plane found), "" for none.
  std::string mounting;
};
// The median of the per-frame engine times, ms (0 without frames).
double median_ms(const TrackRun& run);
TrackRun track_dataset(planarvo_context* ctx, planarvo_dataset* ds, const planarvo_extrinsics& extrinsics,
                       const planarvo_tracker_options& options, const TrackOutputs& outputs, Progress* progress);
void print_track_run(const TrackRun& run);

// The camera calibration of a data set (cmd_calibrate.cpp), for `calibrate` and `demo`, with the
// progress bar: *result filled, status PLANARVO_OK or PLANARVO_ERROR_FAILED (the result says
// why); any other status is thrown.
planarvo_status calibrate_dataset(planarvo_context* ctx, planarvo_dataset* ds,
                                  planarvo_camera_calibration_options* options, Progress* progress,
                                  planarvo_camera_calibration_result* result);

// The motion from pose a to pose b, in a's frame (a^-1 b).
planarvo_se2 relative(const planarvo_se2& a, const planarvo_se2& b);

// Each command: returns the exit code; throws UsageError or ApiError.
struct Command {
  const char* name;
  const char* summary;
  int (*run)(int argc, char** argv);  // argv[0] is the command's name
};
const std::vector<Command>& commands();

int cmd_devices(int argc, char** argv);
int cmd_kernels(int argc, char** argv);
int cmd_simulate(int argc, char** argv);
int cmd_info(int argc, char** argv);
int cmd_demo(int argc, char** argv);
int cmd_track(int argc, char** argv);
int cmd_mosaic(int argc, char** argv);
int cmd_posegraph(int argc, char** argv);
int cmd_calibrate(int argc, char** argv);
int cmd_plot(int argc, char** argv);
// calibrate DATASET (cmd_calibrate.cpp), with the graph options cmd_calibrate parsed.
int cmd_calibrate_dataset(const Args& args, const planarvo_calibration_options& graph);

}  // namespace planarvo::cli
