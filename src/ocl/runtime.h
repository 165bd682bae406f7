// src/ocl owns everything OpenCL: device selection, program build (from the embedded sources,
// the on-disk program cache, or prebuilt binaries), and the command queue. Other layers ask a
// Runtime for programs by name and never call clBuildProgram themselves. See README.md.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <CL/opencl.hpp>

namespace planarvo::ocl {

struct DeviceInfo {
  int platform_index = 0;
  int device_index = 0;   // within the platform
  int global_index = 0;   // across all platforms, the order `planarvo devices` lists
  std::string platform_name;
  std::string platform_version;
  std::string device_name;
  std::string device_version;        // "OpenCL 3.0 ..."
  std::string opencl_c_version;      // "OpenCL C 1.2 ..."
  std::string driver_version;
  std::string type;                  // "GPU", "CPU", "ACCELERATOR", "OTHER"
  bool image_support = false;
  bool fp64 = false;
  uint64_t local_mem_size = 0;
  uint64_t global_mem_size = 0;
  size_t max_work_group_size = 0;
  unsigned compute_units = 0;
};

struct RuntimeOptions {
  // Which device: "" picks the default (first GPU or accelerator, else the first device), an
  // integer picks by global index, "gpu", "cpu" or "accelerator" pick the first device of that
  // type, anything else is a case-insensitive substring of "platform name / device name /
  // platform version" (the platform version is where e.g. "PoCL" or "CUDA" shows). When
  // empty, the environment variable PLANARVO_DEVICE is used.
  std::string device;
  // On-disk program cache; "" means $PLANARVO_CACHE_DIR, else none on a driver that caches
  // compiled kernels itself (PoCL: detail::driver_caches_kernels), else $XDG_CACHE_HOME/planarvo,
  // else ~/.cache/planarvo, and when that cannot be created or written (a service user with no
  // home), <temp>/planarvo-<uid>/programs (cache_dirs.h), else none. Set use_cache = false to
  // always build from source. A cache directory that cannot be created or written is not an
  // error: programs are then simply not cached.
  std::string cache_dir;
  bool use_cache = true;
  // When set, programs are loaded from prebuilt binaries in this directory
  // (clCreateProgramWithBinary) and never compiled, not even as a fallback: a program whose
  // binary is missing or unusable is an error saying what needs it and how to export it. See
  // export_binaries() and README.md for the directory's manifest, kManifestFileName.
  std::string binaries_dir;
};

// Where each program a Runtime handed out came from; tests use it to tell a cache hit from a
// miss.
struct ProgramStats {
  int built_from_source = 0;     // compiled from the embedded source
  int loaded_from_cache = 0;     // loaded from the on-disk program cache
  int loaded_from_binaries = 0;  // loaded from RuntimeOptions::binaries_dir
  int cache_rejected = 0;        // cache entries that existed but were corrupt, stale or
                                 // refused by the driver (each was then rebuilt from source)
  int cache_write_failures = 0;  // built programs whose cache entry could not be written
};

// The manifest that export_binaries() writes and RuntimeOptions::binaries_dir reads.
inline constexpr const char* kManifestFileName = "planarvo-kernels.txt";

// The name of the embedded program that is a prelude to all others (kernels/common/common.cl), never
// a program by itself.
inline constexpr const char* kPreludeName = "common";

// Every platform's devices, in the order `planarvo devices` lists them. Never throws for a
// machine without OpenCL: returns an empty list. A platform or device that cannot be queried
// is left out. The first call in a process (this, or a Runtime's construction) may set
// POCL_CACHE_DIR first, for a user whose home PoCL cannot write (cache_dirs.h); a program
// that queries OpenCL itself before that gets PoCL's own behaviour.
std::vector<DeviceInfo> list_devices();

class Runtime {
 public:
  explicit Runtime(const RuntimeOptions& options = {});
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  const DeviceInfo& device_info() const { return info_; }
  cl::Context& context() { return context_; }
  cl::Device& device() { return device_; }
  // An in-order queue. The Runtime is not thread-safe: one thread uses it at a time.
  cl::CommandQueue& queue() { return queue_; }

  // The program built from kernels/<layer>/<name>.cl with the given build options ("-D WG=64 ..."),
  // memoised per (name, normalised options). Thread-safe. Adds -cl-std=CL1.2 on devices whose
  // OpenCL C is 1.2 or newer. Throws Error(OpenCL) with the build log on failure; with
  // binaries_dir set, Error(InvalidInput or OpenCL) naming the program, options, device and
  // directory when no usable binary is there.
  cl::Program& program(const std::string& name, const std::string& options = "");

  // Writes prebuilt binaries into dir and adds them to dir's manifest, each line saying which
  // uses need it. With uses empty: every embedded program (except the prelude), built with
  // each option set the engine's layers register for it (register_build_options; "" for a
  // program with none registered). Otherwise only the option sets registered for at least one
  // of the given uses (names from known_uses(); an unknown one is Error(InvalidArgument)).
  // Always builds from source (or the program cache), never from binaries_dir. Returns the
  // number of binaries written. Throws Error(Io) when dir cannot be written, Error(OpenCL)
  // when a build fails.
  size_t export_binaries(const std::string& dir, const std::vector<std::string>& uses = {});

  // Builds (or loads) the programs export_binaries() would write for the same uses (empty:
  // every embedded program with each registered option set), so that the first frame does not
  // pay for compilation. An unknown use is Error(InvalidArgument).
  void prepare(const std::vector<std::string>& uses = {});
  void prepare_all() { prepare(); }

  // Error(InvalidArgument) naming the first of uses that no variant is registered for.
  static void check_uses(const std::vector<std::string>& uses);
  // The option sets of program that serve one of uses (every registered one, or "" when none
  // is, for no uses).
  static std::vector<std::string> variants_for(const std::string& program, const std::vector<std::string>& uses);

  // Layers declare the build options they will use for a program, so that export_binaries()
  // can build exactly those variants. uses names what needs the variant in the user's words,
  // opaque to ocl: the layers register with the engine's tasks (core/tasks.h), which are the
  // tool's commands that run them and the manifest's "for" field; the defaults are registered
  // with them before main(), variants made at run time from other options without. Registering again adds uses. Thread-safe.
  static void register_build_options(const std::string& program, const std::string& options,
                                     const std::vector<std::string>& uses = {});
  // The normalised option sets registered for a program, sorted.
  static std::vector<std::string> registered_build_options(const std::string& program);
  // The uses registered for a program's option set, sorted; empty when none is known.
  static std::vector<std::string> registered_uses(const std::string& program,
                                                  const std::string& options);
  // Every use registered for any variant, sorted: what export_binaries() accepts.
  static std::vector<std::string> known_uses();

  ProgramStats stats() const;
  // The program cache directory in use; "" when caching is off (use_cache = false, or no
  // usable default location).
  const std::string& cache_dir() const { return cache_dir_; }
  // The options a program is actually built with: the normalised options plus what the
  // device needs (-cl-std=CL1.2).
  std::string effective_build_options(const std::string& options) const;

 private:
  cl::Program build(const std::string& name, const std::string& options);
  cl::Program build_from_source(const std::string& name, const std::string& source,
                                const std::string& effective_options);
  cl::Program load_from_binaries(const std::string& name, const std::string& options);
  cl::Program build_with_cache(const std::string& name, const std::string& options);

  RuntimeOptions options_;
  DeviceInfo info_;
  cl::Platform platform_;
  cl::Device device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  mutable std::mutex mutex_;
  std::map<std::string, cl::Program> programs_;
  std::string cache_dir_;
  ProgramStats stats_;
};

// The source a program is built from: the prelude kernels/common/common.cl (when the library embeds
// one) followed by kernels/<layer>/<name>.cl, each behind a #line directive so that compiler messages
// name the right file and line. Throws Error(Internal) for a name that is not embedded.
std::string program_source(const std::string& name);
// The composition program_source() uses, for any prelude ("" for none).
std::string compose_program_source(const std::string& prelude, const std::string& name,
                                   const std::string& source);

// Build options in the one spelling that memoisation, the cache and the manifest compare:
// leading and trailing whitespace removed, each run of whitespace outside double quotes
// replaced by one space.
std::string normalize_build_options(const std::string& options);

// FNV-1a 64 of the bytes of s (the manifest's options hash, and the cache's key hashes).
uint64_t fnv1a64(const std::string& s);

// "CL_INVALID_VALUE" etc. for an OpenCL error code.
const char* error_name(cl_int code);

}  // namespace planarvo::ocl
