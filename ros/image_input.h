// From ROS messages to the C API's types: sensor_msgs/Image to planarvo_image (no copy for mono8,
// bgr8 and rgb8; bgra8 and rgba8 lose their alpha into a buffer, so that the library converts every
// colour image to grey the same way), sensor_msgs/CameraInfo (plumb_bob) to planarvo_camera.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <planarvo/planarvo.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

namespace planarvo_node {

// image -> *out, pointing into the message or into *buffer. False with *error saying why (an
// encoding the node does not take, a step or data size that does not hold the image).
bool to_planarvo_image(const sensor_msgs::Image& image, std::vector<uint8_t>* buffer, planarvo_image* out,
                       std::string* error);

// A plumb_bob (k1 k2 p1 p2 k3) or undistorted ("" or "none" with no coefficients) CameraInfo.
bool to_planarvo_camera(const sensor_msgs::CameraInfo& info, planarvo_camera* camera, std::string* error);

bool same_camera(const planarvo_camera& a, const planarvo_camera& b);

}  // namespace planarvo_node
