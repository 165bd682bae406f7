// `planarvo devices` and `planarvo kernels`: the OpenCL side of the tool.
#include <cstdio>
#include <string>
#include <vector>

#include "common.h"

namespace planarvo::cli {
namespace {

std::string bytes(uint64_t b) {
  char buf[32];
  if (b >= (1ull << 30)) std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(b) / (1ull << 30));
  else if (b >= (1ull << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(b) / (1ull << 20));
  else std::snprintf(buf, sizeof buf, "%llu KiB", static_cast<unsigned long long>(b >> 10));
  return buf;
}

// What `--for COMMAND,...` asks the C API to export: the uses each command runs (demo runs
// all three). Commands without a device need no kernels.
std::string uses_of_commands(const std::string& list) {
  std::string uses;
  const auto add = [&](const char* u) {
    if (("," + uses + ",").find(std::string(",") + u + ",") == std::string::npos)
      uses += (uses.empty() ? "" : ",") + std::string(u);
  };
  size_t start = 0;
  for (;;) {
    const size_t comma = list.find(',', start);
    const std::string cmd = list.substr(start, comma == std::string::npos ? comma : comma - start);
    if (cmd == "track" || cmd == "calibrate" || cmd == "simulate") {
      add(cmd.c_str());
    } else if (cmd == "demo") {
      add("simulate");
      add("track");
      add("calibrate");
    } else if (cmd == "info" || cmd == "posegraph" || cmd == "devices" || cmd == "kernels") {
      throw UsageError("--for " + cmd + ": " + cmd + " runs no kernels, so it needs no binaries");
    } else {
      throw UsageError("--for: \"" + cmd + "\" is not a command that runs kernels (track, calibrate, "
                       "simulate, demo; several separated by commas)");
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return uses;
}

}  // namespace

int cmd_devices(int argc, char** argv) {
  const std::vector<OptionSpec> specs = {{"help", "", "show this help", ""}};
  Args args(specs, argc, argv, 1);
  if (args.has("help")) {
    std::printf("usage: planarvo devices\n\nLists every OpenCL platform and device; the number in the first\n"
                "column is what --device N and PLANARVO_DEVICE=N select.\n");
    return kExitOk;
  }
  if (!args.positionals().empty()) throw UsageError("devices takes no arguments");
  size_t n = 0;
  check(planarvo_list_devices(nullptr, 0, &n));
  if (n == 0) {
    std::fprintf(stderr, "planarvo devices: no OpenCL platform or device found "
                         "(install an ICD, e.g. Debian's pocl-opencl-icd; PoCL also needs a writable "
                         "cache directory: set POCL_CACHE_DIR if HOME and TMPDIR are not writable)\n");
    return kExitNoDevice;
  }
  std::vector<planarvo_device_info> devs(n);
  for (auto& d : devs) d.struct_size = sizeof d;
  check(planarvo_list_devices(devs.data(), devs.size(), &n));
  for (const auto& d : devs) {
    std::printf("%d  %-11s %s / %s\n", d.index, d.device_type, d.platform_name, d.device_name);
    std::printf("   %s; %s; driver %s\n", d.device_version, d.opencl_c_version, d.driver_version);
    std::printf("   image support %s, fp64 %s, local memory %s, global memory %s, max work-group %llu, "
                "compute units %u%s\n",
                d.image_support ? "yes" : "no", d.fp64 ? "yes" : "no", bytes(d.local_mem_size).c_str(),
                bytes(d.global_mem_size).c_str(), static_cast<unsigned long long>(d.max_work_group_size),
                d.compute_units, d.driver_caches_kernels ? ", compiled kernels cached by the driver" : "");
  }
  return kExitOk;
}

int cmd_kernels(int argc, char** argv) {
  std::vector<OptionSpec> specs = {
      {"export", "DIR", "build the kernel programs for the device and write the binaries to DIR", ""},
      {"for", "COMMAND", "only what COMMAND needs: track, calibrate, simulate or demo (several separated by "
                         "commas)", "every command"},
      {"help", "", "show this help", ""}};
  for (auto& s : device_options()) specs.push_back(s);
  Args args(specs, argc, argv, 1);
  if (args.has("help") || !args.has("export")) {
    std::printf("usage: planarvo kernels --export DIR [--for COMMAND] [--device SEL]\n\n"
                "Writes prebuilt program binaries for the selected device into DIR, with a manifest\n"
                "(planarvo-kernels.txt) whose last field says which commands need each binary. By\n"
                "default every kernel variant that any command uses; --for narrows it to what the\n"
                "named commands need (calibrate --motions, posegraph and info need none). No option\n"
                "of track or calibrate changes how kernels are built, so one export serves them all.\n"
                "Pass DIR to --kernel-binaries (or the C API's kernel_binaries_dir) to run without\n"
                "compiling kernels, as FPGA and DSP runtimes require. Exporting again on another\n"
                "device adds its binaries to the same DIR.\n\n%s",
                format_options(specs).c_str());
    return args.has("help") ? kExitOk : kExitUsage;
  }
  if (!args.positionals().empty()) throw UsageError("unexpected argument " + args.positionals()[0]);
  if (args.has("kernel-binaries"))
    throw UsageError("kernels --export builds the binaries, so it cannot load them: leave out --kernel-binaries");
  const std::string uses = args.has("for") ? uses_of_commands(args.get("for")) : std::string();
  ContextPtr ctx = make_context(args);
  const std::string dir = args.get("export");
  size_t n = 0;
  check(planarvo_context_export_kernels_for(ctx.get(), dir.c_str(), uses.c_str(), &n));
  std::printf("wrote %zu kernel binaries%s for %s to %s\n", n,
              uses.empty() ? "" : (" (for " + args.get("for") + ")").c_str(), device_name(ctx.get()).c_str(),
              dir.c_str());
  return kExitOk;
}

}  // namespace planarvo::cli
