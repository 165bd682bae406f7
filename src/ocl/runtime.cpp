#include "ocl/runtime.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <sstream>

#include "core/error.h"
#include "ocl/embedded.h"

namespace planarvo::ocl {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string trim(std::string s) {
  while (!s.empty() && (std::isspace(static_cast<unsigned char>(s.back())) || s.back() == '\0'))
    s.pop_back();
  size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

std::string type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "GPU";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "ACCELERATOR";
  if (t & CL_DEVICE_TYPE_CPU) return "CPU";
  return "OTHER";
}

struct Found {
  DeviceInfo info;
  cl::Platform platform;
  cl::Device device;
};

std::vector<Found> enumerate() {
  std::vector<Found> out;
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    return out;  // no ICD or no platform: an empty list, not an error
  }
  int global = 0;
  for (size_t p = 0; p < platforms.size(); ++p) {
    std::vector<cl::Device> devices;
    try {
      platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;
    }
    for (size_t d = 0; d < devices.size(); ++d) {
      Found f;
      f.platform = platforms[p];
      f.device = devices[d];
      DeviceInfo& i = f.info;
      i.platform_index = static_cast<int>(p);
      i.device_index = static_cast<int>(d);
      i.global_index = global++;
      i.platform_name = trim(platforms[p].getInfo<CL_PLATFORM_NAME>());
      i.platform_version = trim(platforms[p].getInfo<CL_PLATFORM_VERSION>());
      i.device_name = trim(devices[d].getInfo<CL_DEVICE_NAME>());
      i.device_version = trim(devices[d].getInfo<CL_DEVICE_VERSION>());
      i.opencl_c_version = trim(devices[d].getInfo<CL_DEVICE_OPENCL_C_VERSION>());
      i.driver_version = trim(devices[d].getInfo<CL_DRIVER_VERSION>());
      i.type = type_name(devices[d].getInfo<CL_DEVICE_TYPE>());
      i.image_support = devices[d].getInfo<CL_DEVICE_IMAGE_SUPPORT>() != CL_FALSE;
      const std::string ext = devices[d].getInfo<CL_DEVICE_EXTENSIONS>();
      i.fp64 = ext.find("cl_khr_fp64") != std::string::npos;
      i.local_mem_size = devices[d].getInfo<CL_DEVICE_LOCAL_MEM_SIZE>();
      i.global_mem_size = devices[d].getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      i.max_work_group_size = devices[d].getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
      i.compute_units = devices[d].getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      out.push_back(std::move(f));
    }
  }
  return out;
}

const EmbeddedSource* find_source(const std::string& name) {
  for (const EmbeddedSource* s = embedded_sources(); s->name; ++s)
    if (name == s->name) return s;
  return nullptr;
}

}  // namespace

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  for (auto& f : enumerate()) out.push_back(f.info);
  return out;
}

Runtime::Runtime(const RuntimeOptions& options) : options_(options) {
  std::string selector = options.device;
  if (selector.empty()) {
    if (const char* env = std::getenv("PLANARVO_DEVICE")) selector = env;
  }
  std::vector<Found> all = enumerate();
  if (all.empty())
    throw Error(ErrorCode::NoDevice,
                "no OpenCL platform or device found (is an ICD such as pocl-opencl-icd installed?)");
  const Found* chosen = nullptr;
  if (selector.empty()) {
    for (auto& f : all)
      if (f.info.type == "GPU" || f.info.type == "ACCELERATOR") { chosen = &f; break; }
    if (!chosen) chosen = &all.front();
  } else if (std::all_of(selector.begin(), selector.end(),
                         [](unsigned char c) { return std::isdigit(c); })) {
    const long idx = std::strtol(selector.c_str(), nullptr, 10);
    if (idx < 0 || idx >= static_cast<long>(all.size()))
      throw Error(ErrorCode::NoDevice, "device index " + selector + " is out of range: there are " +
                                           std::to_string(all.size()) + " devices (see `planarvo devices`)");
    chosen = &all[static_cast<size_t>(idx)];
  } else {
    const std::string want = lower(selector);
    for (auto& f : all)
      if (lower(f.info.platform_name + " / " + f.info.device_name).find(want) != std::string::npos) {
        chosen = &f;
        break;
      }
    if (!chosen)
      throw Error(ErrorCode::NoDevice, "no OpenCL device matches \"" + selector +
                                           "\" (see `planarvo devices` for the names)");
  }
  info_ = chosen->info;
  platform_ = chosen->platform;
  device_ = chosen->device;
  try {
    context_ = cl::Context(device_);
    queue_ = cl::CommandQueue(context_, device_);
  } catch (const cl::Error& e) {
    throw Error(ErrorCode::NoDevice, "could not create an OpenCL context on " + info_.device_name +
                                         ": " + e.what() + " " + error_name(e.err()));
  }
}

Runtime::~Runtime() = default;

cl::Program& Runtime::program(const std::string& name, const std::string& options) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string key = name + '\n' + options;
  auto it = programs_.find(key);
  if (it == programs_.end()) it = programs_.emplace(key, build(name, options)).first;
  return it->second;
}

cl::Program Runtime::build(const std::string& name, const std::string& options) {
  const EmbeddedSource* src = find_source(name);
  if (!src) throw Error(ErrorCode::Internal, "no embedded kernel program named \"" + name + "\"");
  std::string source(src->source, src->size);
  cl::Program program(context_, source);
  try {
    program.build(std::vector<cl::Device>{device_}, options.c_str());
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    } catch (const cl::Error&) {
    }
    throw Error(ErrorCode::OpenCL, "building OpenCL program \"" + name + "\" for " +
                                       info_.device_name + " failed (" + error_name(e.err()) +
                                       ") with options \"" + options + "\":\n" + log);
  }
  return program;
}

void Runtime::export_binaries(const std::string& /*dir*/) {
  throw Error(ErrorCode::Internal, "export_binaries: not implemented yet");
}

void Runtime::register_build_options(const std::string& /*program*/, const std::string& /*options*/) {}

const char* error_name(cl_int code) {
  switch (code) {
#define PV_CASE(x) case x: return #x;
    PV_CASE(CL_SUCCESS) PV_CASE(CL_DEVICE_NOT_FOUND) PV_CASE(CL_DEVICE_NOT_AVAILABLE)
    PV_CASE(CL_COMPILER_NOT_AVAILABLE) PV_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    PV_CASE(CL_OUT_OF_RESOURCES) PV_CASE(CL_OUT_OF_HOST_MEMORY)
    PV_CASE(CL_PROFILING_INFO_NOT_AVAILABLE) PV_CASE(CL_MEM_COPY_OVERLAP)
    PV_CASE(CL_IMAGE_FORMAT_MISMATCH) PV_CASE(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    PV_CASE(CL_BUILD_PROGRAM_FAILURE) PV_CASE(CL_MAP_FAILURE)
    PV_CASE(CL_MISALIGNED_SUB_BUFFER_OFFSET) PV_CASE(CL_COMPILE_PROGRAM_FAILURE)
    PV_CASE(CL_LINKER_NOT_AVAILABLE) PV_CASE(CL_LINK_PROGRAM_FAILURE)
    PV_CASE(CL_INVALID_VALUE) PV_CASE(CL_INVALID_DEVICE_TYPE) PV_CASE(CL_INVALID_PLATFORM)
    PV_CASE(CL_INVALID_DEVICE) PV_CASE(CL_INVALID_CONTEXT) PV_CASE(CL_INVALID_QUEUE_PROPERTIES)
    PV_CASE(CL_INVALID_COMMAND_QUEUE) PV_CASE(CL_INVALID_HOST_PTR) PV_CASE(CL_INVALID_MEM_OBJECT)
    PV_CASE(CL_INVALID_IMAGE_SIZE) PV_CASE(CL_INVALID_BINARY) PV_CASE(CL_INVALID_BUILD_OPTIONS)
    PV_CASE(CL_INVALID_PROGRAM) PV_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    PV_CASE(CL_INVALID_KERNEL_NAME) PV_CASE(CL_INVALID_KERNEL_DEFINITION) PV_CASE(CL_INVALID_KERNEL)
    PV_CASE(CL_INVALID_ARG_INDEX) PV_CASE(CL_INVALID_ARG_VALUE) PV_CASE(CL_INVALID_ARG_SIZE)
    PV_CASE(CL_INVALID_KERNEL_ARGS) PV_CASE(CL_INVALID_WORK_DIMENSION)
    PV_CASE(CL_INVALID_WORK_GROUP_SIZE) PV_CASE(CL_INVALID_WORK_ITEM_SIZE)
    PV_CASE(CL_INVALID_GLOBAL_OFFSET) PV_CASE(CL_INVALID_EVENT_WAIT_LIST) PV_CASE(CL_INVALID_EVENT)
    PV_CASE(CL_INVALID_OPERATION) PV_CASE(CL_INVALID_BUFFER_SIZE) PV_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
#undef PV_CASE
    default: return "CL_UNKNOWN_ERROR";
  }
}

}  // namespace planarvo::ocl
