// Device enumeration and selection, and the three ways a program comes to be: built from the
// embedded source, loaded from the on-disk cache (program_cache.h), or loaded from prebuilt
// binaries named by a manifest (manifest.h).
#include "ocl/runtime.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>
#include <system_error>

#include "core/error.h"
#include "core/sha256.h"
#include "ocl/cache_dirs.h"
#include "ocl/embedded.h"
#include "ocl/manifest.h"
#include "ocl/program_cache.h"

namespace planarvo::ocl {
namespace fs = std::filesystem;
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

std::string quote(const std::string& s) { return "\"" + s + "\""; }

std::string join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (const std::string& i : items) out += (out.empty() ? "" : sep) + i;
  return out;
}

// "a", "a and b", "a, b and c".
std::string words(const std::vector<std::string>& items) {
  if (items.size() <= 1) return join(items, "");
  return join(std::vector<std::string>(items.begin(), items.end() - 1), ", ") + " and " +
         items.back();
}

// What a user does about a variant missing from a prebuilt-binaries directory, in the tool's
// and the C API's words: which of the engine's uses (the tool's commands) need it and how to
// export it.
std::string export_advice(const std::string& program, const std::string& options,
                          const std::string& dir) {
  const std::vector<std::string> uses = Runtime::registered_uses(program, options);
  const std::string all = "`planarvo kernels --export " + dir + "`";
  if (uses.empty())
    return "No command of the tool uses this variant with its default options, so " + all +
           " does not write it: build it with the vendor's offline compiler from the "
           "program's source and add a line for it to the manifest (src/ocl/README.md)";
  const bool one = uses.size() == 1;
  return std::string(one ? "The command " : "The commands ") + words(uses) + (one ? " uses" : " use") +
         " it with " + (one ? "its" : "their") + " default options: export what " +
         (one ? "it needs" : "they need") + " on this device and driver with `planarvo kernels " +
         "--export " + dir + " --for " + join(uses, ",") + "`, or every kernel with " + all +
         " (C API: planarvo_context_export_kernels)";
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
  cache_dir_ = detail::resolve_cache_dir(options_);
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

namespace {

// The manifest's entry for the program and options on this device and driver; InvalidInput naming
// what is missing or mismatched, and how to export it. what: the program, options and device;
// where: the directory, as the messages say them.
detail::ManifestEntry manifest_entry(const std::string& dir, const std::string& name, const std::string& options,
                                     const DeviceInfo& info, const std::string& what, const std::string& where) {
  const fs::path manifest_path = fs::path(dir) / kManifestFileName;
  std::error_code ec;
  if (fs::exists(manifest_path, ec) && !fs::is_regular_file(manifest_path, ec))
    throw_invalid_input("the manifest " + quote(manifest_path.string()) + " is not a file (" + where + ")");
  const auto text = detail::read_file(manifest_path);
  if (!text)
    throw_invalid_input("cannot load " + what + ": " + where + " has no manifest " +
                        kManifestFileName + ", and with prebuilt binaries the engine never " +
                        "compiles kernels. " + export_advice(name, options, dir) +
                        "; or write the manifest by hand as src/ocl/README.md describes.");
  std::vector<detail::ManifestEntry> entries;
  try {
    entries = detail::parse_manifest(std::string(text->begin(), text->end()),
                                     manifest_path.string());
  } catch (const Error& e) {
    throw_invalid_input(std::string(e.what()) + " (while loading " + what + ")");
  }

  std::vector<const detail::ManifestEntry*> candidates;
  std::vector<std::string> other_options;
  for (const auto& e : entries) {
    if (e.program != name) continue;
    if (e.options == options)
      candidates.push_back(&e);
    else
      other_options.push_back(quote(e.options));
  }
  if (candidates.empty()) {
    std::string msg = "no prebuilt binary for " + what + " in " + where;
    if (!other_options.empty()) {
      msg += "; the manifest has " + quote(name) + " only with options";
      for (const auto& o : other_options) msg += " " + o;
    }
    throw_invalid_input(msg + ". With prebuilt binaries the engine never compiles kernels. " +
                        export_advice(name, options, dir) + ".");
  }
  const detail::ManifestEntry* entry = nullptr;
  for (const auto* e : candidates) {
    if ((e->device == "*" || e->device == info.device_name) &&
        (e->driver == "*" || e->driver == info.driver_version)) {
      entry = e;
      break;
    }
  }
  if (!entry) {
    std::string built_for;
    for (const auto* e : candidates)
      built_for += (built_for.empty() ? "" : ", ") + quote(e->device) + " (driver " + e->driver +
                   ", manifest line " + std::to_string(e->line) + ")";
    throw_invalid_input("mismatched binary for " + name + " with options " + quote(options) +
                        " in " + where + ": built for " + built_for + ", this device is " +
                        quote(info.device_name) + " (driver " + info.driver_version +
                        "); export the binaries on this device and driver (`planarvo kernels " +
                        "--export " + dir + "` adds them beside the others)");
  }

  return *entry;
}

// The binary file of a manifest entry, checked before the driver parses it: a truncated binary
// crashed a driver, and one program's binary under another's name ran and tracked nothing.
std::vector<unsigned char> checked_binary(const std::string& dir, const detail::ManifestEntry& e,
                                          const std::string& what, const std::string& where) {
  const detail::ManifestEntry* entry = &e;
  std::error_code ec;
  const fs::path file = fs::path(dir) / entry->file;
  if (fs::exists(file, ec) && !fs::is_regular_file(file, ec))
    throw_invalid_input("the binary file " + quote(file.string()) + " for " + what + " is not a file (" + where +
                        ", manifest line " + std::to_string(entry->line) + ")");
  const auto binary = detail::read_file(file);
  if (!binary)
    throw_invalid_input("the binary file " + quote(file.string()) + " for " + what +
                        " is missing or unreadable (" + where + ", manifest line " +
                        std::to_string(entry->line) + ")");
  if (binary->empty())
    throw_invalid_input("the binary file " + quote(file.string()) + " for " + what +
                        " is empty (" + where + ")");
  const std::string manifest_line = where + ", manifest line " + std::to_string(entry->line);
  if (entry->size >= 0 && static_cast<long long>(binary->size()) != entry->size)
    throw_invalid_input("the binary file " + quote(file.string()) + " for " + what + " is " +
                        std::to_string(binary->size()) + " bytes, the manifest says " + std::to_string(entry->size) +
                        " (truncated or replaced? " + manifest_line + "); export the binaries again");
  if (!entry->sha256.empty() && sha256_hex(binary->data(), binary->size()) != entry->sha256)
    throw_invalid_input("the binary file " + quote(file.string()) + " for " + what +
                        " does not have the SHA-256 the manifest records (corrupted or another program's? " +
                        manifest_line + "); export the binaries again");

  return *binary;
}

}  // namespace

cl::Program Runtime::load_from_binaries(const std::string& name, const std::string& options) {
  const std::string& dir = options_.binaries_dir;
  const std::string what = "program " + quote(name) + " with options " + quote(options) +
                           " on device " + quote(info_.device_name) + " (driver " +
                           info_.driver_version + ")";
  const std::string where = "the prebuilt binaries directory " + quote(dir) +
                            " (--kernel-binaries)";

  const detail::ManifestEntry entry = manifest_entry(dir, name, options, info_, what, where);
  const fs::path file = fs::path(dir) / entry.file;
  const std::vector<unsigned char> bytes = checked_binary(dir, entry, what, where);
  const std::string effective = effective_build_options(options);
  cl::Program p;
  std::vector<cl_int> status;
  try {
    p = cl::Program(context_, std::vector<cl::Device>{device_}, cl::Program::Binaries{bytes},
                    &status);
  } catch (const cl::Error& e) {
    const cl_int code = !status.empty() && status[0] != CL_SUCCESS ? status[0] : e.err();
    throw Error(ErrorCode::OpenCL, "the driver rejected the binary " + quote(file.string()) +
                                       " for " + what + " (" + error_name(code) + ", " + where +
                                       "); was it built for this device and driver?");
  }
  try {
    p.build(std::vector<cl::Device>{device_}, effective.c_str());
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = p.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    } catch (const cl::Error&) {
    }
    throw Error(ErrorCode::OpenCL, "building the binary " + quote(file.string()) + " for " +
                                       what + " failed (" + error_name(e.err()) + ", " + where +
                                       "):\n" + log);
  }
  ++stats_.loaded_from_binaries;
  return p;
}

void Runtime::prepare_all() {
  for (const EmbeddedSource* s = embedded_sources(); s->name; ++s) {
    if (std::string(s->name) == kPreludeName) continue;
    std::vector<std::string> option_sets = registered_build_options(s->name);
    if (option_sets.empty()) option_sets.push_back("");
    for (const std::string& options : option_sets) program(s->name, options);
  }
}

size_t Runtime::export_binaries(const std::string& dir, const std::vector<std::string>& uses) {
  const std::vector<std::string> known = known_uses();
  for (const std::string& u : uses)
    if (std::find(known.begin(), known.end(), u) == known.end())
      throw Error(ErrorCode::InvalidArgument,
                  "no kernels are registered for " + quote(u) + "; the uses are " + join(known, ", "));
  // The option sets to export for a program: every registered one (or "" when none is) when
  // no use is asked for; otherwise those registered for one of the uses.
  const auto wanted = [&](const std::string& program) {
    std::vector<std::string> sets = registered_build_options(program);
    if (uses.empty()) {
      if (sets.empty()) sets.push_back("");
      return sets;
    }
    std::vector<std::string> out;
    for (const std::string& options : sets) {
      const std::vector<std::string> has = registered_uses(program, options);
      if (std::any_of(uses.begin(), uses.end(), [&](const std::string& u) {
            return std::find(has.begin(), has.end(), u) != has.end();
          }))
        out.push_back(options);
    }
    return out;
  };

  std::lock_guard<std::mutex> lock(mutex_);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw Error(ErrorCode::Io, "cannot create the kernel binaries directory " + quote(dir) +
                                   (ec ? ": " + ec.message() : std::string()));
  const fs::path manifest_path = fs::path(dir) / kManifestFileName;

  // Entries for other devices stay, so one directory can serve several devices.
  std::vector<detail::ManifestEntry> entries;
  if (auto text = detail::read_file(manifest_path))
    entries = detail::parse_manifest(std::string(text->begin(), text->end()),
                                     manifest_path.string());

  const std::string device_tag =
      detail::hex64(fnv1a64(info_.device_name + "\n" + info_.driver_version)).substr(0, 8);
  size_t written = 0;
  for (const EmbeddedSource* s = embedded_sources(); s->name; ++s) {
    const std::string name = s->name;
    if (name == kPreludeName) continue;
    for (const std::string& options : wanted(name)) {
      if (options.find_first_of("\t\r\n") != std::string::npos)
        throw Error(ErrorCode::InvalidArgument,
                    "the options " + quote(options) + " registered for program " + quote(name) +
                        " hold a TAB or line break, which the manifest cannot list");
      cl::Program p = build_with_cache(name, options);
      std::vector<std::vector<unsigned char>> binaries;
      try {
        binaries = p.getInfo<CL_PROGRAM_BINARIES>();
      } catch (const cl::Error& e) {
        throw Error(ErrorCode::OpenCL, "cannot read the binary of program " + quote(name) +
                                           " with options " + quote(options) + " on " +
                                           info_.device_name + ": " + error_name(e.err()));
      }
      if (binaries.size() != 1 || binaries[0].empty())
        throw Error(ErrorCode::OpenCL, "the driver of " + info_.device_name +
                                           " returned no binary for program " + quote(name) +
                                           " with options " + quote(options));
      detail::ManifestEntry e;
      e.program = name;
      e.options = options;
      e.options_hash = detail::options_hash(options);
      e.file = name + "-" + e.options_hash + "-" + device_tag + ".bin";
      e.device = info_.device_name;
      e.driver = info_.driver_version;
      e.uses = join(registered_uses(name, options), ",");
      e.size = static_cast<long long>(binaries[0].size());
      e.sha256 = sha256_hex(binaries[0].data(), binaries[0].size());
      if (!detail::write_file_atomically(fs::path(dir) / e.file, binaries[0].data(),
                                         binaries[0].size()))
        throw Error(ErrorCode::Io, "cannot write " + quote((fs::path(dir) / e.file).string()));
      entries.erase(std::remove_if(entries.begin(), entries.end(),
                                   [&](const detail::ManifestEntry& old) {
                                     return old.program == e.program && old.options == e.options &&
                                            old.device == e.device;
                                   }),
                    entries.end());
      entries.push_back(std::move(e));
      ++written;
    }
  }
  const std::string text = detail::format_manifest(entries);
  if (!detail::write_file_atomically(manifest_path,
                                     reinterpret_cast<const unsigned char*>(text.data()),
                                     text.size()))
    throw Error(ErrorCode::Io, "cannot write " + quote(manifest_path.string()));
  return written;
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
