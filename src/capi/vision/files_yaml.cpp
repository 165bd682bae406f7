// C API: reading camera.yaml and extrinsics.yaml, which cv::FileStorage parses (so in the vision
// module; their writers and the plain-text formats are in base/files.cpp).
#include <string>
#include <utility>

#include "capi/convert.h"
#include "capi/status.h"
#include "core/error.h"
#include "core/extrinsics_estimate.h"
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

PLANARVO_API planarvo_status planarvo_extrinsics_file_load(const char* path, planarvo_extrinsics_file* file) {
  return guard([&] {
    require_path(path, "planarvo_extrinsics_file_load");
    require(file != nullptr, "planarvo_extrinsics_file_load: file is NULL");
    const planarvo::ExtrinsicsEstimate e = planarvo::io::read_extrinsics_yaml(path);
    for (const auto& [text, name] : {std::pair{&e.method, "method"}, std::pair{&e.notes, "notes"}})
      if (text->size() > PLANARVO_EXTRINSICS_TEXT_MAX)
        planarvo::throw_invalid_input(std::string(path) + ": '" + name + "' is " + std::to_string(text->size()) +
                                      " bytes long; at most " + std::to_string(PLANARVO_EXTRINSICS_TEXT_MAX) +
                                      " are read");
    *file = planarvo_extrinsics_file{};
    file->value = planarvo::capi::to_c(e.value);
    planarvo::capi::matrix_to_c<6>(e.covariance, file->covariance);
    for (size_t i = 0; i < 6; ++i) file->estimated[i] = e.estimated[i] ? 1 : 0;
    planarvo::capi::copy_string(file->method, sizeof file->method, e.method);
    planarvo::capi::copy_string(file->notes, sizeof file->notes, e.notes);
  });
}

}  // extern "C"
