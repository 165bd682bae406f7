// src/ocl owns everything OpenCL: device selection, program build (from the embedded sources,
// the on-disk program cache, or prebuilt binaries), and the command queue. Other layers ask a
// Runtime for programs by name and never call clBuildProgram themselves.
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
  // integer picks by global index, anything else is a case-insensitive substring of
  // "platform name / device name". When empty, the environment variable PLANARVO_DEVICE is used.
  std::string device;
  // On-disk program cache; "" means $PLANARVO_CACHE_DIR, else $XDG_CACHE_HOME/planarvo, else
  // ~/.cache/planarvo. Set use_cache = false to always build from source.
  std::string cache_dir;
  bool use_cache = true;
  // When set, programs are loaded from prebuilt binaries in this directory
  // (clCreateProgramWithBinary) and never compiled; see export_binaries().
  std::string binaries_dir;
};

// Every platform's devices, in the order `planarvo devices` lists them. Never throws for a
// machine without OpenCL: returns an empty list.
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

  // The program built from kernels/<name>.cl with the given build options ("-D WG=64 ..."),
  // memoised per (name, options). Throws Error(OpenCL) with the build log on failure.
  cl::Program& program(const std::string& name, const std::string& options = "");

  // Writes prebuilt binaries of every embedded program, built with the options that the
  // engine's layers register for it (register_build_options), into dir.
  void export_binaries(const std::string& dir);

  // Layers declare the build options they will use for a program, so that export_binaries()
  // can build exactly those variants. Idempotent.
  static void register_build_options(const std::string& program, const std::string& options);

 private:
  cl::Program build(const std::string& name, const std::string& options);

  RuntimeOptions options_;
  DeviceInfo info_;
  cl::Platform platform_;
  cl::Device device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  std::mutex mutex_;
  std::map<std::string, cl::Program> programs_;
};

// "CL_INVALID_VALUE" etc. for an OpenCL error code.
const char* error_name(cl_int code);

}  // namespace planarvo::ocl
