// An estimate of the camera's extrinsics (core/extrinsics.h): the values, their 6x6 covariance,
// which parameters were estimated and determined by the data, and how they were found. What a
// calibration returns, extrinsics.yaml holds (io/formats.h) and the C API's results carry; the
// one table of the six parameters' names and order.
#pragma once
#include <array>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "core/extrinsics.h"

namespace planarvo {

// The order of the six parameters in every vector, covariance and flag array of extrinsics, and
// their names in extrinsics.yaml, the C API and the command line.
inline constexpr std::array<const char*, 6> kExtrinsicsNames = {"x", "y", "z", "roll", "pitch", "yaw"};

// The index of `name` in kExtrinsicsNames; -1 when it is none of them.
int extrinsics_index(std::string_view name);

// The six values in kExtrinsicsNames' order.
inline std::array<double, 6> extrinsics_values(const Extrinsics& e) { return {e.x, e.y, e.z, e.roll, e.pitch, e.yaw}; }

struct ExtrinsicsEstimate {
  Extrinsics value;
  // Order x, y, z, roll, pitch, yaw (metres, radians); rows and columns of parameters that were
  // not estimated are zero.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::array<bool, 6> estimated{};   // this run estimated it (else it was given or held)
  std::array<bool, 6> observable{};  // estimated and determined by the data (a file does not say: false)
  std::string method;                // how they were found, one sentence ("" when not said)
  std::string notes;                 // where from: the data, the run ("" when not said)
};

}  // namespace planarvo
