// C API: reading camera.yaml and extrinsics.yaml, which cv::FileStorage parses (so in the vision
// module; their writers and the plain-text formats are in base/files.cpp).
#include <string>

#include "capi/convert.h"
#include "capi/status.h"
#include "io/formats.h"

using planarvo::capi::guard;
using planarvo::capi::require;
using planarvo::capi::require_path;

extern "C" {

PLANARVO_API planarvo_status planarvo_camera_load(const char* path, planarvo_camera* camera) {
  return guard([&] {
    require_path(path, "planarvo_camera_load");
    require(camera != nullptr, "planarvo_camera_load: camera is NULL");
    *camera = planarvo::capi::to_c(planarvo::io::read_camera_yaml(path));
  });
}

PLANARVO_API planarvo_status planarvo_extrinsics_load(const char* path, planarvo_extrinsics* e) {
  return guard([&] {
    require_path(path, "planarvo_extrinsics_load");
    require(e != nullptr, "planarvo_extrinsics_load: extrinsics is NULL");
    *e = planarvo::capi::to_c(planarvo::io::read_extrinsics_yaml(path).value);
  });
}

}  // extern "C"
