// Internal to src/io: a decoded 8-bit image of any channel count as the engine's CV_8UC1 frame,
// checked against the camera. Shared by the data set's image files, videos and bags.
#pragma once
#include <string>

#include <opencv2/core.hpp>

#include "core/camera.h"

namespace planarvo::io::detail {

// CV_8UC1 of the camera's size; colour converted with OpenCV's BGR weights (alpha dropped).
// Not 8-bit, or not the camera's size: InvalidInput whose message starts with `name` and says
// `context` (e.g. "frame 3, frames.txt:5") in parentheses, and `camera_from`, where the camera
// came from ("camera.yaml", "the camera info").
cv::Mat to_grey_checked(const cv::Mat& img, const CameraModel& camera, const std::string& name,
                        const std::string& context, const std::string& camera_from = "camera.yaml");

// What is wrong with an encoded image's bytes that its decoder only warns about ("" when
// nothing): a JPEG whose end-of-image marker (FF D9) is missing from its last 64 bytes (zero
// padding after it skipped), or a PNG without its IEND chunk there: the data were cut short.
// libjpeg decodes a truncated JPEG with a warning on stderr and grey rows where the data
// stopped, which the tracker then loses frames on (issue 27).
std::string truncation_problem(const unsigned char* data, size_t size);
// The width and height an encoded PNG (its IHDR) or JPEG (its first start-of-frame marker, found
// as libjpeg finds it) declares, read from its first bytes without decoding; {0, 0} when the
// data are neither or the header is not within them.
cv::Size declared_size(const unsigned char* data, size_t size);
// "" when the image's declared size is the camera's (or its transpose: EXIF orientation may turn
// it), or not declared; otherwise what is wrong, naming both sizes. Checked before decoding: a
// 300-byte JPEG that declares 18756x16724 pixels made the decoder allocate 1.9 GB (fuzz_image).
std::string declared_size_problem(const unsigned char* data, size_t size, const CameraModel& camera,
                                  const std::string& camera_from = "camera.yaml");
// Both checks, in that order: what an image file or a CompressedImage must pass before decoding.
std::string encoded_image_problem(const unsigned char* data, size_t size, const CameraModel& camera,
                                  const std::string& camera_from = "camera.yaml");

}  // namespace planarvo::io::detail
