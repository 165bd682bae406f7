// The simulated drive on the command line and what a drive looks like against its ground truth:
// shared by `planarvo simulate`, `info` and `demo`.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "common.h"

namespace planarvo::cli {

double seconds_since(std::chrono::steady_clock::time_point t0);

// The built-in texture: installed beside the tool (../share/planarvo/textures), else the source
// tree's copy.
std::string default_texture();

// simulate's options (demo takes them too).
std::vector<OptionSpec> simulate_options();
// Fills sim options from the command line over the library's defaults; *texture holds the
// texture's path that o->texture points into.
void apply_simulate_args(const Args& a, planarvo_sim_options* o, std::string* texture);

// What a trajectory and its wheel odometry look like against ground truth.
struct DriveSummary {
  double distance = 0, peak_speed = 0, peak_turn = 0;
  int forward = 0, backward = 0, still = 0;
  bool has_odometry = false;
  double odo_end_error = 0, odo_heading_error = 0, odo_rms_step = 0;
};

// Frames 0..n-1 of the data set against its ground truth.
DriveSummary summarise(planarvo_dataset* ds, int64_t n);

}  // namespace planarvo::cli
