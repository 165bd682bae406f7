// The two serialisations' decoders behind messages.h's dispatch: messages_ros1.cpp (ROS 1:
// little-endian, no padding, uint32 lengths, strings without terminator, header with seq) and
// messages_cdr.cpp (ROS 2 CDR: a 4-byte encapsulation header, then fields aligned to their size
// relative to the end of it, strings with a length that counts their NUL, header without seq).
#pragma once
#include "io/bag/messages.h"

namespace planarvo::io::bag {
namespace ros1 {
Header decode_header(const uint8_t* data, size_t size);
ImageMessage decode_image(const uint8_t* data, size_t size);
CompressedImageMessage decode_compressed_image(const uint8_t* data, size_t size);
CameraInfoMessage decode_camera_info(const uint8_t* data, size_t size);
OdometryMessage decode_odometry(const uint8_t* data, size_t size);
// The md5sum of the ROS 1 message definition these decoders read ("" for Other): a connection
// whose type has another md5sum was recorded with a different definition under the same name.
const char* definition_md5(MessageKind kind);
}  // namespace ros1
namespace cdr {
Header decode_header(const uint8_t* data, size_t size);
ImageMessage decode_image(const uint8_t* data, size_t size);
CompressedImageMessage decode_compressed_image(const uint8_t* data, size_t size);
CameraInfoMessage decode_camera_info(const uint8_t* data, size_t size);
OdometryMessage decode_odometry(const uint8_t* data, size_t size);
}  // namespace cdr
}  // namespace planarvo::io::bag
