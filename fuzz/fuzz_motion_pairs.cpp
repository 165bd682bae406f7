// The motion-pair CSV through planarvo_motion_pairs_load (count first, then the pairs, as the
// header says), then the loaded pairs saved and loaded again, and a short calibration on them.
#include <cstring>
#include <vector>

#include "fuzz_common.h"

namespace {
void check_pair(const planarvo_motion_pair& p) {
  using planarvo_fuzz::broken;
  using planarvo_fuzz::is_finite;
  if (!is_finite(p.interval) || !is_finite(p.sensor.x) || !is_finite(p.sensor.y) || !is_finite(p.sensor.theta))
    broken("a loaded pair with a non-finite value");
  if (p.has_odometry && !(is_finite(p.odometry.x) && is_finite(p.odometry.y) && is_finite(p.odometry.theta)))
    broken("a loaded pair with non-finite odometry");
  if (p.has_direction && (p.direction < -1 || p.direction > 1)) broken("a direction label outside -1..1");
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace planarvo_fuzz;
  static const std::string in = work_dir() + "/pairs.csv";
  static const std::string out = work_dir() + "/pairs_out.csv";
  write_file(in, data, size);
  size_t count = 0;
  planarvo_status st = planarvo_motion_pairs_load(in.c_str(), nullptr, 0, &count);
  check_status(st);
  if (st != PLANARVO_OK) {
    if (st != PLANARVO_ERROR_INVALID_INPUT) broken("a bad motion-pair CSV gave a status other than INVALID_INPUT");
    return 0;
  }
  if (count > size) broken("more pairs than bytes");
  std::vector<planarvo_motion_pair> pairs(count + 1);
  for (auto& p : pairs) planarvo_motion_pair_init(&p);
  if (count > 0) {
    size_t again = 0;
    if (planarvo_motion_pairs_load(in.c_str(), pairs.data(), count - 1, &again) != PLANARVO_ERROR_BUFFER_TOO_SMALL)
      broken("a too small buffer was not refused");
  }
  size_t loaded = 0;
  if (planarvo_motion_pairs_load(in.c_str(), pairs.data(), pairs.size(), &loaded) != PLANARVO_OK || loaded != count)
    broken("the second load differs from the first");
  for (size_t i = 0; i < count; ++i) check_pair(pairs[i]);
  if (planarvo_motion_pairs_save(out.c_str(), pairs.data(), count) != PLANARVO_OK) broken("loaded pairs do not save");
  size_t reloaded = 0;
  if (planarvo_motion_pairs_load(out.c_str(), nullptr, 0, &reloaded) != PLANARVO_OK || reloaded != count)
    broken("saved pairs do not load back");
  // The calibration on what was read: any status but a crash (few iterations keep it fast).
  planarvo_calibration_options options;
  planarvo_calibration_options_init(&options);
  options.max_iterations = 5;
  planarvo_calibration_result result;
  std::memset(&result, 0, sizeof result);
  result.struct_size = sizeof result;
  check_status(planarvo_calibrate(pairs.data(), count, &options, &result));
  return 0;
}
