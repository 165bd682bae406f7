// The structs behind the C API's opaque handles. Only src/capi includes this.
#pragma once
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "io/dataset/dataset.h"
#include "ocl/runtime.h"
#include "planarvo/planarvo.h"

struct planarvo_context {
  std::unique_ptr<planarvo::ocl::Runtime> runtime;
};

struct planarvo_dataset {
  std::unique_ptr<planarvo::io::Dataset> dataset;
  cv::Mat frame;  // the last decoded frame, which planarvo_dataset_frame's image points into
};
