// ROS 2 messages in CDR, as rmw_fastrtps and rmw_cyclonedds write them (plain CDR, XCDR version 1:
// OMG DDS-XTypes 1.3 §7.4.3.5 and CORBA 3.x §9.3 "CDR Transfer Syntax"):
// - a 4-byte encapsulation header: {0x00, 0x00} big-endian or {0x00, 0x01} little-endian CDR,
//   then 2 option bytes (ignored). Other kinds (parameter lists, XCDR2) are refused;
// - each primitive aligned to its size (at most 8) counted from the end of that header;
// - a string: uint32 length counting the terminating NUL, the bytes, the NUL (a length of 0 is
//   taken as an empty string, as some writers emit);
// - a sequence: uint32 element count, then the elements; a fixed array: the elements only.
// The definitions are ROS 2 Humble/Jazzy's (std_msgs/msg/Header has no seq). A header stamp is
// sec * 1e9 + nanosec in int64 exactly (a nanosec of 1e9 or more is not refused, just added).
#include <cstring>

#include "core/error.h"
#include "io/bag/messages_internal.h"

namespace planarvo::io::bag::cdr {

namespace {

constexpr size_t kEncapsulationSize = 4;

class Decoder {
 public:
  Decoder(const uint8_t* data, size_t size, const char* type) : data_(data), size_(size), type_(type) {
    if (size < kEncapsulationSize) fail("the message is shorter than CDR's 4-byte encapsulation header");
    if (data[0] != 0x00 || data[1] > 0x01)
      fail("encapsulation kind 0x" + hex(data[0]) + hex(data[1]) +
           " is not plain CDR; planarvo reads 0x0000 (big-endian) and 0x0001 (little-endian)");
    little_ = data[1] == 0x01;
    pos_ = kEncapsulationSize;
  }

  uint8_t u8(const char* field) { return static_cast<uint8_t>(load(1, field)); }
  bool boolean(const char* field) { return u8(field) != 0; }
  uint32_t u32(const char* field) { return static_cast<uint32_t>(load(4, field)); }
  int32_t i32(const char* field) {
    const uint32_t u = u32(field);
    int32_t v;
    std::memcpy(&v, &u, sizeof v);
    return v;
  }
  double f64(const char* field) {
    const uint64_t u = load(8, field);
    double v;
    std::memcpy(&v, &u, sizeof v);
    return v;
  }

  std::string string(const char* field) {
    const uint32_t n = u32(field);
    if (n == 0) return std::string();
    need(n, field);
    if (data_[pos_ + n - 1] != 0) fail(std::string("the string ") + field + " lacks its terminating NUL");
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n - 1);
    pos_ += n;
    return s;
  }

  // uint8[]: decoded straight into `out` (one copy of an image's pixels).
  void bytes(std::vector<uint8_t>& out, const char* field) {
    const uint32_t n = u32(field);
    need(n, field);
    out.assign(data_ + pos_, data_ + pos_ + n);
    pos_ += n;
  }

  std::vector<double> f64_sequence(const char* field) {
    const uint32_t n = u32(field);
    std::vector<double> out;
    if (n == 0) return out;
    align(8, field);
    if (n > (size_ - pos_) / 8)
      fail(std::string("the sequence ") + field + " of " + std::to_string(n) + " float64 runs past the end");
    out.resize(n);
    for (double& v : out) v = f64(field);
    return out;
  }

  template <size_t N>
  void f64_array(std::array<double, N>& out, const char* field) {
    for (double& v : out) v = f64(field);
  }

  // std_msgs/msg/Header: builtin_interfaces/Time stamp {int32 sec; uint32 nanosec}; string frame_id.
  Header header() {
    Header h;
    const int32_t sec = i32("header.stamp.sec");
    const uint32_t nanosec = u32("header.stamp.nanosec");
    h.stamp_ns = int64_t{sec} * 1000000000 + int64_t{nanosec};
    h.frame_id = string("header.frame_id");
    return h;
  }

 private:
  static std::string hex(uint8_t b) {
    const char digits[] = "0123456789abcdef";
    return {digits[b >> 4], digits[b & 15]};
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw_invalid_input(std::string(type_) + ": at byte " + std::to_string(pos_) + " of the message: " + message);
  }

  void need(size_t n, const char* field) const {
    if (n > size_ - pos_)
      fail(std::string("the field ") + field + " needs " + std::to_string(n) + " bytes, only " +
           std::to_string(size_ - pos_) + " are left (a short or misaligned message)");
  }

  void align(size_t n, const char* field) {
    const size_t pad = (n - (pos_ - kEncapsulationSize) % n) % n;
    need(pad, field);
    pos_ += pad;
  }

  uint64_t load(size_t n, const char* field) {
    align(n, field);
    need(n, field);
    uint64_t v = 0;
    for (size_t i = 0; i < n; ++i) {
      const uint64_t b = data_[pos_ + (little_ ? n - 1 - i : i)];
      v = (v << 8) | b;
    }
    pos_ += n;
    return v;
  }

  const uint8_t* data_;
  size_t size_;
  const char* type_;
  size_t pos_ = 0;
  bool little_ = true;
};

}  // namespace

Header decode_header(const uint8_t* data, size_t size) {
  Decoder d(data, size, "std_msgs/msg/Header");
  return d.header();
}

ImageMessage decode_image(const uint8_t* data, size_t size) {
  Decoder d(data, size, "sensor_msgs/msg/Image");
  ImageMessage m;
  m.header = d.header();
  m.height = d.u32("height");
  m.width = d.u32("width");
  m.encoding = d.string("encoding");
  m.is_bigendian = d.boolean("is_bigendian");
  m.step = d.u32("step");
  d.bytes(m.data, "data");
  return m;
}

CompressedImageMessage decode_compressed_image(const uint8_t* data, size_t size) {
  Decoder d(data, size, "sensor_msgs/msg/CompressedImage");
  CompressedImageMessage m;
  m.header = d.header();
  m.format = d.string("format");
  d.bytes(m.data, "data");
  return m;
}

CameraInfoMessage decode_camera_info(const uint8_t* data, size_t size) {
  Decoder d(data, size, "sensor_msgs/msg/CameraInfo");
  CameraInfoMessage m;
  m.header = d.header();
  m.height = d.u32("height");
  m.width = d.u32("width");
  m.distortion_model = d.string("distortion_model");
  m.d = d.f64_sequence("d");
  d.f64_array(m.k, "k");
  d.f64_array(m.r, "r");
  d.f64_array(m.p, "p");
  m.binning_x = d.u32("binning_x");
  m.binning_y = d.u32("binning_y");
  m.roi.x_offset = d.u32("roi.x_offset");
  m.roi.y_offset = d.u32("roi.y_offset");
  m.roi.height = d.u32("roi.height");
  m.roi.width = d.u32("roi.width");
  m.roi.do_rectify = d.boolean("roi.do_rectify");
  return m;
}

// nav_msgs/msg/Odometry: Header; string child_frame_id; PoseWithCovariance {Pose {Point position;
// Quaternion orientation}; float64[36] covariance}; TwistWithCovariance {Twist {Vector3 linear;
// Vector3 angular}; float64[36] covariance}.
OdometryMessage decode_odometry(const uint8_t* data, size_t size) {
  Decoder d(data, size, "nav_msgs/msg/Odometry");
  OdometryMessage m;
  m.header = d.header();
  m.child_frame_id = d.string("child_frame_id");
  d.f64_array(m.position, "pose.pose.position");
  d.f64_array(m.orientation, "pose.pose.orientation");
  d.f64_array(m.pose_covariance, "pose.covariance");
  d.f64_array(m.linear, "twist.twist.linear");
  d.f64_array(m.angular, "twist.twist.angular");
  d.f64_array(m.twist_covariance, "twist.covariance");
  return m;
}

}  // namespace planarvo::io::bag::cdr
