// Writing the YAML formats of formats.h, camera.yaml (as OpenCV's calibration sample writes it)
// and extrinsics.yaml (docs/formats.md), in cv::FileStorage's layout but without OpenCV
// (yaml_writer.h), so that the base library writes them. Their readers use cv::FileStorage
// itself (dataset/formats_yaml_read.cpp, in the vision module).
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/error.h"
#include "io/formats.h"
#include "io/yaml_writer.h"

namespace planarvo::io {

void write_camera_yaml(const std::string& path, const CameraModel& camera) {
  try {
    camera.validate(path.c_str());
  } catch (const Error& e) {
    throw_invalid_argument(e.what());
  }
  YamlWriter yaml;
  yaml.write("image_width", camera.width);
  yaml.write("image_height", camera.height);
  const double K[9] = {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
  yaml.write_matrix("camera_matrix", 3, 3, K);
  // 5x1, as calibrateCamera returns it and OpenCV's calibration sample writes it.
  const double D[5] = {camera.k1, camera.k2, camera.p1, camera.p2, camera.k3};
  yaml.write_matrix("distortion_coefficients", 5, 1, D);
  if (!camera.roi.empty())
    yaml.write_flow("region_of_interest", std::vector<int>{camera.roi.x, camera.roi.y, camera.roi.width, camera.roi.height});
  if (camera.rolling_shutter_readout != 0) yaml.write("rolling_shutter_readout", camera.rolling_shutter_readout);
  if (camera.exposure_time != 0) yaml.write("exposure_time", camera.exposure_time);
  yaml.save(path);
}

void write_extrinsics_yaml(const std::string& path, const ExtrinsicsEstimate& e) {
  const std::array<double, 6> values = extrinsics_values(e.value);
  for (double v : values)
    if (!std::isfinite(v)) throw_invalid_argument(path + ": extrinsics are not finite");
  if (!e.covariance.allFinite()) throw_invalid_argument(path + ": covariance is not finite");

  YamlWriter yaml;
  for (size_t i = 0; i < 6; ++i) yaml.write(kExtrinsicsNames[i], values[i]);
  // Row-major, as the file lists a matrix's entries.
  const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> T = e.value.T_vc();
  const Eigen::Matrix<double, 6, 6, Eigen::RowMajor> C = e.covariance;
  yaml.write_matrix("T_robot_camera", 4, 4, T.data());
  yaml.write_matrix("covariance", 6, 6, C.data());
  std::vector<std::string> estimated;
  for (size_t i = 0; i < 6; ++i)
    if (e.estimated[i]) estimated.emplace_back(kExtrinsicsNames[i]);
  yaml.write_block("estimated", estimated, path + ": estimated");
  yaml.write("method", e.method, path + ": method");
  yaml.write("notes", e.notes, path + ": notes");
  yaml.save(path);
}

}  // namespace planarvo::io
