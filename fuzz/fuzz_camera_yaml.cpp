// camera.yaml (OpenCV's calibration YAML) through planarvo_camera_load, the entry point the tool
// and the data sets use. A loaded camera must be one the API accepts elsewhere: it saves again.
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace planarvo_fuzz;
  static const std::string in = work_dir() + "/camera.yaml";
  static const std::string out = work_dir() + "/camera_out.yaml";
  write_file(in, data, size);
  planarvo_camera camera;
  const planarvo_status st = planarvo_camera_load(in.c_str(), &camera);
  check_status(st);
  if (st == PLANARVO_OK) {
    if (camera.width <= 0 || camera.height <= 0) broken("camera loaded with a non-positive size");
    for (double v : {camera.fx, camera.fy, camera.cx, camera.cy, camera.k1, camera.k2, camera.p1,
                     camera.p2, camera.k3})
      if (!is_finite(v)) broken("camera loaded with a non-finite value");
    if (planarvo_camera_save(out.c_str(), &camera) != PLANARVO_OK) broken("a loaded camera does not save");
    planarvo_camera again;
    if (planarvo_camera_load(out.c_str(), &again) != PLANARVO_OK) broken("a saved camera does not load");
  } else if (st != PLANARVO_ERROR_INVALID_INPUT) {
    broken("bad camera.yaml gave a status other than INVALID_INPUT");
  }
  return 0;
}
