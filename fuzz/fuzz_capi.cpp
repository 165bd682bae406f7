// The C API with hostile arguments: random sizes, strides, NULL pointers, out-of-range enum values
// and struct_size values, non-finite numbers. The header promises that every function returns a
// status and never crashes on bad input. Each input is a short program: a byte picks a call, the
// bytes after it its arguments.
//
// One context and one tracker (a 64x48 camera) and one roll/pitch estimator are created once per
// process on the default device (PoCL in CI): creating them compiles kernels, which is slow. The
// per-frame calls are fuzzed against them. Buffers handed to the API are exactly as large as the
// arguments say (the caller's side of the contract) and heap-allocated, so that ASan sees any read
// or write past them: an output struct is sizeof the struct whatever its struct_size says.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <climits>
#include <csignal>
#include <iterator>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "fuzz_common.h"

namespace {

using planarvo_fuzz::check_status;

constexpr size_t kMaxBuffer = size_t(1) << 22;  // bytes of image or array the harness allocates

struct Device {
  planarvo_context* context = nullptr;
  planarvo_tracker* tracker = nullptr;
  planarvo_roll_pitch* roll_pitch = nullptr;
  planarvo_camera camera{};
};

Device& device() {
  static Device d = [] {
    Device s;
    planarvo_sim_default_camera(64, 48, 80.0, &s.camera);
    if (planarvo_context_create(nullptr, &s.context) != PLANARVO_OK) {
      std::fprintf(stderr, "fuzz_capi: no device (%s); the device calls are skipped\n", planarvo_last_error());
      return s;
    }
    const planarvo_extrinsics e{0.2, 0.0, 0.2, 0.1, 0.1, 0.0};
    planarvo_tracker_options o;
    planarvo_tracker_options_init(&o);
    o.levels = 2;
    if (planarvo_tracker_create(s.context, &s.camera, &e, &o, &s.tracker) != PLANARVO_OK ||
        planarvo_roll_pitch_create(s.context, &s.camera, nullptr, &s.roll_pitch) != PLANARVO_OK)
      planarvo_fuzz::broken("cannot create the tracker or the roll/pitch estimator on a valid camera");
    return s;
  }();
  return d;
}

// A number that is often one of the awkward ones.
double any_double(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange<int>(0, 7)) {
    case 0: return std::numeric_limits<double>::quiet_NaN();
    case 1: return std::numeric_limits<double>::infinity();
    case 2: return -std::numeric_limits<double>::infinity();
    case 3: return 0.0;
    case 4: return in.ConsumeFloatingPoint<double>();
    default: return in.ConsumeFloatingPointInRange<double>(-10.0, 10.0);
  }
}

int32_t any_size(FuzzedDataProvider& in, int32_t usual) {
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0: return usual;
    case 1: return in.ConsumeIntegralInRange<int32_t>(-2, 2);
    case 2: return in.ConsumeIntegral<int32_t>();
    case 3: return INT32_MAX;
    default: return in.ConsumeIntegralInRange<int32_t>(1, 200);
  }
}

// A struct_size: right, one short, zero, larger (a newer caller), or anything.
size_t any_struct_size(FuzzedDataProvider& in, size_t right) {
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0: return 0;
    case 1: return right - 1;
    case 2: return right + in.ConsumeIntegralInRange<size_t>(1, 64);
    case 3: return in.ConsumeIntegral<size_t>();
    default: return right;
  }
}

// Heap copy of T (exactly sizeof(T) bytes) with struct_size set; nullptr sometimes.
template <typename T>
std::unique_ptr<T> maybe_struct(FuzzedDataProvider& in, const T& value) {
  if (in.ConsumeIntegralInRange<int>(0, 9) == 0) return nullptr;
  auto p = std::make_unique<T>(value);
  p->struct_size = any_struct_size(in, sizeof(T));
  return p;
}

planarvo_camera any_camera(FuzzedDataProvider& in) {
  planarvo_camera c = device().camera;
  if (in.ConsumeBool()) return c;
  c.width = any_size(in, c.width);
  c.height = any_size(in, c.height);
  for (double* v : {&c.fx, &c.fy, &c.cx, &c.cy, &c.k1, &c.k2, &c.p1, &c.p2, &c.k3})
    if (in.ConsumeIntegralInRange<int>(0, 3) == 0) *v = any_double(in);
  return c;
}

// An image whose pixels the harness owns: declared size, stride and format from the input;
// data NULL when asked or when the declared bytes would exceed kMaxBuffer.
struct Image {
  planarvo_image view{};
  std::vector<uint8_t> pixels;
};
Image any_image(FuzzedDataProvider& in) {
  Image im;
  const planarvo_camera& cam = device().camera;
  im.view.width = any_size(in, cam.width);
  im.view.height = any_size(in, cam.height);
  // The format as the int a C caller may store (reading an out-of-range enum back is UB in C++).
  const int format = in.ConsumeBool() ? PLANARVO_GRAY8 : in.ConsumeIntegralInRange<int>(-1, 4);
  im.view.format = static_cast<planarvo_pixel_format>(format);
  const size_t bpp = format == PLANARVO_GRAY32F ? 4 : format == PLANARVO_GRAY8 ? 1 : 3;
  const size_t row = im.view.width > 0 ? bpp * static_cast<size_t>(im.view.width) : 0;
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0: im.view.stride = row; break;
    case 1: im.view.stride = row + in.ConsumeIntegralInRange<size_t>(1, 16); break;
    case 2: im.view.stride = row > 0 ? row - 1 : 0; break;
    default: im.view.stride = in.ConsumeIntegral<size_t>(); break;
  }
  const bool null_data = in.ConsumeIntegralInRange<int>(0, 7) == 0;
  if (!null_data && im.view.width > 0 && im.view.height > 0 && im.view.stride >= row &&
      im.view.stride <= kMaxBuffer && static_cast<size_t>(im.view.height) <= kMaxBuffer / im.view.stride) {
    const size_t bytes = im.view.stride * (static_cast<size_t>(im.view.height) - 1) + row;
    im.pixels.resize(bytes);
    const std::vector<uint8_t> src = in.ConsumeBytes<uint8_t>(bytes);
    for (size_t i = 0; i < bytes; ++i) im.pixels[i] = src.empty() ? uint8_t(i * 37) : src[i % src.size()];
    if (format == PLANARVO_GRAY32F)  // finite floats mostly: bytes from the input otherwise
      if (in.ConsumeBool())
        for (size_t i = 0; i + 4 <= bytes; i += 4) {
          const float f = static_cast<float>(im.pixels[i]);
          std::memcpy(&im.pixels[i], &f, 4);
        }
    im.view.data = im.pixels.data();
  } else if (!null_data && im.view.width > 0 && im.view.height > 0 && im.view.stride < row) {
    im.pixels.resize(1);  // stride below the row: refused before any pixel is read
    im.view.data = im.pixels.data();
  }
  return im;
}

void track_frame(FuzzedDataProvider& in) {
  Device& d = device();
  if (!d.tracker) return;
  Image im = any_image(in);
  planarvo_track_result r{};
  r.struct_size = sizeof r;
  auto result = maybe_struct(in, r);
  const double t = in.ConsumeBool() ? in.ConsumeFloatingPointInRange<double>(0, 1e6) : any_double(in);
  check_status(planarvo_tracker_track(in.ConsumeIntegralInRange<int>(0, 15) ? d.tracker : nullptr,
                                      in.ConsumeIntegralInRange<int>(0, 15) ? &im.view : nullptr, t, result.get()));
}

void roll_pitch_frame(FuzzedDataProvider& in) {
  Device& d = device();
  if (!d.roll_pitch) return;
  Image im = any_image(in);
  int32_t complete = 0;
  const double t = any_double(in);
  check_status(planarvo_roll_pitch_add_frame(d.roll_pitch, in.ConsumeBool() ? &im.view : nullptr, t,
                                             in.ConsumeBool() ? &complete : nullptr));
}

void create_tracker(FuzzedDataProvider& in) {
  Device& d = device();
  const planarvo_camera cam = any_camera(in);
  // Only cameras the API must refuse, or small ones: a valid 10^4 x 10^4 camera is a legitimate
  // request whose device memory the harness does not want to spend.
  const bool small = cam.width > 0 && cam.height > 0 && cam.width <= 256 && cam.height <= 256;
  const bool refused = cam.width <= 0 || cam.height <= 0 || !(cam.fx > 0) || !(cam.fy > 0);
  if (!small && !refused) return;
  planarvo_extrinsics e{any_double(in), any_double(in), in.ConsumeBool() ? 0.2 : any_double(in),
                        any_double(in), any_double(in), any_double(in)};
  planarvo_tracker_options o;
  planarvo_tracker_options_init(&o);
  o.levels = in.ConsumeIntegralInRange<int32_t>(-1, 9);
  o.finest_level = in.ConsumeIntegralInRange<int32_t>(-2, 9);
  o.max_iterations = in.ConsumeIntegralInRange<int32_t>(-1, 3);
  o.keyframe_overlap = in.ConsumeBool() ? 0.7 : any_double(in);
  auto options = maybe_struct(in, o);
  planarvo_tracker* t = nullptr;
  const planarvo_status st = planarvo_tracker_create(in.ConsumeBool() ? d.context : nullptr, &cam, &e, options.get(),
                                                    in.ConsumeIntegralInRange<int>(0, 15) ? &t : nullptr);
  check_status(st);
  if (st == PLANARVO_OK && refused) planarvo_fuzz::broken("a tracker on an invalid camera");
  planarvo_tracker_destroy(t);
}

void files(FuzzedDataProvider& in) {
  using planarvo_fuzz::work_dir;
  static const std::string path = work_dir() + "/capi_out";
  const char* p = in.ConsumeIntegralInRange<int>(0, 7) == 0 ? nullptr : in.ConsumeBool() ? "" : path.c_str();
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0: {
      const planarvo_camera c = any_camera(in);
      check_status(planarvo_camera_save(p, in.ConsumeBool() ? &c : nullptr));
      break;
    }
    case 1: {
      const planarvo_extrinsics e{any_double(in), any_double(in), any_double(in),
                                  any_double(in), any_double(in), any_double(in)};
      double cov[36];
      for (double& v : cov) v = in.ConsumeBool() ? 0.0 : any_double(in);
      const std::string est = in.ConsumeRandomLengthString(32);
      check_status(planarvo_extrinsics_save(p, &e, in.ConsumeBool() ? cov : nullptr,
                                            in.ConsumeBool() ? est.c_str() : nullptr, nullptr, est.c_str()));
      double m[16];
      check_status(planarvo_extrinsics_matrix(in.ConsumeBool() ? &e : nullptr, in.ConsumeBool() ? m : nullptr));
      break;
    }
    case 2: {
      const size_t n = in.ConsumeIntegralInRange<size_t>(0, 64);
      std::vector<double> times(n);
      std::vector<planarvo_se2> poses(n);
      for (size_t i = 0; i < n; ++i) {
        times[i] = in.ConsumeBool() ? 0.1 * static_cast<double>(i) : any_double(in);
        poses[i] = {any_double(in), any_double(in), any_double(in)};
      }
      check_status(planarvo_write_tum(p, n && in.ConsumeBool() ? nullptr : times.data(),
                                      n && in.ConsumeBool() ? nullptr : poses.data(), n));
      break;
    }
    case 3: {
      planarvo_camera c;
      check_status(planarvo_sim_default_camera(any_size(in, 640), any_size(in, 480), any_double(in),
                                               in.ConsumeBool() ? &c : nullptr));
      break;
    }
    case 4: {
      size_t count = 0;
      check_status(planarvo_motion_pairs_load(p, nullptr, 0, in.ConsumeBool() ? &count : nullptr));
      planarvo_solver_summary s{};
      s.struct_size = sizeof s;
      auto summary = maybe_struct(in, s);
      planarvo_posegraph_options o;
      planarvo_posegraph_options_init(&o);
      o.max_iterations = in.ConsumeIntegralInRange<int32_t>(-1, 3);
      o.init = static_cast<planarvo_posegraph_init>(in.ConsumeIntegralInRange<int>(-1, 3));
      auto options = maybe_struct(in, o);
      check_status(planarvo_posegraph_optimize(p, nullptr, options.get(), summary.get()));
      break;
    }
    default: {
      (void)planarvo_status_name(static_cast<planarvo_status>(in.ConsumeIntegral<int>()));
      break;
    }
  }
}

// An array of motion pairs whose stride is pairs[0].struct_size, allocated count * stride bytes.
void calibrate(FuzzedDataProvider& in) {
  const size_t count = in.ConsumeIntegralInRange<size_t>(0, 48);
  size_t stride = any_struct_size(in, sizeof(planarvo_motion_pair));
  if (stride > sizeof(planarvo_motion_pair) + 64) stride = sizeof(planarvo_motion_pair) + 64;
  // The first element's struct_size is always there (it says what the stride is), however small.
  std::vector<uint8_t> buffer(std::max(count * stride, sizeof(size_t)));
  for (size_t i = 0; i < count; ++i) {
    planarvo_motion_pair p;
    planarvo_motion_pair_init(&p);
    p.struct_size = (i == 0 || in.ConsumeIntegralInRange<int>(0, 15)) ? stride : in.ConsumeIntegral<size_t>();
    p.interval = in.ConsumeBool() ? 0.1 : any_double(in);
    p.sensor = {any_double(in), any_double(in), any_double(in)};
    p.has_odometry = in.ConsumeIntegralInRange<int32_t>(-1, 2);
    p.odometry = {any_double(in), any_double(in), any_double(in)};
    p.has_direction = in.ConsumeBool();
    p.direction = in.ConsumeIntegralInRange<int32_t>(-2, 2);
    p.has_sensor_covariance = in.ConsumeBool();
    for (double& v : p.sensor_covariance) v = in.ConsumeBool() ? 0.01 : any_double(in);
    p.has_odometry_covariance = in.ConsumeBool();
    for (double& v : p.odometry_covariance) v = in.ConsumeBool() ? 0.01 : any_double(in);
    std::memcpy(buffer.data() + i * stride, &p, std::min(stride, sizeof p));
  }
  std::memcpy(buffer.data(), &stride, sizeof stride);
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  o.method = static_cast<planarvo_calibration_method>(in.ConsumeIntegralInRange<int>(-1, 3));
  o.loss = static_cast<planarvo_robust_loss>(in.ConsumeIntegralInRange<int>(-1, 4));
  o.max_iterations = in.ConsumeIntegralInRange<int32_t>(-1, 8);
  o.fix_scale = in.ConsumeBool();
  o.fixed_scale = in.ConsumeBool() ? 1.0 : any_double(in);
  o.has_initial = in.ConsumeBool();
  for (double& v : o.initial) v = any_double(in);
  for (double* v : {&o.sensor_sigma_relative, &o.sensor_sigma_floor, &o.odometry_sigma_theta, &o.loss_scale,
                    &o.gate_sigma, &o.still_speed})
    if (in.ConsumeIntegralInRange<int>(0, 3) == 0) *v = any_double(in);
  o.estimate_odometry_noise = in.ConsumeBool();
  auto options = maybe_struct(in, o);
  planarvo_calibration_result r{};
  r.struct_size = sizeof r;
  auto result = maybe_struct(in, r);
  const auto* pairs = reinterpret_cast<const planarvo_motion_pair*>(buffer.data());
  check_status(planarvo_calibrate(count || in.ConsumeBool() ? pairs : nullptr, count, options.get(), result.get()));
  if (count > 0) {
    static const std::string path = planarvo_fuzz::work_dir() + "/capi_pairs.csv";
    check_status(planarvo_motion_pairs_save(path.c_str(), pairs, count));
  }
  if (result && result->struct_size >= sizeof r) {
    planarvo_extrinsics e;
    double cov[36];
    int32_t est[6];
    const double rp[4] = {any_double(in), 0, 0, any_double(in)};
    check_status(planarvo_compose_extrinsics(any_double(in), any_double(in), in.ConsumeBool() ? rp : nullptr,
                                             in.ConsumeBool() ? result.get() : nullptr, &e,
                                             in.ConsumeBool() ? cov : nullptr, in.ConsumeBool() ? est : nullptr));
  }
}

void evaluate(FuzzedDataProvider& in) {
  const size_t n = in.ConsumeIntegralInRange<size_t>(0, 64);
  std::vector<planarvo_se2> est(n), truth(n);
  std::vector<double> dt(n);
  std::vector<int32_t> valid(n);
  for (size_t i = 0; i < n; ++i) {
    est[i] = {any_double(in), any_double(in), any_double(in)};
    truth[i] = {any_double(in), any_double(in), any_double(in)};
    dt[i] = in.ConsumeBool() ? 0.1 : any_double(in);
    valid[i] = in.ConsumeIntegralInRange<int32_t>(-1, 1);
  }
  planarvo_motion_accuracy a{};
  a.struct_size = sizeof a;
  auto acc = maybe_struct(in, a);
  check_status(planarvo_evaluate_motions(in.ConsumeBool() ? est.data() : nullptr, truth.data(), dt.data(),
                                         in.ConsumeBool() ? valid.data() : nullptr, n, any_double(in), acc.get()));
}

// PoCL compiles kernels with LLVM, which installs its own handlers for SIGSEGV, SIGABRT and the
// other crash signals: a crash then ends the process without libFuzzer's report or artifact. The
// handlers from before the device was made are put back, and those in force at the first input
// (libFuzzer's and the sanitizers') after every input, in case a later compile installs LLVM's again.
constexpr int kCrashSignals[] = {SIGSEGV, SIGBUS, SIGABRT, SIGILL, SIGFPE, SIGTRAP};
struct Handlers {
  struct sigaction action[sizeof kCrashSignals / sizeof kCrashSignals[0]];
  void save() {
    for (size_t i = 0; i < std::size(kCrashSignals); ++i) sigaction(kCrashSignals[i], nullptr, &action[i]);
  }
  void restore() const {
    for (size_t i = 0; i < std::size(kCrashSignals); ++i) sigaction(kCrashSignals[i], &action[i], nullptr);
  }
};

}  // namespace

// The device objects are made before the first input: compiling the kernels takes longer than an
// input may (-timeout).
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  Handlers before;
  before.save();
  (void)device();
  before.restore();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const Handlers fuzzer_handlers = [] {
    Handlers h;
    h.save();
    return h;
  }();
  struct Restore {
    ~Restore() { fuzzer_handlers.restore(); }
  } restore_after_input;
  FuzzedDataProvider in(data, size);
  for (int step = 0; step < 8 && in.remaining_bytes() > 0; ++step) {
    switch (in.ConsumeIntegralInRange<int>(0, 6)) {
      case 0: track_frame(in); break;
      case 1: roll_pitch_frame(in); break;
      case 2: create_tracker(in); break;
      case 3: files(in); break;
      case 4: calibrate(in); break;
      case 5: evaluate(in); break;
      default: check_status(planarvo_tracker_reset(in.ConsumeBool() ? device().tracker : nullptr)); break;
    }
  }
  return 0;
}
