#include "image_input.h"

namespace planarvo_node {

bool to_planarvo_image(const sensor_msgs::Image& m, std::vector<uint8_t>* buffer, planarvo_image* out,
                       std::string* error) {
  size_t bpp = 0;
  planarvo_pixel_format format = PLANARVO_GRAY8;
  bool alpha = false;
  if (m.encoding == "mono8" || m.encoding == "8UC1") {
    bpp = 1;
  } else if (m.encoding == "bgr8") {
    bpp = 3, format = PLANARVO_BGR8;
  } else if (m.encoding == "rgb8") {
    bpp = 3, format = PLANARVO_RGB8;
  } else if (m.encoding == "bgra8") {
    bpp = 4, format = PLANARVO_BGR8, alpha = true;
  } else if (m.encoding == "rgba8") {
    bpp = 4, format = PLANARVO_RGB8, alpha = true;
  } else {
    *error = "encoding \"" + m.encoding + "\" is not one the node takes (mono8, bgr8, rgb8, bgra8, rgba8)";
    return false;
  }
  const size_t w = m.width, h = m.height;
  if (w == 0 || h == 0 || w > 100000 || h > 100000) {
    *error = "image size " + std::to_string(w) + "x" + std::to_string(h) + " is empty or absurd";
    return false;
  }
  if (m.step < w * bpp || m.data.size() < m.step * (h - 1) + w * bpp) {
    *error = "a " + std::to_string(w) + "x" + std::to_string(h) + " " + m.encoding + " image needs step >= " +
             std::to_string(w * bpp) + " and " + std::to_string(m.step * (h - 1) + w * bpp) +
             " bytes of data, the message has step " + std::to_string(m.step) + " and " +
             std::to_string(m.data.size()) + " bytes";
    return false;
  }
  out->width = static_cast<int32_t>(w);
  out->height = static_cast<int32_t>(h);
  out->format = format;
  if (!alpha) {
    out->data = m.data.data();
    out->stride = m.step;
    return true;
  }
  buffer->resize(w * h * 3);
  for (size_t y = 0; y < h; ++y) {
    const uint8_t* src = m.data.data() + y * m.step;
    uint8_t* dst = buffer->data() + y * w * 3;
    for (size_t x = 0; x < w; ++x, src += 4, dst += 3) dst[0] = src[0], dst[1] = src[1], dst[2] = src[2];
  }
  out->data = buffer->data();
  out->stride = w * 3;
  return true;
}

bool to_planarvo_camera(const sensor_msgs::CameraInfo& info, planarvo_camera* c, std::string* error) {
  const std::string& model = info.distortion_model;
  const size_t n = info.D.size();
  const bool plumb_bob = model == "plumb_bob" && (n == 5 || n == 4);
  const bool none = (model.empty() || model == "none") && (n == 0 || n == 5);
  if (!plumb_bob && !none) {
    *error = "CameraInfo distortion model \"" + model + "\" with " + std::to_string(n) +
             " coefficients: the node takes plumb_bob (k1 k2 p1 p2 k3), or give ~camera camera.yaml";
    return false;
  }
  if ((info.binning_x > 1 || info.binning_y > 1) ||
      (info.roi.width != 0 && (info.roi.width != info.width || info.roi.height != info.height))) {
    *error = "CameraInfo with binning or a region of interest is not supported: give ~camera camera.yaml";
    return false;
  }
  if (info.width == 0 || info.height == 0 || !(info.K[0] > 0) || !(info.K[4] > 0)) {
    *error = "CameraInfo without an image size or focal lengths (width " + std::to_string(info.width) + ", height " +
             std::to_string(info.height) + ", fx " + std::to_string(info.K[0]) + ", fy " + std::to_string(info.K[4]) +
             ")";
    return false;
  }
  *c = planarvo_camera{};
  c->width = static_cast<int32_t>(info.width);
  c->height = static_cast<int32_t>(info.height);
  c->fx = info.K[0];
  c->fy = info.K[4];
  c->cx = info.K[2];
  c->cy = info.K[5];
  if (plumb_bob) {  // "none": no distortion, whatever D holds
    c->k1 = info.D[0], c->k2 = info.D[1], c->p1 = info.D[2], c->p2 = info.D[3];
    if (n == 5) c->k3 = info.D[4];
  }
  return true;
}

bool same_camera(const planarvo_camera& a, const planarvo_camera& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.k1 == b.k1 && a.k2 == b.k2 && a.p1 == b.p1 && a.p2 == b.p2 && a.k3 == b.k3;
}

}  // namespace planarvo_node
