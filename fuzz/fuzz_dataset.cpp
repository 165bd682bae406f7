// The data set's text files through planarvo_dataset_open, as the tool reads them: a fixed data
// set (camera.yaml, frames.txt with 20 frames at 10 Hz, empty image files that are stat'ed but not
// decoded) in which one file, PLANARVO_FUZZ_FILE (frames.txt, odometry.txt or direction.txt), is
// the input. An opened data set is then queried for every frame's odometry and direction label.
#include <cstring>
#include <vector>

#include "fuzz_common.h"

#ifndef PLANARVO_FUZZ_FILE
#error "PLANARVO_FUZZ_FILE names the data set file this target fuzzes"
#endif

namespace {

constexpr int kFrames = 20;

const std::string& dataset_dir() {
  static const std::string dir = [] {
    using planarvo_fuzz::work_dir;
    const std::string d = work_dir() + "/dataset";
    std::filesystem::create_directories(d + "/images");
    planarvo_camera camera;
    if (planarvo_sim_default_camera(160, 120, 80.0, &camera) != PLANARVO_OK ||
        planarvo_camera_save((d + "/camera.yaml").c_str(), &camera) != PLANARVO_OK)
      planarvo_fuzz::broken("cannot write the fixture's camera.yaml");
    std::string frames = "# timestamp path\n";
    for (int i = 0; i < kFrames; ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "images/%06d.png", i);
      std::ofstream(d + "/" + name).close();  // stat'ed at open, decoded only on request
      frames += std::to_string(0.1 * i) + " " + name + "\n";
    }
    std::ofstream(d + "/frames.txt") << frames;
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace planarvo_fuzz;
  const std::string& dir = dataset_dir();
  write_file(dir + "/" + PLANARVO_FUZZ_FILE, data, size);
  planarvo_dataset* dataset = nullptr;
  const planarvo_status st = planarvo_dataset_open(dir.c_str(), nullptr, &dataset);
  check_status(st);
  if (st != PLANARVO_OK) {
    if (dataset) broken("a failed open returned a handle");
    if (st != PLANARVO_ERROR_INVALID_INPUT) broken("a bad data set file gave a status other than INVALID_INPUT");
    return 0;
  }
  planarvo_dataset_info info;
  std::memset(&info, 0, sizeof info);
  info.struct_size = sizeof info;
  if (planarvo_dataset_info_get(dataset, &info) != PLANARVO_OK) broken("no info for an opened data set");
  if (info.frame_count <= 0) broken("an opened data set without frames");
  if (!is_finite(info.first_timestamp) || !is_finite(info.last_timestamp) || info.first_timestamp > info.last_timestamp)
    broken("bad first/last timestamps");
  const int64_t n = info.frame_count < 4096 ? info.frame_count : 4096;
  for (int64_t i = -1; i <= n; ++i) {  // one index each side out of range
    planarvo_frame_data fd;
    const planarvo_status fs = planarvo_dataset_frame_data(dataset, i, &fd);
    check_status(fs);
    const bool in_range = i >= 0 && i < info.frame_count;
    if ((fs == PLANARVO_OK) != in_range) broken("frame_data accepted an index out of range or refused one in range");
    if (fs != PLANARVO_OK) continue;
    if (!is_finite(fd.timestamp)) broken("a non-finite frame time");
    if (fd.has_odometry && !(is_finite(fd.odometry.x) && is_finite(fd.odometry.y) && is_finite(fd.odometry.theta)))
      broken("non-finite interpolated odometry");
    if (fd.has_direction && (fd.direction < -1 || fd.direction > 1)) broken("a direction label outside -1..1");
  }
  planarvo_dataset_destroy(dataset);
  return 0;
}
