// ROS 1 serialisation (http://wiki.ros.org/msg "Serialization" and roscpp's serialization.h):
// little-endian, no alignment or padding; string = uint32 length + bytes (no terminator);
// variable array T[] = uint32 count + elements; fixed array T[N] = N elements; time = uint32
// secs + uint32 nsecs. std_msgs/Header = uint32 seq, time stamp, string frame_id. The message
// definitions are those of ROS Noetic's sensor_msgs 1.13 and nav_msgs 1.13; each has its md5sum.
#include <cstring>

#include "core/error.h"
#include "io/bag/messages_internal.h"

namespace planarvo::io::bag::ros1 {

namespace {

// Reads fields in order; anything that runs past the end is InvalidInput naming the type and
// the byte inside the message.
class Reader {
 public:
  Reader(const uint8_t* data, size_t size, const char* type) : data_(data), size_(size), type_(type) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw_invalid_input(std::string(type_) + ": at byte " + std::to_string(pos_) + " of the message: " +
                        what);
  }
  void need(size_t n, const char* what) const {
    if (n > size_ - pos_)
      fail(std::string(what) + " of " + std::to_string(n) + " bytes runs past the end (" +
           std::to_string(size_ - pos_) + " bytes left)");
  }

  uint8_t u8() {
    need(1, "a uint8");
    return data_[pos_++];
  }
  uint32_t u32() {
    need(4, "a uint32");
    const uint8_t* p = data_ + pos_;
    pos_ += 4;
    return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
           static_cast<uint32_t>(p[3]) << 24;
  }
  double f64() {
    need(8, "a float64");
    uint64_t bits = 0;
    for (int i = 7; i >= 0; --i) bits = bits << 8 | data_[pos_ + static_cast<size_t>(i)];
    pos_ += 8;
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  // The count of a variable array (or the length of a string) of elements of `element` bytes,
  // checked against what remains.
  uint32_t count(size_t element, const char* what) {
    const uint32_t n = u32();
    if (n > (size_ - pos_) / element)
      fail(std::string(what) + " of " + std::to_string(n) + " elements runs past the end (" +
           std::to_string(size_ - pos_) + " bytes left)");
    return n;
  }
  std::string str() {
    const uint32_t n = count(1, "a string");
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return s;
  }
  std::vector<uint8_t> bytes() {
    const uint32_t n = count(1, "a uint8[]");
    std::vector<uint8_t> v(data_ + pos_, data_ + pos_ + n);
    pos_ += n;
    return v;
  }
  template <size_t N>
  void f64s(std::array<double, N>& out) {
    need(8 * N, "a float64 array");
    for (double& v : out) v = f64();
  }
  Header header() {
    Header h;
    u32();  // seq
    const int64_t secs = u32();
    const int64_t nsecs = u32();
    h.stamp_ns = secs * 1000000000 + nsecs;  // at most about 4.3e18: fits int64
    h.frame_id = str();
    return h;
  }
  // A fully decoded message uses every byte: more means another definition.
  void end() const {
    if (pos_ != size_) fail(std::to_string(size_ - pos_) + " bytes after the end of the message");
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  const char* type_;
};

}  // namespace

const char* definition_md5(MessageKind kind) {
  switch (kind) {
    case MessageKind::Image: return "060021388200f6f0f447d0fcd9c64743";
    case MessageKind::CompressedImage: return "8f7a12909da2c9d3332d540a0977563f";
    case MessageKind::CameraInfo: return "c9a58c1b0b154e0e6da7578cb991d214";
    case MessageKind::Odometry: return "cd5e73d190d741a2f92e81eda573aca7";
    case MessageKind::Other: break;
  }
  return "";
}

Header decode_header(const uint8_t* data, size_t size) {
  Reader r(data, size, "std_msgs/Header");
  return r.header();
}

// sensor_msgs/Image: Header header, uint32 height, uint32 width, string encoding,
// uint8 is_bigendian, uint32 step, uint8[] data.
ImageMessage decode_image(const uint8_t* data, size_t size) {
  Reader r(data, size, kind_name(MessageKind::Image));
  ImageMessage m;
  m.header = r.header();
  m.height = r.u32();
  m.width = r.u32();
  m.encoding = r.str();
  m.is_bigendian = r.u8() != 0;
  m.step = r.u32();
  m.data = r.bytes();
  r.end();
  return m;
}

// sensor_msgs/CompressedImage: Header header, string format, uint8[] data.
CompressedImageMessage decode_compressed_image(const uint8_t* data, size_t size) {
  Reader r(data, size, kind_name(MessageKind::CompressedImage));
  CompressedImageMessage m;
  m.header = r.header();
  m.format = r.str();
  m.data = r.bytes();
  r.end();
  return m;
}

// sensor_msgs/CameraInfo: Header header, uint32 height, uint32 width, string distortion_model,
// float64[] D, float64[9] K, float64[9] R, float64[12] P, uint32 binning_x, uint32 binning_y,
// RegionOfInterest roi {uint32 x_offset, y_offset, height, width; bool do_rectify}.
CameraInfoMessage decode_camera_info(const uint8_t* data, size_t size) {
  Reader r(data, size, kind_name(MessageKind::CameraInfo));
  CameraInfoMessage m;
  m.header = r.header();
  m.height = r.u32();
  m.width = r.u32();
  m.distortion_model = r.str();
  m.d.resize(r.count(8, "a float64[] D"));
  for (double& v : m.d) v = r.f64();
  r.f64s(m.k);
  r.f64s(m.r);
  r.f64s(m.p);
  m.binning_x = r.u32();
  m.binning_y = r.u32();
  m.roi.x_offset = r.u32();
  m.roi.y_offset = r.u32();
  m.roi.height = r.u32();
  m.roi.width = r.u32();
  m.roi.do_rectify = r.u8() != 0;
  r.end();
  return m;
}

// nav_msgs/Odometry: Header header, string child_frame_id, PoseWithCovariance pose {Pose pose
// {Point position {x, y, z}; Quaternion orientation {x, y, z, w}}; float64[36] covariance},
// TwistWithCovariance twist {Twist twist {Vector3 linear; Vector3 angular}; float64[36] covariance}.
OdometryMessage decode_odometry(const uint8_t* data, size_t size) {
  Reader r(data, size, kind_name(MessageKind::Odometry));
  OdometryMessage m;
  m.header = r.header();
  m.child_frame_id = r.str();
  r.f64s(m.position);
  r.f64s(m.orientation);
  r.f64s(m.pose_covariance);
  r.f64s(m.linear);
  r.f64s(m.angular);
  r.f64s(m.twist_covariance);
  r.end();
  return m;
}

}  // namespace planarvo::io::bag::ros1
