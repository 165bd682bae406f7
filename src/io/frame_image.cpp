#include "io/frame_image.h"

#include <algorithm>
#include <fstream>

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

std::string truncation_problem(const unsigned char* head, size_t head_size, const unsigned char* tail,
                               size_t tail_size) {
  // Zero bytes after the image (a card's block padding) are skipped; the marker is then looked
  // for in the last 64 bytes.
  while (tail_size > 0 && tail[tail_size - 1] == 0) --tail_size;
  const size_t from = tail_size > 64 ? tail_size - 64 : 0;
  const auto holds = [&](const unsigned char* marker, size_t n) {
    for (size_t i = from; i + n <= tail_size; ++i)
      if (std::equal(marker, marker + n, tail + i)) return true;
    return false;
  };
  if (head_size >= 3 && head[0] == 0xFF && head[1] == 0xD8 && head[2] == 0xFF) {
    static const unsigned char eoi[2] = {0xFF, 0xD9};
    if (!holds(eoi, 2)) return "the JPEG data end without their end-of-image marker: they were cut short";
  } else if (static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
             head_size >= 8 && std::equal(head, head + 8, png)) {
    static const unsigned char iend[4] = {'I', 'E', 'N', 'D'};
    if (!holds(iend, 4)) return "the PNG data end without their IEND chunk: they were cut short";
  }
  return "";
}

std::string truncation_problem(const unsigned char* data, size_t size) {
  const size_t tail = std::min<size_t>(size, 4096);
  return truncation_problem(data, size, data + size - tail, tail);
}

std::string file_truncation_problem(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";  // the decoder says what is wrong with a file it cannot read
  unsigned char head[8] = {}, tail[4096] = {};
  in.read(reinterpret_cast<char*>(head), sizeof head);
  const auto got = static_cast<size_t>(in.gcount());
  in.clear();
  in.seekg(0, std::ios::end);
  const auto size = static_cast<long long>(in.tellg());
  const long long from = std::max<long long>(0, size - static_cast<long long>(sizeof tail));
  in.seekg(from);
  in.read(reinterpret_cast<char*>(tail), static_cast<std::streamsize>(size - from));
  return truncation_problem(head, got, tail, static_cast<size_t>(in.gcount()));
}

}  // namespace planarvo::io::detail
