#include "io/dataset/frame_image.h"

#include <algorithm>
#include <cstdint>

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

std::string truncation_problem(const unsigned char* data, size_t size) {
  // Zero bytes after the image (a card's block padding) are skipped; the marker is then looked
  // for in the last 64 bytes.
  size_t end = size;
  while (end > 0 && data[end - 1] == 0) --end;
  const size_t from = end > 64 ? end - 64 : 0;
  const auto holds = [&](const unsigned char* marker, size_t n) {
    for (size_t i = from; i + n <= end; ++i)
      if (std::equal(marker, marker + n, data + i)) return true;
    return false;
  };
  if (size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF) {
    static const unsigned char eoi[2] = {0xFF, 0xD9};
    if (!holds(eoi, 2)) return "the JPEG data end without their end-of-image marker: they were cut short";
  } else if (static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
             size >= 8 && std::equal(data, data + 8, png)) {
    static const unsigned char iend[4] = {'I', 'E', 'N', 'D'};
    if (!holds(iend, 4)) return "the PNG data end without their IEND chunk: they were cut short";
  }
  return "";
}

cv::Size declared_size(const unsigned char* data, size_t size) {
  const auto be16 = [&](size_t at) { return static_cast<int>(data[at]) << 8 | data[at + 1]; };
  const auto be32 = [&](size_t at) {
    return static_cast<uint32_t>(be16(at)) << 16 | static_cast<uint32_t>(be16(at + 2));
  };
  static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (size >= 24 && std::equal(png, png + 8, data) && std::equal(data + 12, data + 16, "IHDR")) {
    const uint32_t w = be32(16), h = be32(20);
    if (w > 0x7FFFFFFFu || h > 0x7FFFFFFFu) return {-1, -1};  // beyond any image: PNG forbids it
    return {static_cast<int>(w), static_cast<int>(h)};
  }
  if (size < 4 || data[0] != 0xFF || data[1] != 0xD8) return {0, 0};
  // Markers after SOI: bytes before a marker's FF are skipped (libjpeg warns "extraneous bytes"
  // and goes on), fill FFs too; standalone markers have no length.
  size_t at = 2;
  while (at + 1 < size) {
    if (data[at] != 0xFF) {
      ++at;
      continue;
    }
    while (at + 1 < size && data[at + 1] == 0xFF) ++at;
    if (at + 1 >= size) break;
    const int marker = data[at + 1];
    if (marker == 0xD9 || marker == 0xDA) break;  // end of image, start of scan: no frame header
    if (marker == 0x00 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {
      at += 2;
      continue;
    }
    if (at + 4 > size) break;
    const size_t length = static_cast<size_t>(be16(at + 2));
    const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame) {
      if (at + 9 > size) break;
      return {be16(at + 7), be16(at + 5)};  // P, Y (height), X (width)
    }
    at += 2 + length;
  }
  return {0, 0};
}

std::string declared_size_problem(const unsigned char* data, size_t size, const CameraModel& camera,
                                  const std::string& camera_from) {
  const cv::Size s = declared_size(data, size);
  if (s == cv::Size(0, 0)) return "";
  if ((s.width == camera.width && s.height == camera.height) || (s.width == camera.height && s.height == camera.width))
    return "";
  const std::string declared = s.width < 0 ? "over 2^31 pixels on a side" : size_text(s.width, s.height);
  return "the image declares " + declared + " pixels, but " + camera_from + " says " +
         size_text(camera.width, camera.height) + " (not decoded)";
}

std::string encoded_image_problem(const unsigned char* data, size_t size, const CameraModel& camera,
                                  const std::string& camera_from) {
  if (std::string cut = truncation_problem(data, size); !cut.empty()) return cut;
  return declared_size_problem(data, size, camera, camera_from);
}

}  // namespace planarvo::io::detail
