// The ROS 1 bag reader (src/io/bag/rosbag1.cpp) and decoders (messages_ros1.cpp) against bags
// written by Debian's python3-rosbag, the official writer: test/tools/rosbag/write_test_bags.py
// writes them with a sidecar of every message's topic, receive time, serialised bytes (length
// and FNV-1a) and decoded fields, computed by the ROS message classes.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "core/error.h"
#include "io/bag/bag.h"
#include "io/bag/messages.h"

#ifndef PLANARVO_HAVE_BZ2
#define PLANARVO_HAVE_BZ2 1  // as src/io/bag/rosbag1_decompress.cpp assumes without CMake's definitions
#endif
#ifndef PLANARVO_HAVE_LZ4
#define PLANARVO_HAVE_LZ4 1
#endif

namespace planarvo::io::bag {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string fnv1a(const uint8_t* data, size_t n) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < n; ++i) h = (h ^ data[i]) * 0x100000001b3ull;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}
std::string fnv1a(const std::vector<uint8_t>& v) { return fnv1a(v.data(), v.size()); }

struct ExpectedMessage {
  std::string topic;
  int64_t receive_ns = 0;
  size_t raw_len = 0;
  std::string raw_fnv, kind;
  std::vector<std::string> fields;  // after KIND
};

struct Expected {
  std::vector<TopicInfo> topics;  // sorted by name
  std::vector<ExpectedMessage> messages;
  int64_t error_byte = -1;
};

Expected read_sidecar(const std::string& path) {
  Expected e;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string what;
    s >> what;
    if (what == "topic") {
      TopicInfo t;
      s >> t.name >> t.type >> t.md5sum >> t.count;
      e.topics.push_back(t);
    } else if (what == "msg") {
      ExpectedMessage m;
      s >> m.topic >> m.receive_ns >> m.raw_len >> m.raw_fnv >> m.kind;
      for (std::string f; s >> f;) m.fields.push_back(f);
      e.messages.push_back(m);
    } else if (what == "error") {
      s >> e.error_byte;
    }
  }
  EXPECT_FALSE(e.messages.empty()) << path;
  return e;
}

// Compares a decoded message with its sidecar fields.
class FieldCursor {
 public:
  explicit FieldCursor(const ExpectedMessage& m) : m_(m) {}
  std::string next() {
    if (k_ >= m_.fields.size()) {
      ADD_FAILURE() << "the sidecar line of " << m_.topic << " is short";
      return "0";
    }
    return m_.fields[k_++];
  }
  int64_t i64() { return std::stoll(next()); }
  double f64() { return std::strtod(next().c_str(), nullptr); }
  template <typename Container>
  void floats(const Container& got, const char* what) {
    for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], f64()) << m_.topic << " " << what << "[" << i << "]";
  }
  void header(const Header& h) {
    EXPECT_EQ(h.stamp_ns, i64()) << m_.topic;
    EXPECT_EQ(h.frame_id, next()) << m_.topic;
  }
  void done() const { EXPECT_EQ(k_, m_.fields.size()) << m_.topic; }

 private:
  const ExpectedMessage& m_;
  size_t k_ = 0;
};

void check_decoded(const ExpectedMessage& e, const std::vector<uint8_t>& raw) {
  FieldCursor f(e);
  const Serialization s = Serialization::Ros1;
  if (e.kind == "image") {
    const ImageMessage m = decode_image(s, raw.data(), raw.size());
    f.header(m.header);
    EXPECT_EQ(m.height, f.i64());
    EXPECT_EQ(m.width, f.i64());
    EXPECT_EQ(m.encoding, f.next());
    EXPECT_EQ(m.is_bigendian, f.i64() != 0);
    EXPECT_EQ(m.step, f.i64());
    EXPECT_EQ(static_cast<int64_t>(m.data.size()), f.i64());
    EXPECT_EQ(fnv1a(m.data), f.next());
    EXPECT_GT(m.step, m.width * (m.encoding == "bgr8" ? 3u : 1u));
  } else if (e.kind == "compressed") {
    const CompressedImageMessage m = decode_compressed_image(s, raw.data(), raw.size());
    f.header(m.header);
    EXPECT_EQ(m.format, f.next());
    EXPECT_EQ(static_cast<int64_t>(m.data.size()), f.i64());
    EXPECT_EQ(fnv1a(m.data), f.next());
  } else if (e.kind == "camera_info") {
    const CameraInfoMessage m = decode_camera_info(s, raw.data(), raw.size());
    f.header(m.header);
    EXPECT_EQ(m.height, f.i64());
    EXPECT_EQ(m.width, f.i64());
    EXPECT_EQ(m.distortion_model, f.next());
    EXPECT_EQ(static_cast<int64_t>(m.d.size()), f.i64());
    f.floats(m.d, "D");
    f.floats(m.k, "K");
    f.floats(m.r, "R");
    f.floats(m.p, "P");
    EXPECT_EQ(m.binning_x, f.i64());
    EXPECT_EQ(m.binning_y, f.i64());
    EXPECT_EQ(m.roi.x_offset, f.i64());
    EXPECT_EQ(m.roi.y_offset, f.i64());
    EXPECT_EQ(m.roi.height, f.i64());
    EXPECT_EQ(m.roi.width, f.i64());
    EXPECT_EQ(m.roi.do_rectify, f.i64() != 0);
  } else if (e.kind == "odometry") {
    const OdometryMessage m = decode_odometry(s, raw.data(), raw.size());
    f.header(m.header);
    EXPECT_EQ(m.child_frame_id, f.next());
    f.floats(m.position, "position");
    f.floats(m.orientation, "orientation");
    f.floats(m.pose_covariance, "pose covariance");
    f.floats(m.linear, "linear");
    f.floats(m.angular, "angular");
    f.floats(m.twist_covariance, "twist covariance");
  } else {
    EXPECT_EQ(e.kind, "other");
  }
  f.done();
}

std::vector<uint32_t> all_topics(const BagFile& bag) {
  std::vector<uint32_t> t(bag.topics().size());
  for (uint32_t i = 0; i < t.size(); ++i) t[i] = i;
  return t;
}

uint32_t topic_index(const BagFile& bag, const std::string& name) {
  for (uint32_t i = 0; i < bag.topics().size(); ++i)
    if (bag.topics()[i].name == name) return i;
  ADD_FAILURE() << "no topic " << name;
  return 0;
}

// Runs f, expecting Error(code) whose message contains every one of `parts`; returns the message.
template <typename F>
std::string expect_error(F&& f, ErrorCode code, const std::vector<std::string>& parts) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(static_cast<int>(e.code()), static_cast<int>(code)) << e.what();
    for (const std::string& p : parts) EXPECT_THAT(e.what(), HasSubstr(p));
    return e.what();
  }
  ADD_FAILURE() << "no planarvo::Error was thrown";
  return {};
}

class Rosbag1Test : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A folder per process (CTest runs the suite's tests in parallel processes), removed at the end.
    dir_ = PLANARVO_BINARY_DIR "/test-scratch/rosbag1." + std::to_string(getpid());
    if (std::system("/usr/bin/python3 -c 'import rosbag, roslz4, sensor_msgs.msg, nav_msgs.msg' 2>/dev/null") != 0) {
      skip_ = "Debian's python3-rosbag (and its message packages) are missing: run scripts/install-deps.sh";
      return;
    }
    fs::remove_all(dir_);
    const std::string cmd = "/usr/bin/python3 " PLANARVO_SOURCE_DIR "/test/tools/rosbag/write_test_bags.py '" + dir_ +
                            "' 2>/dev/null";
    generated_ = std::system(cmd.c_str()) == 0;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    if (!std::getenv("PLANARVO_KEEP_SCRATCH")) fs::remove_all(dir_, ec);
  }

  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    ASSERT_TRUE(generated_) << "test/tools/rosbag/write_test_bags.py failed";
  }

  static std::string bag(const std::string& name) { return dir_ + "/" + name + ".bag"; }

  // Every message of the bag, in index order, with its bytes.
  static std::vector<std::pair<MessageRef, std::vector<uint8_t>>> read_all(BagFile& b) {
    std::vector<std::pair<MessageRef, std::vector<uint8_t>>> out;
    for (const MessageRef& r : b.index(all_topics(b))) {
      out.emplace_back(r, std::vector<uint8_t>());
      b.read(r, out.back().second);
    }
    return out;
  }

  static inline std::string dir_;
  static inline std::string skip_;
  static inline bool generated_ = false;
};

const char* const kReadableBags[] = {"none_small", "none_large", "bz2_small",           "lz4_small",
                                     "lz4_large",  "none_small_unindexed", "lz4_small_unindexed"};

bool compression_missing(const std::string& name) {
  return (name.rfind("lz4", 0) == 0 && !PLANARVO_HAVE_LZ4) || (name.rfind("bz2", 0) == 0 && !PLANARVO_HAVE_BZ2);
}

TEST_F(Rosbag1Test, EveryBagHoldsWhatTheWriterRecorded) {
  for (const char* name : kReadableBags) {
    SCOPED_TRACE(name);
    const Expected e = read_sidecar(bag(name) + ".expected");
    if (compression_missing(name)) {
      expect_error([&] { read_all(*open_bag(bag(name))); }, ErrorCode::InvalidInput, {"-dev"});
      continue;
    }
    const std::unique_ptr<BagFile> b = open_bag(bag(name));
    EXPECT_EQ(b->serialization(), Serialization::Ros1);
    EXPECT_EQ(b->path(), bag(name));
    std::vector<TopicInfo> topics = b->topics();
    std::sort(topics.begin(), topics.end(), [](const TopicInfo& x, const TopicInfo& y) { return x.name < y.name; });
    ASSERT_EQ(topics.size(), e.topics.size());
    for (size_t i = 0; i < topics.size(); ++i) {
      EXPECT_EQ(topics[i].name, e.topics[i].name);
      EXPECT_EQ(topics[i].type, e.topics[i].type);
      EXPECT_EQ(topics[i].md5sum, e.topics[i].md5sum);
      EXPECT_EQ(topics[i].count, e.topics[i].count) << topics[i].name;
    }
    const auto all = read_all(*b);
    ASSERT_EQ(all.size(), e.messages.size());
    for (size_t i = 0; i < all.size(); ++i) {
      const auto& [ref, raw] = all[i];
      const ExpectedMessage& m = e.messages[i];
      SCOPED_TRACE("message " + std::to_string(i) + " on " + m.topic);
      EXPECT_EQ(b->topics()[ref.topic].name, m.topic);
      EXPECT_EQ(ref.receive_time_ns, m.receive_ns);
      EXPECT_EQ(ref.size, raw.size());
      EXPECT_EQ(raw.size(), m.raw_len);
      EXPECT_EQ(fnv1a(raw), m.raw_fnv);
      check_decoded(m, raw);
      if (m.kind != "other") {
        EXPECT_EQ(decode_header(Serialization::Ros1, raw.data(), raw.size()).stamp_ns, std::stoll(m.fields.at(0)));
      }
    }
  }
}

TEST_F(Rosbag1Test, IndexIsSortedByReceiveTimeWithTiesInFileOrder) {
  const std::unique_ptr<BagFile> b = open_bag(bag("none_small"));
  const uint32_t image = topic_index(*b, "/camera/image_raw");
  const uint32_t info = topic_index(*b, "/camera/camera_info");
  const uint32_t truth = topic_index(*b, "/ground_truth");
  const std::vector<MessageRef> refs = b->index({truth, info, image});
  ASSERT_EQ(refs.size(), 25u);
  for (size_t i = 1; i < refs.size(); ++i) EXPECT_LE(refs[i - 1].receive_time_ns, refs[i].receive_time_ns);
  // Each image and its camera info share a receive time; the image was written first.
  for (size_t i = 0; i + 1 < refs.size(); ++i)
    if (refs[i].receive_time_ns == refs[i + 1].receive_time_ns) {
      EXPECT_EQ(refs[i].topic, image);
      EXPECT_EQ(refs[i + 1].topic, info);
    }
  // The ground truth message was written after the sixth frame but received before the fourth.
  const auto gt = std::find_if(refs.begin(), refs.end(), [&](const MessageRef& r) { return r.topic == truth; });
  ASSERT_NE(gt, refs.end());
  EXPECT_EQ(gt - refs.begin(), 8);
  // A subset: only its topic's messages.
  const std::vector<MessageRef> odom = b->index({topic_index(*b, "/odom")});
  EXPECT_EQ(odom.size(), 12u);
  EXPECT_TRUE(b->index({}).empty());
}

TEST_F(Rosbag1Test, IndexAndScanGiveTheSameMessages) {
  for (const std::string name : {"none_small", "lz4_small"}) {
    SCOPED_TRACE(name);
    if (compression_missing(name)) continue;
    const std::unique_ptr<BagFile> indexed = open_rosbag1(bag(name));
    const std::unique_ptr<BagFile> scanned = open_rosbag1(bag(name + "_unindexed"));
    ASSERT_EQ(indexed->topics().size(), scanned->topics().size());
    for (size_t i = 0; i < indexed->topics().size(); ++i) {
      EXPECT_EQ(indexed->topics()[i].name, scanned->topics()[i].name);
      EXPECT_EQ(indexed->topics()[i].count, scanned->topics()[i].count);
    }
    const auto a = read_all(*indexed);
    const auto b = read_all(*scanned);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].first.receive_time_ns, b[i].first.receive_time_ns) << i;
      EXPECT_EQ(a[i].first.topic, b[i].first.topic) << i;
      EXPECT_EQ(a[i].first.location, b[i].first.location) << i;
      EXPECT_EQ(a[i].first.offset, b[i].first.offset) << i;
      EXPECT_EQ(a[i].first.size, b[i].first.size) << i;
      EXPECT_EQ(a[i].second, b[i].second) << i;
    }
  }
}

TEST_F(Rosbag1Test, ReadingBackwardsGivesTheSameBytes) {
  for (const char* name : {"none_small", "bz2_small", "lz4_small", "lz4_small_unindexed"}) {
    SCOPED_TRACE(name);
    if (compression_missing(name)) continue;
    const std::unique_ptr<BagFile> b = open_bag(bag(name));
    const auto forward = read_all(*b);
    std::vector<uint8_t> raw;
    for (size_t i = forward.size(); i-- > 0;) {
      b->read(forward[i].first, raw);
      EXPECT_EQ(raw, forward[i].second) << i;
    }
  }
}

TEST_F(Rosbag1Test, AnIndexPosPointingAtGarbageFallsBackToTheScan) {
  const std::string src = bag("none_small");
  const std::string dst = dir_ + "/bad_index_pos.bag";
  fs::copy_file(src, dst, fs::copy_options::overwrite_existing);
  {
    std::fstream f(dst, std::ios::in | std::ios::out | std::ios::binary);
    std::string head(4096, '\0');
    f.read(&head[0], 4096);
    const size_t at = head.find("index_pos=") + 10;
    ASSERT_NE(at, std::string::npos + 10);
    const char garbage[8] = {0x40, 0x10, 0, 0, 0, 0, 0, 0};  // byte 4160: inside the first chunk
    f.seekp(static_cast<std::streamoff>(at));
    f.write(garbage, 8);
  }
  const auto expected = read_all(*open_bag(src));
  const auto got = read_all(*open_bag(dst));
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i].second, expected[i].second) << i;
}

TEST_F(Rosbag1Test, ATruncatedBagNamesTheChunkItEndsIn) {
  for (const char* name : {"none_truncated", "lz4_truncated"}) {
    SCOPED_TRACE(name);
    const Expected e = read_sidecar(bag(name) + ".expected");
    ASSERT_GT(e.error_byte, 0);
    expect_error([&] { open_bag(bag(name)); }, ErrorCode::InvalidInput,
                 {bag(name), "the file ends inside a chunk at byte " + std::to_string(e.error_byte), "truncated"});
  }
}

TEST_F(Rosbag1Test, ARecordingKilledInsideAChunkNamesTheChunk) {
  const Expected e = read_sidecar(bag("none_killed") + ".expected");
  ASSERT_GT(e.error_byte, 0);
  expect_error([&] { open_bag(bag("none_killed")); }, ErrorCode::InvalidInput,
               {bag("none_killed") + ": at byte " + std::to_string(e.error_byte), "length was never written",
                "rosbag reindex"});
}

TEST_F(Rosbag1Test, OpenBagGoesByContentNotName) {
  const std::string renamed = dir_ + "/looks_like.mcap";
  fs::copy_file(bag("none_large"), renamed, fs::copy_options::overwrite_existing);
  EXPECT_TRUE(looks_like_bag(renamed));
  const std::unique_ptr<BagFile> b = open_bag(renamed);
  EXPECT_EQ(b->serialization(), Serialization::Ros1);
  EXPECT_EQ(b->index(all_topics(*b)).size(), 73u);  // 12 frames x 6 topics + 1 ground truth
}

TEST_F(Rosbag1Test, AnOlderBagVersionIsRefusedNamingIt) {
  const std::string old = dir_ + "/v12.bag";
  std::ofstream(old, std::ios::binary) << "#ROSBAG V1.2\n" << std::string(100, '\0');
  expect_error([&] { open_bag(old); }, ErrorCode::InvalidInput, {old, "1.2"});
  expect_error([&] { open_rosbag1(old); }, ErrorCode::InvalidInput, {old, "1.2"});
  const std::string not_bag = dir_ + "/text.bag";
  std::ofstream(not_bag, std::ios::binary) << "#ROSBAG V2.0\nshort";
  expect_error([&] { open_rosbag1(not_bag); }, ErrorCode::InvalidInput, {not_bag, "byte 13"});
}

TEST_F(Rosbag1Test, ATopicWithTwoTypesIsRefusedWhenAskedFor) {
  const std::unique_ptr<BagFile> b = open_bag(bag("conflict"));
  std::vector<std::string> odom_types;
  for (const TopicInfo& t : b->topics())
    if (t.name == "/odom") odom_types.push_back(t.type);
  EXPECT_THAT(odom_types, ::testing::UnorderedElementsAre("nav_msgs/Odometry", "std_msgs/String"));
  EXPECT_EQ(b->index({topic_index(*b, "/chatter")}).size(), 12u);
  for (uint32_t t = 0; t < b->topics().size(); ++t)
    if (b->topics()[t].name == "/odom")
      expect_error([&] { b->index({t}); }, ErrorCode::InvalidInput,
                   {bag("conflict"), "/odom", "nav_msgs/Odometry", "std_msgs/String"});
}

TEST_F(Rosbag1Test, ADifferentDefinitionUnderAKnownTypeIsRefusedWhenAskedFor) {
  const std::unique_ptr<BagFile> b = open_bag(bag("md5_mismatch"));
  const uint32_t image = topic_index(*b, "/camera/image_raw");
  EXPECT_EQ(b->topics()[image].md5sum, "0123456789abcdef0123456789abcdef");
  expect_error([&] { b->index({image}); }, ErrorCode::InvalidInput,
               {"/camera/image_raw", "0123456789abcdef0123456789abcdef", "060021388200f6f0f447d0fcd9c64743"});
  EXPECT_EQ(b->index({topic_index(*b, "/odom")}).size(), 12u);
}

TEST_F(Rosbag1Test, ProgressRisesToOneAndCanCancel) {
  const std::unique_ptr<BagFile> b = open_bag(bag("none_small"));
  std::vector<double> seen;
  b->index(all_topics(*b), [&](double f) {
    seen.push_back(f);
    return true;
  });
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GE(seen.front(), 0.0);
  EXPECT_EQ(seen.back(), 1.0);
  expect_error([&] { b->index(all_topics(*b), [](double) { return false; }); }, ErrorCode::Cancelled, {"cancelled"});
  expect_error([&] { b->index({99}); }, ErrorCode::InvalidArgument, {"99"});
  MessageRef forged;
  forged.location = 12345;
  std::vector<uint8_t> out;
  expect_error([&] { b->read(forged, out); }, ErrorCode::InvalidArgument, {"not of this bag"});
}

// Found by fuzz_rosbag1: a chunk's second index data record relabelled with the first one's
// connection. Each record matched the chunk info on its own, so the relabelled connection's
// messages in that chunk were silently left out of the index. Each connection the chunk info
// lists must now have exactly one index data record.
TEST_F(Rosbag1Test, AnIndexDataRecordGivenTwiceIsInvalidInput) {
  const std::string dst = dir_ + "/index_twice.bag";
  fs::copy_file(bag("none_small"), dst, fs::copy_options::overwrite_existing);
  std::fstream f(dst, std::ios::in | std::ios::out | std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const auto u32 = [&](size_t at) {
    uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = v << 8 | static_cast<uint8_t>(bytes.at(at + static_cast<size_t>(i)));
    return v;
  };
  // Two index data records of one chunk, one after the other, with equal counts. python3-rosbag
  // writes their header fields as op, conn, ver, count, so conn's value is 4 + 5 bytes past op.
  const std::string op = std::string("op=") + '\x04';
  size_t first = 0, second = 0;
  for (size_t at = bytes.find(op); at != std::string::npos && second == 0; at = bytes.find(op, at + 1)) {
    const size_t start = at - 8;  // header_len, then op's field length
    const size_t header_len = u32(start);
    const size_t next = start + 8 + header_len + u32(start + 4 + header_len);
    const size_t count = bytes.find("count=", at);
    if (bytes.compare(next + 8, op.size(), op) == 0 && u32(count + 6) == u32(bytes.find("count=", next) + 6)) {
      first = at + op.size() + 9;
      second = next + 8 + op.size() + 9;
    }
  }
  ASSERT_NE(second, 0u) << "no two index data records of one chunk with equal counts";
  ASSERT_EQ(bytes.substr(second - 5, 5), "conn=");
  f.seekp(static_cast<std::streamoff>(second));
  f.write(bytes.data() + first, 4);
  f.close();
  // Each topic alone (as the fuzzer found it: the dropped connection's topic alone indexed short).
  const std::unique_ptr<BagFile> b = open_bag(dst);
  std::string errors;
  for (uint32_t t = 0; t < b->topics().size(); ++t) {
    try {
      EXPECT_EQ(static_cast<int64_t>(b->index({t}).size()), b->topics()[t].count) << b->topics()[t].name;
    } catch (const Error& e) {
      EXPECT_EQ(static_cast<int>(e.code()), static_cast<int>(ErrorCode::InvalidInput));
      errors += std::string(e.what()) + "\n";
    }
  }
  EXPECT_THAT(errors, HasSubstr(dst + ": at byte "));
  EXPECT_THAT(errors, HasSubstr("index data for connection " + std::to_string(u32(first))));
}

// ROS 1 serialisation by hand: little-endian, no padding.
struct Ros1Writer {
  std::vector<uint8_t> bytes;
  void u8(uint8_t v) { bytes.push_back(v); }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void f64(double v) {
    uint64_t b;
    std::memcpy(&b, &v, 8);
    for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<uint8_t>(b >> (8 * i)));
  }
  void str(const std::string& s) {
    u32(static_cast<uint32_t>(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
  void header(uint32_t secs, uint32_t nsecs, const std::string& frame) {
    u32(7);  // seq
    u32(secs);
    u32(nsecs);
    str(frame);
  }
};

std::vector<uint8_t> hand_image() {
  Ros1Writer w;
  w.header(4294967295u, 999999999u, "cam");
  w.u32(2);  // height
  w.u32(3);  // width
  w.str("mono8");
  w.u8(1);
  w.u32(4);  // step
  w.u32(8);
  for (uint8_t i = 0; i < 8; ++i) w.u8(static_cast<uint8_t>(10 + i));
  return w.bytes;
}

TEST(Ros1Decoders, HandBuiltImage) {
  const std::vector<uint8_t> raw = hand_image();
  const ImageMessage m = decode_image(Serialization::Ros1, raw.data(), raw.size());
  EXPECT_EQ(m.header.stamp_ns, 4294967295ll * 1000000000 + 999999999);  // the largest ROS 1 time
  EXPECT_EQ(m.header.frame_id, "cam");
  EXPECT_EQ(m.height, 2u);
  EXPECT_EQ(m.width, 3u);
  EXPECT_EQ(m.encoding, "mono8");
  EXPECT_TRUE(m.is_bigendian);
  EXPECT_EQ(m.step, 4u);
  EXPECT_EQ(m.data, (std::vector<uint8_t>{10, 11, 12, 13, 14, 15, 16, 17}));
  EXPECT_EQ(decode_header(Serialization::Ros1, raw.data(), 19).frame_id, "cam");
}

TEST(Ros1Decoders, EveryShortBufferIsInvalidInput) {
  const std::vector<uint8_t> image = hand_image();
  Ros1Writer info;
  info.header(1, 2, "c");
  info.u32(480);
  info.u32(640);
  info.str("plumb_bob");
  info.u32(5);
  for (int i = 0; i < 5 + 9 + 9 + 12; ++i) info.f64(0.5 * i);
  for (int i = 0; i < 6; ++i) info.u32(static_cast<uint32_t>(i));
  info.u8(1);
  Ros1Writer odom;
  odom.header(1, 2, "odom");
  odom.str("base_link");
  for (int i = 0; i < 3 + 4 + 36 + 3 + 3 + 36; ++i) odom.f64(-1.0 * i);
  Ros1Writer compressed;
  compressed.header(1, 2, "c");
  compressed.str("png");
  compressed.u32(3);
  compressed.u8(1), compressed.u8(2), compressed.u8(3);

  const CameraInfoMessage ci = decode_camera_info(Serialization::Ros1, info.bytes.data(), info.bytes.size());
  EXPECT_EQ(ci.d.size(), 5u);
  EXPECT_EQ(ci.k[0], 2.5);
  EXPECT_EQ(ci.p[11], 0.5 * 34);
  EXPECT_EQ(ci.roi.width, 5u);
  EXPECT_TRUE(ci.roi.do_rectify);
  const OdometryMessage od = decode_odometry(Serialization::Ros1, odom.bytes.data(), odom.bytes.size());
  EXPECT_EQ(od.child_frame_id, "base_link");
  EXPECT_EQ(od.orientation[3], -6.0);
  EXPECT_EQ(od.twist_covariance[35], -84.0);
  EXPECT_EQ(decode_compressed_image(Serialization::Ros1, compressed.bytes.data(), compressed.bytes.size()).data,
            (std::vector<uint8_t>{1, 2, 3}));

  const auto every_prefix = [](const std::vector<uint8_t>& raw, auto decode, const char* type) {
    for (size_t n = 0; n < raw.size(); ++n) {
      const std::vector<uint8_t> cut(raw.begin(), raw.begin() + static_cast<std::ptrdiff_t>(n));
      expect_error([&] { decode(Serialization::Ros1, cut.data(), cut.size()); }, ErrorCode::InvalidInput,
                   {type, "byte"});
    }
    std::vector<uint8_t> longer = raw;
    longer.push_back(0);
    expect_error([&] { decode(Serialization::Ros1, longer.data(), longer.size()); }, ErrorCode::InvalidInput,
                 {type, "1 bytes after the end"});
  };
  every_prefix(image, decode_image, "sensor_msgs/Image");
  every_prefix(info.bytes, decode_camera_info, "sensor_msgs/CameraInfo");
  every_prefix(odom.bytes, decode_odometry, "nav_msgs/Odometry");
  every_prefix(compressed.bytes, decode_compressed_image, "sensor_msgs/CompressedImage");
}

TEST(Ros1Decoders, ALengthPastTheEndIsInvalidInput) {
  std::vector<uint8_t> raw = hand_image();
  // The data array's count (after header 12 + 4 + 3, height, width, "mono8", is_bigendian, step).
  const size_t count_at = 19 + 8 + 9 + 1 + 4;
  raw[count_at + 3] = 0x7f;
  expect_error([&] { decode_image(Serialization::Ros1, raw.data(), raw.size()); }, ErrorCode::InvalidInput,
               {"sensor_msgs/Image", "at byte " + std::to_string(count_at + 4), "runs past the end"});
  std::vector<uint8_t> frame = hand_image();
  frame[15] = 0xff;  // frame_id's length
  expect_error([&] { decode_header(Serialization::Ros1, frame.data(), frame.size()); }, ErrorCode::InvalidInput,
               {"std_msgs/Header", "runs past the end"});
  Ros1Writer d;
  d.header(1, 2, "c");
  d.u32(1);
  d.u32(1);
  d.str("x");
  d.u32(0x20000000);  // D: 2^29 doubles
  expect_error([&] { decode_camera_info(Serialization::Ros1, d.bytes.data(), d.bytes.size()); },
               ErrorCode::InvalidInput, {"sensor_msgs/CameraInfo", "536870912 elements"});
}

}  // namespace
}  // namespace planarvo::io::bag
