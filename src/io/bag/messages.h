// The messages planarvo reads from a bag, decoded from ROS 1 serialisation or ROS 2 CDR into
// one set of plain structs. Field names follow the ROS message definitions. A header stamp is
// kept as integer nanoseconds (sec * 1e9 + nanosec) so that no precision is lost before it is
// made relative to the first frame.
//
// Errors: bytes that end early, a length that runs past the end, a string without its CDR
// terminator, an array of the wrong fixed size: Error(InvalidInput) naming the message type and
// the byte offset inside the message. The caller adds the file and message position.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io/bag/bag.h"

namespace planarvo::io::bag {

enum class MessageKind { Image, CompressedImage, CameraInfo, Odometry, Other };

// "sensor_msgs/Image" and "sensor_msgs/msg/Image" are both Image; anything else is Other.
MessageKind message_kind(const std::string& type);
// The type's name in the form `type` uses ("sensor_msgs/Image" or "sensor_msgs/msg/Image").
const char* kind_name(MessageKind kind);

struct Header {
  int64_t stamp_ns = 0;
  std::string frame_id;
};

struct ImageMessage {  // sensor_msgs/Image
  Header header;
  uint32_t height = 0, width = 0;
  std::string encoding;  // "mono8", "bgr8", "rgb8", "bayer_rggb8", ...
  bool is_bigendian = false;
  uint32_t step = 0;     // bytes per row
  std::vector<uint8_t> data;
};

struct CompressedImageMessage {  // sensor_msgs/CompressedImage
  Header header;
  std::string format;    // "jpeg", "png", "mono8; jpeg compressed mono8", ...
  std::vector<uint8_t> data;
};

struct CameraInfoMessage {  // sensor_msgs/CameraInfo
  Header header;
  uint32_t height = 0, width = 0;
  std::string distortion_model;  // "plumb_bob", "rational_polynomial", "equidistant", ""
  std::vector<double> d;
  std::array<double, 9> k{};     // row-major 3x3
  std::array<double, 9> r{};
  std::array<double, 12> p{};
  uint32_t binning_x = 0, binning_y = 0;
  struct { uint32_t x_offset = 0, y_offset = 0, height = 0, width = 0; bool do_rectify = false; } roi;
};

struct OdometryMessage {  // nav_msgs/Odometry
  Header header;
  std::string child_frame_id;
  std::array<double, 3> position{};     // x y z
  std::array<double, 4> orientation{};  // x y z w
  std::array<double, 36> pose_covariance{};
  std::array<double, 3> linear{}, angular{};
  std::array<double, 36> twist_covariance{};
};

ImageMessage decode_image(Serialization s, const uint8_t* data, size_t size);
CompressedImageMessage decode_compressed_image(Serialization s, const uint8_t* data, size_t size);
CameraInfoMessage decode_camera_info(Serialization s, const uint8_t* data, size_t size);
OdometryMessage decode_odometry(Serialization s, const uint8_t* data, size_t size);

// Only the header, without decoding the rest (an image's pixels are not copied).
Header decode_header(Serialization s, const uint8_t* data, size_t size);

}  // namespace planarvo::io::bag
