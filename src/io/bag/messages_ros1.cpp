// STUB: replaced by the real decoder.
#include "core/error.h"
#include "io/bag/messages_internal.h"

namespace planarvo::io::bag::ros1 {
Header decode_header(const uint8_t*, size_t) { throw_invalid_input("not implemented"); }
ImageMessage decode_image(const uint8_t*, size_t) { throw_invalid_input("not implemented"); }
CompressedImageMessage decode_compressed_image(const uint8_t*, size_t) { throw_invalid_input("not implemented"); }
CameraInfoMessage decode_camera_info(const uint8_t*, size_t) { throw_invalid_input("not implemented"); }
OdometryMessage decode_odometry(const uint8_t*, size_t) { throw_invalid_input("not implemented"); }
}  // namespace planarvo::io::bag::ros1
