// Device enumeration and selection, and the ways a program comes to be: built from the embedded
// source, or loaded from the on-disk cache (program_cache.h); loading from and exporting prebuilt
// binaries named by a manifest (manifest.h) is runtime_binaries.cpp.
#include "ocl/runtime.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>
#include <system_error>

#include "core/error.h"
#include "ocl/cache_dirs.h"
#include "ocl/embedded.h"
#include "ocl/program_cache.h"
#include "ocl/runtime_text.h"

namespace planarvo::ocl {
namespace fs = std::filesystem;
using detail::join;
using detail::quote;
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

// A device whose properties cannot be read is of no use to the engine: leave it out rather
// than fail the whole list.
bool describe(const cl::Platform& platform, const cl::Device& device, DeviceInfo& i) {
  try {
    i.platform_name = trim(platform.getInfo<CL_PLATFORM_NAME>());
    i.platform_version = trim(platform.getInfo<CL_PLATFORM_VERSION>());
    i.device_name = trim(device.getInfo<CL_DEVICE_NAME>());
    i.device_version = trim(device.getInfo<CL_DEVICE_VERSION>());
    i.driver_version = trim(device.getInfo<CL_DRIVER_VERSION>());
    i.type = type_name(device.getInfo<CL_DEVICE_TYPE>());
    i.image_support = device.getInfo<CL_DEVICE_IMAGE_SUPPORT>() != CL_FALSE;
    const std::string ext = device.getInfo<CL_DEVICE_EXTENSIONS>();
    i.fp64 = ext.find("cl_khr_fp64") != std::string::npos;
    i.local_mem_size = device.getInfo<CL_DEVICE_LOCAL_MEM_SIZE>();
    i.global_mem_size = device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
    i.max_work_group_size = device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
    i.compute_units = device.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
  } catch (const cl::Error&) {
    return false;
  }
  try {
    i.opencl_c_version = trim(device.getInfo<CL_DEVICE_OPENCL_C_VERSION>());
  } catch (const cl::Error&) {
    i.opencl_c_version = "OpenCL C 1.0";  // the query is 1.1; a 1.0 device has no answer
  }
  return true;
}

std::vector<Found> enumerate() {
  std::vector<Found> out;
  std::vector<cl::Platform> platforms;
  detail::prepare_driver_environment();  // before a driver reads its environment
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
      continue;  // a broken platform must not hide the others
    }
    for (size_t d = 0; d < devices.size(); ++d) {
      Found f;
      f.platform = platforms[p];
      f.device = devices[d];
      if (!describe(f.platform, f.device, f.info)) continue;
      f.info.platform_index = static_cast<int>(p);
      f.info.device_index = static_cast<int>(d);
      f.info.global_index = global++;
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

// (major, minor) of "OpenCL C 1.2 ..."; (0, 0) when unreadable.
std::pair<int, int> opencl_c_version(const std::string& s) {
  const std::string prefix = "OpenCL C ";
  const size_t at = s.find(prefix);
  if (at == std::string::npos) return {0, 0};
  int major = 0, minor = 0;
  char dot = 0;
  std::istringstream in(s.substr(at + prefix.size()));
  if (!(in >> major >> dot >> minor) || dot != '.') return {0, 0};
  return {major, minor};
}

// The process-wide registry behind Runtime::register_build_options(): program -> normalised
// options -> the uses that need that variant.
struct OptionRegistry {
  std::mutex mutex;
  std::map<std::string, std::map<std::string, std::set<std::string>>> options;
};
OptionRegistry& option_registry() {
  static OptionRegistry registry;
  return registry;
}

}  // namespace

std::string normalize_build_options(const std::string& options) {
  std::string out;
  bool in_quotes = false, pending_space = false;
  for (size_t i = 0; i < options.size(); ++i) {
    const char c = options[i];
    if (!in_quotes && std::isspace(static_cast<unsigned char>(c))) {
      pending_space = !out.empty();
      continue;
    }
    if (pending_space) out += ' ';
    pending_space = false;
    out += c;
    if (c == '\\' && i + 1 < options.size()) {
      out += options[++i];  // an escaped character, a quote included, is kept as it is
    } else if (c == '"') {
      in_quotes = !in_quotes;
    }
  }
  return out;
}

std::string compose_program_source(const std::string& prelude, const std::string& name,
                                   const std::string& source) {
  // Drivers compile from a temporary file of their own; #line makes the build log say
  // "fill.cl:11" instead of "/tmp/tempfile_x1.cl:40".
  std::string out;
  if (!prelude.empty()) {
    out = "#line 1 \"" + std::string(kPreludeName) + ".cl\"\n" + prelude;
    if (out.back() != '\n') out += '\n';
  }
  out += "#line 1 \"" + name + ".cl\"\n";
  out += source;
  return out;
}

std::string program_source(const std::string& name) {
  const EmbeddedSource* src = find_source(name);
  if (!src) throw Error(ErrorCode::Internal, "no embedded kernel program named \"" + name + "\"");
  const EmbeddedSource* prelude = name == kPreludeName ? nullptr : find_source(kPreludeName);
  return compose_program_source(prelude ? std::string(prelude->source, prelude->size) : "", name,
                                std::string(src->source, src->size));
}

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  for (auto& f : enumerate()) out.push_back(f.info);
  return out;
}

Runtime::Runtime(const RuntimeOptions& options) : options_(options) {
  std::string selector = trim(options.device);
  // Where the selector came from, said only when it is not the caller's own (the tool's
  // --device, the C API's device field): the environment.
  std::string origin;
  if (selector.empty()) {
    if (const char* env = std::getenv("PLANARVO_DEVICE")) {
      selector = trim(env);
      origin = "from PLANARVO_DEVICE; ";
    }
  }
  std::vector<Found> all = enumerate();
  if (all.empty()) {
    const std::string& driver_problem = detail::prepare_driver_environment();
    throw Error(ErrorCode::NoDevice,
                "no OpenCL platform or device found (is an ICD such as pocl-opencl-icd installed?)" +
                    (driver_problem.empty() ? std::string() : ". " + driver_problem));
  }
  const Found* chosen = nullptr;
  const std::string want = lower(selector);
  if (selector.empty()) {
    for (auto& f : all)
      if (f.info.type == "GPU" || f.info.type == "ACCELERATOR") { chosen = &f; break; }
    if (!chosen) chosen = &all.front();
  } else if (std::all_of(selector.begin(), selector.end(),
                         [](unsigned char c) { return std::isdigit(c); })) {
    const long idx = std::strtol(selector.c_str(), nullptr, 10);
    if (idx < 0 || idx >= static_cast<long>(all.size()))
      throw Error(ErrorCode::NoDevice, "device index " + selector +
                                           (origin.empty() ? "" : " (from PLANARVO_DEVICE)") +
                                           " is out of range: there " +
                                           (all.size() == 1 ? "is 1 device"
                                                            : "are " + std::to_string(all.size()) +
                                                                  " devices") +
                                           " (see `planarvo devices`)");
    chosen = &all[static_cast<size_t>(idx)];
  } else if (want == "gpu" || want == "cpu" || want == "accelerator") {
    for (auto& f : all)
      if (lower(f.info.type) == want) { chosen = &f; break; }
    if (!chosen)
      throw Error(ErrorCode::NoDevice, "no OpenCL device of type " + quote(selector) + " (" +
                                           origin + "see `planarvo devices`)");
  } else {
    for (auto& f : all) {
      const std::string name = lower(f.info.platform_name + " / " + f.info.device_name + " / " +
                                     f.info.platform_version);
      if (name.find(want) != std::string::npos) { chosen = &f; break; }
    }
    if (!chosen)
      throw Error(ErrorCode::NoDevice, "no OpenCL device matches " + quote(selector) + " (" +
                                           origin + "see `planarvo devices` for the names)");
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
  // A driver with a kernel cache of its own needs none of ours, unless a directory was chosen.
  const char* env_dir = std::getenv("PLANARVO_CACHE_DIR");
  const bool dir_chosen = !options_.cache_dir.empty() || (env_dir && *env_dir);
  cache_dir_ = !dir_chosen && detail::driver_caches_kernels(info_.platform_name) ? "" : detail::resolve_cache_dir(options_);
}

Runtime::~Runtime() = default;

ProgramStats Runtime::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

std::string Runtime::effective_build_options(const std::string& options) const {
  std::string out = normalize_build_options(options);
  // Without -cl-std, OpenCL 2.x/3.0 compilers may pick their newest dialect; the kernels are
  // written to 1.2 (portability.md). A 1.1 device (TI C66x) rejects the flag, so it gets none.
  if (out.find("-cl-std=") == std::string::npos && opencl_c_version(info_.opencl_c_version) >=
                                                       std::make_pair(1, 2))
    out = out.empty() ? "-cl-std=CL1.2" : "-cl-std=CL1.2 " + out;
  return out;
}

cl::Program& Runtime::program(const std::string& name, const std::string& options) {
  const std::string normalized = normalize_build_options(options);
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string key = name + '\n' + normalized;
  auto it = programs_.find(key);
  if (it == programs_.end()) it = programs_.emplace(key, build(name, normalized)).first;
  return it->second;
}

cl::Program Runtime::build(const std::string& name, const std::string& options) {
  if (name == kPreludeName)
    throw Error(ErrorCode::InvalidArgument,
                "\"" + name + "\" is the prelude of every kernel program, not a program itself");
  if (!find_source(name))
    throw Error(ErrorCode::Internal, "no embedded kernel program named \"" + name + "\"");
  if (!options_.binaries_dir.empty()) return load_from_binaries(name, options);
  return build_with_cache(name, options);
}

cl::Program Runtime::build_from_source(const std::string& name, const std::string& source,
                                       const std::string& effective_options) {
  cl::Program program(context_, source);
  try {
    program.build(std::vector<cl::Device>{device_}, effective_options.c_str());
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    } catch (const cl::Error&) {
    }
    throw Error(ErrorCode::OpenCL, "building OpenCL program \"" + name + "\" for " +
                                       info_.device_name + " failed (" + error_name(e.err()) +
                                       ") with options \"" + effective_options + "\":\n" + log);
  }
  return program;
}

cl::Program Runtime::build_with_cache(const std::string& name, const std::string& options) {
  const std::string source = program_source(name);
  const std::string effective = effective_build_options(options);
  if (cache_dir_.empty()) {
    cl::Program p = build_from_source(name, source, effective);
    ++stats_.built_from_source;
    return p;
  }
  const std::string key = detail::cache_key(name, source, effective, info_);
  const fs::path path = detail::cache_entry_path(cache_dir_, name, key);

  // Any failure to load an entry is a miss: the entry is rebuilt and overwritten below.
  if (auto bytes = detail::read_file(path)) {
    if (auto binary = detail::decode_cache_entry(*bytes, key)) {
      try {
        cl::Program p(context_, std::vector<cl::Device>{device_},
                      cl::Program::Binaries{std::move(*binary)});
        p.build(std::vector<cl::Device>{device_}, effective.c_str());
        ++stats_.loaded_from_cache;
        return p;
      } catch (const cl::Error&) {
      }
    }
    ++stats_.cache_rejected;
  }

  cl::Program p = build_from_source(name, source, effective);
  ++stats_.built_from_source;
  // The cache is an optimisation: a directory that cannot be written costs speed, not a result.
  bool written = false;
  try {
    const std::vector<std::vector<unsigned char>> binaries = p.getInfo<CL_PROGRAM_BINARIES>();
    std::error_code ec;
    fs::create_directories(cache_dir_, ec);
    if (!ec && binaries.size() == 1 && !binaries[0].empty()) {
      const std::vector<unsigned char> entry = detail::encode_cache_entry(key, binaries[0]);
      written = detail::write_file_atomically(path, entry.data(), entry.size());
    }
  } catch (const cl::Error&) {
  }
  if (!written) ++stats_.cache_write_failures;
  return p;
}

void Runtime::prepare(const std::vector<std::string>& uses) {
  check_uses(uses);
  for (const EmbeddedSource* s = embedded_sources(); s->name; ++s) {
    if (std::string(s->name) == kPreludeName) continue;
    for (const std::string& options : variants_for(s->name, uses)) program(s->name, options);
  }
}

void Runtime::check_uses(const std::vector<std::string>& uses) {
  const std::vector<std::string> known = known_uses();
  for (const std::string& u : uses)
    if (std::find(known.begin(), known.end(), u) == known.end())
      throw Error(ErrorCode::InvalidArgument,
                  "no kernels are registered for " + quote(u) + "; the uses are " + join(known, ", "));
}

std::vector<std::string> Runtime::variants_for(const std::string& program, const std::vector<std::string>& uses) {
  std::vector<std::string> sets = registered_build_options(program);
  if (uses.empty()) {
    if (sets.empty()) sets.push_back("");
    return sets;
  }
  std::vector<std::string> out;
  for (const std::string& options : sets) {
    const std::vector<std::string> has = registered_uses(program, options);
    if (std::any_of(uses.begin(), uses.end(),
                    [&](const std::string& u) { return std::find(has.begin(), has.end(), u) != has.end(); }))
      out.push_back(options);
  }
  return out;
}

void Runtime::register_build_options(const std::string& program, const std::string& options,
                                     const std::vector<std::string>& uses) {
  OptionRegistry& r = option_registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::set<std::string>& u = r.options[program][normalize_build_options(options)];
  u.insert(uses.begin(), uses.end());
}

std::vector<std::string> Runtime::registered_build_options(const std::string& program) {
  OptionRegistry& r = option_registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto it = r.options.find(program);
  if (it == r.options.end()) return {};
  std::vector<std::string> out;
  for (const auto& [options, uses] : it->second) out.push_back(options);
  return out;
}

std::vector<std::string> Runtime::registered_uses(const std::string& program,
                                                  const std::string& options) {
  OptionRegistry& r = option_registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto it = r.options.find(program);
  if (it == r.options.end()) return {};
  auto jt = it->second.find(normalize_build_options(options));
  if (jt == it->second.end()) return {};
  return {jt->second.begin(), jt->second.end()};
}

std::vector<std::string> Runtime::known_uses() {
  OptionRegistry& r = option_registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::set<std::string> all;
  for (const auto& [program, sets] : r.options)
    for (const auto& [options, uses] : sets) all.insert(uses.begin(), uses.end());
  return {all.begin(), all.end()};
}

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
    PV_CASE(CL_INVALID_SAMPLER) PV_CASE(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    PV_CASE(CL_INVALID_MIP_LEVEL) PV_CASE(CL_INVALID_PROPERTY)
    PV_CASE(CL_INVALID_IMAGE_DESCRIPTOR) PV_CASE(CL_INVALID_COMPILER_OPTIONS)
    PV_CASE(CL_INVALID_LINKER_OPTIONS) PV_CASE(CL_INVALID_DEVICE_PARTITION_COUNT)
    PV_CASE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST) PV_CASE(CL_DEVICE_PARTITION_FAILED)
    PV_CASE(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";  // from the ICD loader
#undef PV_CASE
    default: return "CL_UNKNOWN_ERROR";
  }
}

}  // namespace planarvo::ocl
