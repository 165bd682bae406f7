// Internal to src/io: a decoded 8-bit image of any channel count as the engine's CV_8UC1 frame,
// checked against the camera. Shared by the data set's image files, videos and bags.
#pragma once
#include <string>

#include <opencv2/core.hpp>

#include "image/camera.h"

namespace planarvo::io::detail {

// CV_8UC1 of the camera's size; colour converted with OpenCV's BGR weights (alpha dropped).
// Not 8-bit, or not the camera's size: InvalidInput whose message starts with `name` and says
// `context` (e.g. "frame 3, frames.txt:5") in parentheses, and `camera_from`, where the camera
// came from ("camera.yaml", "the camera info").
cv::Mat to_grey_checked(const cv::Mat& img, const CameraModel& camera, const std::string& name,
                        const std::string& context, const std::string& camera_from = "camera.yaml");

}  // namespace planarvo::io::detail
