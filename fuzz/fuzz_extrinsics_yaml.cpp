// extrinsics.yaml through planarvo_extrinsics_load; a loaded value saves and loads again.
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace planarvo_fuzz;
  static const std::string in = work_dir() + "/extrinsics.yaml";
  static const std::string out = work_dir() + "/extrinsics_out.yaml";
  write_file(in, data, size);
  planarvo_extrinsics e;
  const planarvo_status st = planarvo_extrinsics_load(in.c_str(), &e);
  check_status(st);
  if (st == PLANARVO_OK) {
    for (double v : {e.x, e.y, e.z, e.roll, e.pitch, e.yaw})
      if (!is_finite(v)) broken("extrinsics loaded with a non-finite value");
    double m[16];
    if (planarvo_extrinsics_matrix(&e, m) != PLANARVO_OK) broken("loaded extrinsics give no matrix");
    if (planarvo_extrinsics_save(out.c_str(), &e, nullptr, nullptr, nullptr, nullptr) != PLANARVO_OK)
      broken("loaded extrinsics do not save");
    planarvo_extrinsics again;
    if (planarvo_extrinsics_load(out.c_str(), &again) != PLANARVO_OK) broken("saved extrinsics do not load");
  } else if (st != PLANARVO_ERROR_INVALID_INPUT) {
    broken("bad extrinsics.yaml gave a status other than INVALID_INPUT");
  }
  return 0;
}
