// The `planarvo` command-line tool: a client of the C API (include/planarvo/planarvo.h) only.
// Exit codes (docs/outputs.md): 0 success; 1 the work ran but failed; 2 bad usage or
// unreadable/invalid input; 3 no usable OpenCL device.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "common.h"

namespace planarvo::cli {

const std::vector<Command>& commands() {
  static const std::vector<Command> all = {
      {"demo", "simulate a short drive over a real texture, run the engine, print accuracy", cmd_demo},
      {"track", "dense visual odometry over a data set: trajectory, statistics, accuracy", cmd_track},
      {"calibrate", "the camera's pose on the robot from a drive (data set) or from motion pairs (CSV)", cmd_calibrate},
      {"posegraph", "optimise a 2-D pose graph (g2o format)", cmd_posegraph},
      {"simulate", "render a synthetic data set with exact ground truth", cmd_simulate},
      {"mosaic", "the floor under a trajectory as one image, with a ROS map_server YAML", cmd_mosaic},
      {"plot", "figures and a calibration report (PNG/PDF/SVG, HTML) from a run's files; needs python3-matplotlib", cmd_plot},
      {"info", "read and check a data set, print what it holds", cmd_info},
      {"devices", "list OpenCL platforms and devices", cmd_devices},
      {"kernels", "export prebuilt kernel binaries for a device (FPGA flows)", cmd_kernels},
  };
  return all;
}

namespace {

void print_usage(FILE* f) {
  std::fprintf(f,
               "planarvo %s: dense planar visual odometry and camera extrinsics autocalibration\n\n"
               "usage: planarvo <command> [options]   (planarvo <command> --help for its options)\n\n"
               "commands:\n",
               planarvo_version_string());
  for (const auto& c : commands()) std::fprintf(f, "  %-10s %s\n", c.name, c.summary);
  std::fprintf(f,
               "  %-10s print the version\n\n"
               "exit codes: 0 success, 1 failed, 2 bad usage or invalid input, 3 no OpenCL device\n",
               "version");
}

}  // namespace
}  // namespace planarvo::cli

int main(int argc, char** argv) {
  using namespace planarvo::cli;
  if (argc < 2) {
    print_usage(stderr);
    return kExitUsage;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    print_usage(stdout);
    return kExitOk;
  }
  if (name == "version" || name == "--version") {
    std::printf("planarvo %s\n", planarvo_version_string());
    return kExitOk;
  }
  for (const auto& c : commands()) {
    if (name != c.name) continue;
    try {
      return c.run(argc - 1, argv + 1);
    } catch (const UsageError& e) {
      std::fprintf(stderr, "planarvo %s: %s\n(see `planarvo %s --help`)\n", c.name, e.what(), c.name);
      return kExitUsage;
    } catch (const ApiError& e) {
      std::fprintf(stderr, "planarvo %s: %s\n", c.name, e.what());
      return e.exit_code();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "planarvo %s: internal error: %s\n", c.name, e.what());
      return kExitFailed;
    }
  }
  std::fprintf(stderr, "planarvo: unknown command \"%s\"\n\n", name.c_str());
  print_usage(stderr);
  return kExitUsage;
}
