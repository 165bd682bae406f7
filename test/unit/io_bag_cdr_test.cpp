// The ROS 2 CDR decoders (src/io/bag/messages_cdr.cpp) on hand-built bytes (io_bag_mcap_bytes.h):
// both byte orders, alignment, and every way the bytes can be short or wrong. The files written
// by the official CDR writer are decoded in io_bag_mcap_test.cpp.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "io_bag_mcap_bytes.h"
#include "core/error.h"
#include "io/bag/messages.h"

namespace {

using planarvo::Error;
using planarvo::ErrorCode;
using namespace planarvo::io::bag;
using planarvo_test::CdrBytes;

constexpr Serialization kCdr = Serialization::Cdr;

// The InvalidInput message of decoding `bytes` as `kind`, or "" when it decoded.
std::string error_of(MessageKind kind, const std::vector<uint8_t>& bytes) {
  try {
    const uint8_t* p = bytes.data();
    const size_t n = bytes.size();
    if (kind == MessageKind::Image) decode_image(kCdr, p, n);
    if (kind == MessageKind::CompressedImage) decode_compressed_image(kCdr, p, n);
    if (kind == MessageKind::CameraInfo) decode_camera_info(kCdr, p, n);
    if (kind == MessageKind::Odometry) decode_odometry(kCdr, p, n);
    if (kind == MessageKind::Other) decode_header(kCdr, p, n);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidInput);
    return e.what();
  }
  return "";
}

CdrBytes image(bool little) {
  CdrBytes b(little);
  b.header(1700000000, 123456789, "cam").u32(2).u32(3).str("mono8").u8(0).u32(4);
  b.seq({1, 2, 3, 4, 5, 6, 7, 8});
  return b;
}

CdrBytes camera_info(bool little) {
  CdrBytes b(little);
  b.header(5, 6, "c").u32(480).u32(640).str("plumb_bob");
  b.u32(5);
  for (int i = 0; i < 5; ++i) b.f64(0.1 * (i + 1));
  for (int i = 0; i < 9 + 9 + 12; ++i) b.f64(i);
  b.u32(1).u32(2).u32(3).u32(4).u32(5).u32(6).u8(1);
  return b;
}

TEST(BagCdr, ImageInBothByteOrders) {
  for (const bool little : {true, false}) {
    SCOPED_TRACE(little);
    const std::vector<uint8_t> bytes = image(little).bytes;
    const ImageMessage m = decode_image(kCdr, bytes.data(), bytes.size());
    EXPECT_EQ(m.header.stamp_ns, 1700000000123456789);
    EXPECT_EQ(m.header.frame_id, "cam");
    EXPECT_EQ(m.height, 2u);
    EXPECT_EQ(m.width, 3u);
    EXPECT_EQ(m.encoding, "mono8");
    EXPECT_FALSE(m.is_bigendian);
    EXPECT_EQ(m.step, 4u);
    EXPECT_EQ(m.data, (std::vector<uint8_t>{1, 2, 3, 4, 5, 6, 7, 8}));
    EXPECT_EQ(decode_header(kCdr, bytes.data(), bytes.size()).stamp_ns, 1700000000123456789);
  }
}

TEST(BagCdr, CameraInfoAlignsTheDoublesAfterTheString) {
  for (const bool little : {true, false}) {
    SCOPED_TRACE(little);
    const std::vector<uint8_t> bytes = camera_info(little).bytes;
    const CameraInfoMessage m = decode_camera_info(kCdr, bytes.data(), bytes.size());
    EXPECT_EQ(m.header.stamp_ns, 5000000006);
    EXPECT_EQ(m.distortion_model, "plumb_bob");
    EXPECT_EQ(m.d, (std::vector<double>{0.1, 0.2, 0.1 * 3, 0.4, 0.5}));
    EXPECT_EQ(m.k[8], 8.0);
    EXPECT_EQ(m.r[0], 9.0);
    EXPECT_EQ(m.p[11], 29.0);
    EXPECT_EQ(m.binning_x, 1u);
    EXPECT_EQ(m.roi.width, 6u);
    EXPECT_TRUE(m.roi.do_rectify);
  }
}

TEST(BagCdr, OdometryAndANegativeStamp) {
  CdrBytes b;
  b.header(-2, 5, "odom").str("base_link");
  for (int i = 0; i < 3 + 4 + 36 + 3 + 3 + 36; ++i) b.f64(i + 0.5);
  const OdometryMessage m = decode_odometry(kCdr, b.bytes.data(), b.bytes.size());
  EXPECT_EQ(m.header.stamp_ns, -1999999995);
  EXPECT_EQ(m.child_frame_id, "base_link");
  EXPECT_EQ(m.position[0], 0.5);
  EXPECT_EQ(m.orientation[3], 6.5);
  EXPECT_EQ(m.pose_covariance[35], 42.5);
  EXPECT_EQ(m.linear[0], 43.5);
  EXPECT_EQ(m.angular[2], 48.5);
  EXPECT_EQ(m.twist_covariance[35], 84.5);
  b.bytes.pop_back();
  EXPECT_NE(error_of(MessageKind::Odometry, b.bytes).find("twist.covariance"), std::string::npos);
}

// nanosec >= 1e9 is not refused: added exactly (documented in messages_cdr.cpp).
TEST(BagCdr, ANanosecOfASecondOrMoreIsAddedExactly) {
  CdrBytes b;
  b.header(1, 1500000000, "");
  EXPECT_EQ(decode_header(kCdr, b.bytes.data(), b.bytes.size()).stamp_ns, 2500000000);
}

TEST(BagCdr, DecodesFromAnOddAddress) {  // no aligned loads from the buffer (UBSan would see them)
  const std::vector<uint8_t> bytes = camera_info(true).bytes;
  std::vector<uint8_t> shifted(bytes.size() + 1);
  std::copy(bytes.begin(), bytes.end(), shifted.begin() + 1);
  EXPECT_EQ(decode_camera_info(kCdr, shifted.data() + 1, bytes.size()).p[11], 29.0);
}

TEST(BagCdr, EveryShortBufferIsInvalidInput) {
  const std::vector<uint8_t> full = camera_info(true).bytes;
  for (size_t n = 0; n < full.size(); ++n) {
    const std::vector<uint8_t> cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
    const std::string e = error_of(MessageKind::CameraInfo, cut);
    EXPECT_NE(e.find("sensor_msgs/msg/CameraInfo: at byte "), std::string::npos) << n << ": " << e;
  }
  const std::vector<uint8_t> img = image(false).bytes;
  for (size_t n = 0; n < img.size(); ++n)
    EXPECT_NE(error_of(MessageKind::Image, std::vector<uint8_t>(img.begin(), img.begin() + static_cast<std::ptrdiff_t>(n))),
              "")
        << n;
}

TEST(BagCdr, BadEncapsulationStringsAndLengths) {
  std::vector<uint8_t> pl = image(true).bytes;
  pl[1] = 0x03;  // PL_CDR_LE: parameter lists, not plain CDR
  EXPECT_NE(error_of(MessageKind::Image, pl).find("encapsulation kind 0x0003"), std::string::npos);
  std::vector<uint8_t> xcdr2 = image(true).bytes;
  xcdr2[1] = 0x07;
  EXPECT_NE(error_of(MessageKind::Image, xcdr2), "");

  CdrBytes no_nul;
  no_nul.i32(1).u32(2).u32(3);
  no_nul.bytes.insert(no_nul.bytes.end(), {'a', 'b', 'c'});
  EXPECT_NE(error_of(MessageKind::Other, no_nul.bytes).find("NUL"), std::string::npos);

  CdrBytes long_string;
  long_string.i32(1).u32(2).u32(1000).u8('a').u8(0);
  EXPECT_NE(error_of(MessageKind::Other, long_string.bytes).find("at byte 16"), std::string::npos);

  CdrBytes long_data;
  long_data.header(1, 2, "c").str("png").u32(0xFFFFFFFFu).u8(1);
  EXPECT_NE(error_of(MessageKind::CompressedImage, long_data.bytes).find("data needs 4294967295 bytes"),
            std::string::npos);

  CdrBytes many_doubles;
  many_doubles.header(1, 2, "c").u32(1).u32(1).str("x").u32(0x20000000u).f64(1.0);
  EXPECT_NE(error_of(MessageKind::CameraInfo, many_doubles.bytes).find("sequence d"), std::string::npos);
}

TEST(BagCdr, AnEmptyStringOfLengthZeroIsAccepted) {
  CdrBytes b;
  b.i32(3).u32(4).u32(0);
  const Header h = decode_header(kCdr, b.bytes.data(), b.bytes.size());
  EXPECT_EQ(h.frame_id, "");
  EXPECT_EQ(h.stamp_ns, 3000000004);
}

}  // namespace
