#include "io/bag/messages.h"

#include "io/bag/messages_internal.h"

namespace planarvo::io::bag {

MessageKind message_kind(const std::string& type) {
  if (type == "sensor_msgs/Image" || type == "sensor_msgs/msg/Image") return MessageKind::Image;
  if (type == "sensor_msgs/CompressedImage" || type == "sensor_msgs/msg/CompressedImage")
    return MessageKind::CompressedImage;
  if (type == "sensor_msgs/CameraInfo" || type == "sensor_msgs/msg/CameraInfo") return MessageKind::CameraInfo;
  if (type == "nav_msgs/Odometry" || type == "nav_msgs/msg/Odometry") return MessageKind::Odometry;
  return MessageKind::Other;
}

const char* kind_name(MessageKind kind) {
  switch (kind) {
    case MessageKind::Image: return "sensor_msgs/Image";
    case MessageKind::CompressedImage: return "sensor_msgs/CompressedImage";
    case MessageKind::CameraInfo: return "sensor_msgs/CameraInfo";
    case MessageKind::Odometry: return "nav_msgs/Odometry";
    case MessageKind::Other: break;
  }
  return "another type";
}

#define PLANARVO_DISPATCH(fn) \
  return s == Serialization::Ros1 ? ros1::fn(data, size) : cdr::fn(data, size)

Header decode_header(Serialization s, const uint8_t* data, size_t size) { PLANARVO_DISPATCH(decode_header); }
ImageMessage decode_image(Serialization s, const uint8_t* data, size_t size) { PLANARVO_DISPATCH(decode_image); }
CompressedImageMessage decode_compressed_image(Serialization s, const uint8_t* data, size_t size) {
  PLANARVO_DISPATCH(decode_compressed_image);
}
CameraInfoMessage decode_camera_info(Serialization s, const uint8_t* data, size_t size) {
  PLANARVO_DISPATCH(decode_camera_info);
}
OdometryMessage decode_odometry(Serialization s, const uint8_t* data, size_t size) {
  PLANARVO_DISPATCH(decode_odometry);
}
#undef PLANARVO_DISPATCH

}  // namespace planarvo::io::bag
