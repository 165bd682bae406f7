#include "io/frame_image.h"

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace planarvo::io::detail {

namespace {

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace

cv::Mat to_grey_checked(const cv::Mat& img, const CameraModel& camera, const std::string& name,
                        const std::string& context, const std::string& camera_from) {
  if (img.depth() != CV_8U)
    throw_invalid_input(name + ": " + (img.depth() == CV_16U ? "a 16-bit" : "a non-8-bit") +
                        " image (" + context + "); planarvo reads 8-bit grey or colour images, "
                        "convert it to 8 bits first");
  if (img.cols != camera.width || img.rows != camera.height)
    throw_invalid_input(name + ": " + size_text(img.cols, img.rows) + " pixels (" + context +
                        "), but " + camera_from + " says " + size_text(camera.width, camera.height));
  cv::Mat grey;
  switch (img.channels()) {
    case 1: grey = img; break;
    case 2: cv::extractChannel(img, grey, 0); break;  // grey + alpha
    case 3: cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY); break;
    case 4: cv::cvtColor(img, grey, cv::COLOR_BGRA2GRAY); break;
    default:
      throw_invalid_input(name + ": an image with " + std::to_string(img.channels()) +
                          " channels (" + context + ")");
  }
  return grey;
}

}  // namespace planarvo::io::detail
