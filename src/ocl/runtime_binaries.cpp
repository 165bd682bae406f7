// Prebuilt kernel binaries (src/ocl/README.md, "Prebuilt binaries"): loading a program from a
// directory's manifest (manifest.h) instead of compiling it, and exporting every registered
// variant for this device and driver.
#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/sha256.h"
#include "ocl/embedded.h"
#include "ocl/manifest.h"
#include "ocl/program_cache.h"
#include "ocl/runtime.h"
#include "ocl/runtime_text.h"

namespace planarvo::ocl {
namespace fs = std::filesystem;
using detail::join;
using detail::quote;

namespace {

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

size_t Runtime::export_binaries(const std::string& dir, const std::vector<std::string>& uses) {
  check_uses(uses);

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
    for (const std::string& options : variants_for(name, uses)) {
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

}  // namespace planarvo::ocl
