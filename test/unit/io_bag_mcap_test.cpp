// The MCAP reader (src/io/bag/mcap*.cpp) on files written by the official writer (@mcap/core, CDR
// from @foxglove/cdr) through test/tools/mcap/write_test_mcaps.mjs, whose expected values (a line
// file per MCAP file) are the independent reference; a few hand-built files for what the writer
// cannot produce (unknown records, bad CRCs, out-of-range times).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/error.h"
#include "io/bag/bag.h"
#include "io/bag/mcap_records.h"
#include "io/bag/messages.h"
#include "io_bag_mcap_bytes.h"

namespace {

namespace fs = std::filesystem;
using planarvo::Error;
using planarvo::ErrorCode;
using namespace planarvo::io::bag;
using planarvo_test::McapBytes;

// One line of NAME.expected.txt: a tag and its key=value fields.
struct Line {
  std::string tag;
  std::map<std::string, std::string> f;
  const std::string& at(const std::string& key) const {
    static const std::string none;
    const auto it = f.find(key);
    return it == f.end() ? none : it->second;
  }
};

struct Expected {
  Line file;
  std::vector<Line> topics, messages;
};

Expected load_expected(const std::string& path) {
  std::ifstream in(path);
  Expected e;
  for (std::string text; std::getline(in, text);) {
    if (text.empty() || text[0] == '#') continue;
    std::stringstream ss(text);
    Line line;
    std::getline(ss, line.tag, '\t');
    for (std::string field; std::getline(ss, field, '\t');) {
      const size_t eq = field.find('=');
      line.f[field.substr(0, eq)] = field.substr(eq + 1);
    }
    if (line.tag == "file") e.file = line;
    if (line.tag == "topic") e.topics.push_back(line);
    if (line.tag == "message") e.messages.push_back(line);
  }
  return e;
}

uint32_t fnv1a(const uint8_t* p, size_t n) {
  uint32_t h = 0x811c9dc5u;
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x01000193u;
  return h;
}

std::vector<double> numbers(const std::string& list) {
  std::vector<double> out;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');) out.push_back(std::strtod(item.c_str(), nullptr));
  return out;
}

template <typename C>
std::vector<double> as_vector(const C& c) {
  return std::vector<double>(c.begin(), c.end());
}

const std::vector<std::string> kReadable = {"chunked_none", "chunked_zstd", "chunked_lz4", "unchunked",
                                            "no_message_index", "chunked_zstd_nosummary", "cdr_be",
                                            "chunked_none_cut", "unchunked_cut", "type_conflict"};

class McapFiles : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string tools = std::string(PLANARVO_SOURCE_DIR) + "/test/tools/mcap";
    // CTest runs each test in a process of its own, two at once: a folder per process.
    dir_ = std::string(PLANARVO_BINARY_DIR) + "/test-scratch/mcap-" + std::to_string(getpid());
    if (std::system("command -v node >/dev/null 2>&1") != 0) {
      skip_ = "node is not installed: run scripts/install-deps.sh";
      return;
    }
    if (!fs::exists(tools + "/node_modules/@mcap/core")) {
      skip_ = tools + "/node_modules is missing: run scripts/install-deps.sh";
      return;
    }
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const std::string command = "node '" + tools + "/write_test_mcaps.mjs' '" + dir_ + "' > '" + dir_ + "/log.txt' 2>&1";
    generated_ = std::system(command.c_str()) == 0;
  }

  static void TearDownTestSuite() {
    if (generated_) fs::remove_all(dir_);  // kept when the generator failed: its log.txt says why
  }

  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    ASSERT_TRUE(generated_) << "write_test_mcaps.mjs failed; see " << dir_ << "/log.txt";
  }

  static std::string file(const std::string& name) { return dir_ + "/" + name + ".mcap"; }
  static Expected expected(const std::string& name) { return load_expected(dir_ + "/" + name + ".expected.txt"); }

  // Every topic that can be indexed.
  static std::vector<uint32_t> indexable(const BagFile& bag, const Expected& e) {
    std::vector<uint32_t> out;
    for (uint32_t t = 0; t < bag.topics().size(); ++t) {
      const auto it = std::find_if(e.topics.begin(), e.topics.end(),
                                   [&](const Line& l) { return l.at("name") == bag.topics()[t].name; });
      if (it != e.topics.end() && it->at("problem") == "-") out.push_back(t);
    }
    return out;
  }

  static std::string dir_, skip_;
  static bool generated_;
};

std::string McapFiles::dir_, McapFiles::skip_;
bool McapFiles::generated_ = false;

void expect_header(const Header& h, const Line& m) {
  EXPECT_EQ(h.stamp_ns, std::stoll(m.at("stamp_ns")));
  EXPECT_EQ(h.frame_id, m.at("frame_id"));
}

void expect_image_data(const std::vector<uint8_t>& data, const Line& m) {
  ASSERT_EQ(data.size(), std::stoul(m.at("data_size")));
  EXPECT_EQ(fnv1a(data.data(), data.size()), std::stoul(m.at("data_fnv")));
  EXPECT_EQ(data.front(), std::stoul(m.at("data_first")));
  EXPECT_EQ(data.back(), std::stoul(m.at("data_last")));
}

// The decoded message against the writer's values.
void expect_decoded(const std::vector<uint8_t>& bytes, const Line& m) {
  const std::string kind = m.at("kind");
  if (kind == "Other") return;
  expect_header(decode_header(Serialization::Cdr, bytes.data(), bytes.size()), m);
  if (kind == "Image") {
    const ImageMessage im = decode_image(Serialization::Cdr, bytes.data(), bytes.size());
    expect_header(im.header, m);
    EXPECT_EQ(im.height, std::stoul(m.at("height")));
    EXPECT_EQ(im.width, std::stoul(m.at("width")));
    EXPECT_EQ(im.encoding, m.at("encoding"));
    EXPECT_EQ(im.is_bigendian, m.at("is_bigendian") == "1");
    EXPECT_EQ(im.step, std::stoul(m.at("step")));
    expect_image_data(im.data, m);
  } else if (kind == "CompressedImage") {
    const CompressedImageMessage ci = decode_compressed_image(Serialization::Cdr, bytes.data(), bytes.size());
    expect_header(ci.header, m);
    EXPECT_EQ(ci.format, m.at("format"));
    expect_image_data(ci.data, m);
  } else if (kind == "CameraInfo") {
    const CameraInfoMessage c = decode_camera_info(Serialization::Cdr, bytes.data(), bytes.size());
    expect_header(c.header, m);
    EXPECT_EQ(c.height, std::stoul(m.at("height")));
    EXPECT_EQ(c.width, std::stoul(m.at("width")));
    EXPECT_EQ(c.distortion_model, m.at("distortion_model"));
    EXPECT_EQ(c.d, numbers(m.at("d")));
    EXPECT_EQ(as_vector(c.k), numbers(m.at("k")));
    EXPECT_EQ(as_vector(c.r), numbers(m.at("r")));
    EXPECT_EQ(as_vector(c.p), numbers(m.at("p")));
    EXPECT_EQ(c.binning_x, std::stoul(m.at("binning_x")));
    EXPECT_EQ(c.binning_y, std::stoul(m.at("binning_y")));
    const std::vector<double> roi{double(c.roi.x_offset), double(c.roi.y_offset), double(c.roi.height),
                                  double(c.roi.width), c.roi.do_rectify ? 1.0 : 0.0};
    EXPECT_EQ(roi, numbers(m.at("roi")));
  } else if (kind == "Odometry") {
    const OdometryMessage o = decode_odometry(Serialization::Cdr, bytes.data(), bytes.size());
    expect_header(o.header, m);
    EXPECT_EQ(o.child_frame_id, m.at("child_frame_id"));
    EXPECT_EQ(as_vector(o.position), numbers(m.at("position")));
    EXPECT_EQ(as_vector(o.orientation), numbers(m.at("orientation")));
    EXPECT_EQ(as_vector(o.pose_covariance), numbers(m.at("pose_covariance")));
    EXPECT_EQ(as_vector(o.linear), numbers(m.at("linear")));
    EXPECT_EQ(as_vector(o.angular), numbers(m.at("angular")));
    EXPECT_EQ(as_vector(o.twist_covariance), numbers(m.at("twist_covariance")));
  } else {
    ADD_FAILURE() << "unknown kind " << kind;
  }
}

TEST_F(McapFiles, EveryFileMatchesWhatTheWriterWrote) {
  for (const std::string& name : kReadable) {
    SCOPED_TRACE(name);
    const Expected e = expected(name);
    ASSERT_FALSE(e.messages.empty());
    const auto bag = open_mcap(file(name));
    EXPECT_EQ(bag->path(), file(name));
    EXPECT_EQ(bag->serialization(), Serialization::Cdr);
    ASSERT_EQ(bag->topics().size(), e.topics.size());
    for (size_t t = 0; t < e.topics.size(); ++t) {
      EXPECT_EQ(bag->topics()[t].name, e.topics[t].at("name"));
      EXPECT_EQ(bag->topics()[t].type, e.topics[t].at("type"));
      const int64_t count = bag->topics()[t].count;
      // Known at once from the summary's statistics; a file without one was scanned at open.
      EXPECT_TRUE(count == std::stoll(e.topics[t].at("count")) || (count == -1 && e.file.at("summary") == "0"))
          << bag->topics()[t].name << " " << count;
    }
    const std::vector<uint32_t> topics = indexable(*bag, e);
    const std::vector<MessageRef> refs = bag->index(topics);
    // The expected index: the messages as written, stably sorted by log time.
    std::vector<Line> want;
    for (const Line& m : e.messages)
      for (uint32_t t : topics)
        if (bag->topics()[t].name == m.at("topic")) want.push_back(m);
    std::stable_sort(want.begin(), want.end(), [](const Line& a, const Line& b) {
      return std::stoull(a.at("log_time")) < std::stoull(b.at("log_time"));
    });
    ASSERT_EQ(refs.size(), want.size());
    std::vector<uint8_t> bytes;
    for (size_t i = 0; i < refs.size(); ++i) {
      SCOPED_TRACE("message " + std::to_string(i) + " " + want[i].at("topic"));
      EXPECT_EQ(bag->topics()[refs[i].topic].name, want[i].at("topic"));
      EXPECT_EQ(refs[i].receive_time_ns, std::stoll(want[i].at("log_time")));
      EXPECT_EQ(refs[i].size, std::stoul(want[i].at("raw_size")));
      bag->read(refs[i], bytes);
      ASSERT_EQ(bytes.size(), std::stoul(want[i].at("raw_size")));
      EXPECT_EQ(fnv1a(bytes.data(), bytes.size()), std::stoul(want[i].at("raw_fnv")));
      expect_decoded(bytes, want[i]);
    }
    for (uint32_t t : topics) EXPECT_EQ(bag->topics()[t].count, std::stoll(e.topics[t].at("count")));
  }
}

TEST_F(McapFiles, IndexIsByLogTimeWithTiesInFileOrder) {
  const auto bag = open_mcap(file("chunked_zstd"));
  std::vector<uint32_t> all(bag->topics().size());
  for (uint32_t t = 0; t < all.size(); ++t) all[t] = t;
  const std::vector<MessageRef> refs = bag->index(all);
  ASSERT_GE(refs.size(), 6u);
  for (size_t i = 1; i < refs.size(); ++i) EXPECT_LE(refs[i - 1].receive_time_ns, refs[i].receive_time_ns);
  // Frame 0: the /odom message written after the images but logged 35 ms earlier comes first;
  // then the four camera messages with one log time, in the order written.
  const auto name = [&](size_t i) { return bag->topics()[refs[i].topic].name; };
  EXPECT_EQ(name(0), "/odom");
  EXPECT_EQ(name(1), "/camera/image_raw");
  EXPECT_EQ(name(2), "/camera/image_color");
  EXPECT_EQ(name(3), "/camera/image_raw/compressed");
  EXPECT_EQ(name(4), "/camera/camera_info");
  EXPECT_EQ(name(5), "/chatter");
  for (size_t i = 2; i <= 5; ++i) EXPECT_EQ(refs[i].receive_time_ns, refs[1].receive_time_ns);
}

TEST_F(McapFiles, SummaryAndScanGiveTheSameIndex) {
  const std::vector<std::pair<std::string, std::string>> pairs = {
      {"chunked_zstd", "chunked_zstd_nosummary"}, {"chunked_none", "chunked_none_cut"}, {"unchunked", "unchunked_cut"}};
  for (const auto& [with, without] : pairs) {
    SCOPED_TRACE(with);
    const auto a = open_mcap(file(with));
    const auto b = open_mcap(file(without));
    ASSERT_EQ(a->topics().size(), b->topics().size());
    std::vector<uint32_t> all(a->topics().size());
    for (uint32_t t = 0; t < all.size(); ++t) {
      all[t] = t;
      EXPECT_EQ(a->topics()[t].name, b->topics()[t].name);
    }
    const std::vector<MessageRef> ra = a->index(all), rb = b->index(all);
    ASSERT_EQ(ra.size(), rb.size());
    for (size_t i = 0; i < ra.size(); ++i) {
      EXPECT_EQ(ra[i].receive_time_ns, rb[i].receive_time_ns);
      EXPECT_EQ(ra[i].topic, rb[i].topic);
      EXPECT_EQ(ra[i].location, rb[i].location);
      EXPECT_EQ(ra[i].offset, rb[i].offset);
      EXPECT_EQ(ra[i].size, rb[i].size);
    }
  }
}

TEST_F(McapFiles, ReadingInReverseGivesTheSameBytes) {
  for (const std::string name : {"chunked_zstd", "chunked_lz4", "chunked_none", "unchunked"}) {
    SCOPED_TRACE(name);
    const auto bag = open_mcap(file(name));
    std::vector<uint32_t> all(bag->topics().size());
    for (uint32_t t = 0; t < all.size(); ++t) all[t] = t;
    const std::vector<MessageRef> refs = bag->index(all);
    std::vector<std::vector<uint8_t>> forward(refs.size());
    for (size_t i = 0; i < refs.size(); ++i) bag->read(refs[i], forward[i]);
    std::vector<uint8_t> bytes;
    for (size_t i = refs.size(); i-- > 0;) {
      bag->read(refs[i], bytes);
      EXPECT_EQ(bytes, forward[i]) << i;
    }
  }
}

// Where a cut MCAP file's first incomplete record starts, found by walking the records
// (opcode, uint64 length, content) from after the magic: an independent reading of the layout.
uint64_t first_cut_record(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  uint64_t off = 8;
  while (off + 9 <= b.size()) {
    uint64_t len = 0;
    for (int i = 7; i >= 0; --i) len = (len << 8) | b[off + 1 + static_cast<uint64_t>(i)];
    if (len > b.size() || off + 9 + len > b.size()) return off;
    off += 9 + len;
  }
  return off;
}

TEST_F(McapFiles, ATruncatedFileIsInvalidInputNamingTheByte) {
  for (const std::string name : {"truncated_mid_chunk", "truncated_mid_message"}) {
    SCOPED_TRACE(name);
    const uint64_t cut_at = first_cut_record(file(name));
    try {
      const auto bag = open_mcap(file(name));
      std::vector<uint32_t> all(bag->topics().size());
      for (uint32_t t = 0; t < all.size(); ++t) all[t] = t;
      bag->index(all);
      ADD_FAILURE() << "no error";
    } catch (const Error& err) {
      EXPECT_EQ(err.code(), ErrorCode::InvalidInput);
      // Issue 27: this test checked for the words "at byte", not for the byte.
      EXPECT_NE(std::string(err.what()).find(file(name) + ": at byte " + std::to_string(cut_at) + ": "),
                std::string::npos)
          << err.what();
    }
  }
}

// A byte of a message in an uncompressed chunk corrupted: read through the summary's index, the
// message is refused by its chunk's uncompressed_crc (before, the index path read the message
// straight from the file and returned the corrupt bytes).
TEST_F(McapFiles, ACorruptMessageReadThroughTheIndexFailsItsChunksCrc) {
  const auto clean = open_mcap(file("chunked_none"));
  const std::vector<MessageRef> refs = clean->index(indexable(*clean, expected("chunked_none")));
  ASSERT_FALSE(refs.empty());
  std::vector<uint8_t> message;
  const MessageRef& victim = refs[refs.size() / 2];
  clean->read(victim, message);
  ASSERT_GE(message.size(), 8u);
  std::ifstream in(file("chunked_none"), std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = std::search(bytes.begin(), bytes.end(), message.begin(), message.end());
  ASSERT_NE(at, bytes.end());
  at[static_cast<std::ptrdiff_t>(message.size() / 2)] ^= 0x5a;
  const std::string corrupt = dir_ + "/corrupt_message.mcap";
  std::ofstream(corrupt, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                 static_cast<std::streamsize>(bytes.size()));
  const auto bag = open_mcap(corrupt);
  const std::vector<MessageRef> again = bag->index(indexable(*bag, expected("chunked_none")));
  ASSERT_EQ(again.size(), refs.size());
  std::string msg;
  try {
    bag->read(again[refs.size() / 2], message);
    ADD_FAILURE() << "the corrupt message was read";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidInput);
    msg = e.what();
  }
  EXPECT_NE(msg.find("uncompressed_crc"), std::string::npos) << msg;
  EXPECT_NE(msg.find(corrupt), std::string::npos) << msg;
}

TEST_F(McapFiles, TopicsOfOtherTypesAndChannelsSharingATopic) {
  const auto bag = open_mcap(file("chunked_none"));
  std::map<std::string, TopicInfo> by_name;
  for (const TopicInfo& t : bag->topics()) by_name[t.name] = t;
  EXPECT_EQ(by_name.size(), bag->topics().size());  // /odom's two channels are one topic
  EXPECT_EQ(by_name["/chatter"].type, "std_msgs/msg/String");
  EXPECT_EQ(by_name["/diagnostics"].type, "example_msgs/msg/Status");  // JSON-encoded: listed all the same
  EXPECT_EQ(by_name["/odom"].type, "nav_msgs/msg/Odometry");
  EXPECT_EQ(by_name["/odom"].count, 16);
}

TEST_F(McapFiles, ATopicOfTwoTypesOrNotCdrIsAnErrorWhenAskedFor) {
  const auto bag = open_mcap(file("type_conflict"));
  const auto topic = [&](const std::string& name) {
    for (uint32_t t = 0; t < bag->topics().size(); ++t)
      if (bag->topics()[t].name == name) return t;
    ADD_FAILURE() << name;
    return uint32_t{0};
  };
  try {
    bag->index({topic("/camera/image_raw")});
    ADD_FAILURE() << "no error";
  } catch (const Error& err) {
    EXPECT_EQ(err.code(), ErrorCode::InvalidInput);
    EXPECT_NE(std::string(err.what()).find("sensor_msgs/msg/Image"), std::string::npos) << err.what();
    EXPECT_NE(std::string(err.what()).find("sensor_msgs/msg/CompressedImage"), std::string::npos) << err.what();
  }
  try {
    bag->index({topic("/odom_json")});
    ADD_FAILURE() << "no error";
  } catch (const Error& err) {
    EXPECT_EQ(err.code(), ErrorCode::InvalidInput);
    EXPECT_NE(std::string(err.what()).find("\"json\""), std::string::npos) << err.what();
  }
  EXPECT_EQ(bag->index({topic("/camera/image_color")}).size(), 8u);
  EXPECT_THROW(bag->index({static_cast<uint32_t>(bag->topics().size())}), Error);
}

TEST_F(McapFiles, OpenBagPicksMcapByItsMagic) {
  const std::string renamed = dir_ + "/renamed.bag";
  fs::copy_file(file("chunked_lz4"), renamed, fs::copy_options::overwrite_existing);
  EXPECT_TRUE(looks_like_bag(renamed));
  const auto bag = open_bag(renamed);
  EXPECT_EQ(bag->serialization(), Serialization::Cdr);
  EXPECT_EQ(bag->topics().size(), 7u);
}

TEST_F(McapFiles, ProgressRisesAndFalseCancels) {
  for (const std::string name : {"chunked_zstd", "unchunked"}) {
    SCOPED_TRACE(name);
    const auto bag = open_mcap(file(name));
    std::vector<double> seen;
    bag->index({0}, [&](double f) {
      seen.push_back(f);
      return true;
    });
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
    EXPECT_GE(seen.front(), 0.0);
    EXPECT_EQ(seen.back(), 1.0);
    try {
      open_mcap(file(name))->index({0}, [](double) { return false; });
      ADD_FAILURE() << "not cancelled";
    } catch (const Error& err) {
      EXPECT_EQ(err.code(), ErrorCode::Cancelled);
    }
  }
}

// Hand-built files: what the official writer does not produce.

// This process's folder for hand-built files, removed when it exits.
const std::string& handmade_dir() {
  static const struct Dir {
    std::string path = std::string(PLANARVO_BINARY_DIR) + "/test-scratch/mcap-handmade-" + std::to_string(getpid());
    Dir() { fs::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  } dir;
  return dir.path;
}

std::string write_scratch(const std::string& name, const std::vector<uint8_t>& bytes) {
  const std::string path = handmade_dir() + "/" + name;
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
  return path;
}

std::string error_of(const std::string& path) {
  try {
    const auto bag = open_mcap(path);
    std::vector<uint32_t> all(bag->topics().size());
    for (uint32_t t = 0; t < all.size(); ++t) all[t] = t;
    std::vector<uint8_t> bytes;
    for (const MessageRef& r : bag->index(all)) bag->read(r, bytes);
  } catch (const Error& err) {
    EXPECT_EQ(err.code(), ErrorCode::InvalidInput) << err.what();
    return err.what();
  }
  return "";
}

TEST(McapHandmade, UnknownRecordsAreSkipped) {
  McapBytes chunk;
  chunk.record(0x81, {1, 2, 3});  // a private record inside a chunk
  chunk.message(1, 20, {7, 7});
  McapBytes f = McapBytes::file();
  f.schema(1, "std_msgs/msg/String");
  f.channel(1, 1, "/a");
  f.record(0x80, std::vector<uint8_t>(5, 0xAB));  // private, top level
  f.message(1, 10, {1, 2, 3});
  f.record(0x70, {});                               // a future opcode
  f.chunk(chunk.bytes, true);
  f.record(0x0F, {0, 0, 0, 0});                     // Data End
  const auto bag = open_mcap(write_scratch("unknown_records.mcap", f.bytes));
  ASSERT_EQ(bag->topics().size(), 1u);
  EXPECT_EQ(bag->topics()[0].count, 2);
  const std::vector<MessageRef> refs = bag->index({0});
  ASSERT_EQ(refs.size(), 2u);
  std::vector<uint8_t> bytes;
  bag->read(refs[0], bytes);
  EXPECT_EQ(bytes, (std::vector<uint8_t>{1, 2, 3}));
  bag->read(refs[1], bytes);
  EXPECT_EQ(bytes, (std::vector<uint8_t>{7, 7}));
  EXPECT_EQ(refs[1].receive_time_ns, 20);
}

// A summary with Chunk Index records, and a message outside the chunks that the Statistics count:
// the chunk indexes alone would miss it, so the data section is scanned.
TEST(McapHandmade, AMessageOutsideTheIndexedChunksIsFoundThroughTheStatistics) {
  for (const bool with_statistics : {true, false}) {
    SCOPED_TRACE(with_statistics);
    McapBytes records;
    records.message(1, 5, {5});
    McapBytes f = McapBytes::file();
    f.schema(1, "std_msgs/msg/String");
    f.channel(1, 1, "/a");
    const uint64_t chunk = f.bytes.size();
    f.chunk(records.bytes, true);
    const uint64_t chunk_length = f.bytes.size() - chunk;
    f.message(1, 3, {3});
    f.record(0x0F, {0, 0, 0, 0});
    const uint64_t summary = f.bytes.size();
    f.schema(1, "std_msgs/msg/String");
    f.channel(1, 1, "/a");
    f.chunk_index(chunk, chunk_length, records.bytes.size());
    if (with_statistics) f.statistics(1, 2);
    f.footer(summary, 0, 0);
    const auto bag = open_mcap(write_scratch("outside_chunks.mcap", f.bytes));
    EXPECT_EQ(bag->topics()[0].count, with_statistics ? 2 : -1);
    const std::vector<MessageRef> refs = bag->index({0});
    // Without statistics the index is trusted, as the spec's indexed readers do (mcap_reader.h).
    ASSERT_EQ(refs.size(), with_statistics ? 2u : 1u);
    EXPECT_EQ(refs.front().receive_time_ns, with_statistics ? 3 : 5);
    EXPECT_EQ(refs.back().receive_time_ns, 5);
  }
}

// Found by fuzz_mcap (374k runs): a summary without chunk indexes makes index() scan; a channel
// the summary lacks was defined before the scan failed (or was cancelled), and the next index()
// read its topic, which it did not have yet, as an index (a crash).
McapBytes summary_without_channel_b(bool bad_record) {
  McapBytes f = McapBytes::file();
  f.schema(1, "std_msgs/msg/String");
  f.channel(1, 1, "/a");
  f.channel(2, 1, "/b");
  f.message(1, 4, {4});
  f.message(bad_record ? 9 : 2, 5, {5});
  f.record(0x0F, {0, 0, 0, 0});
  const uint64_t summary = f.bytes.size();
  f.schema(1, "std_msgs/msg/String");
  f.channel(1, 1, "/a");
  f.footer(summary, 0, 0);
  return f;
}

TEST(McapHandmade, AnIndexAfterAFailedScanFailsAlike) {
  const auto bag = open_mcap(write_scratch("failed_scan.mcap", summary_without_channel_b(true).bytes));
  ASSERT_EQ(bag->topics().size(), 1u);
  for (int i = 0; i < 2; ++i) {
    try {
      bag->index({0});
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidInput);
      EXPECT_NE(std::string(e.what()).find("a message on channel 9"), std::string::npos) << e.what();
    }
  }
}

TEST(McapHandmade, AnIndexAfterACancelledScanScansAgain) {
  const auto bag = open_mcap(write_scratch("cancelled_scan.mcap", summary_without_channel_b(false).bytes));
  int calls = 0;
  EXPECT_THROW(bag->index({0}, [&](double) { return ++calls < 4; }), Error);  // after /b's channel
  const std::vector<MessageRef> refs = bag->index({0});
  ASSERT_EQ(bag->topics().size(), 2u);  // /b, which only the data section defines
  EXPECT_EQ(bag->topics()[1].name, "/b");
  ASSERT_EQ(refs.size(), 1u);
  EXPECT_EQ(bag->index({1}).size(), 1u);
}

TEST(McapHandmade, TwoChunkIndexesOfOneChunkAreRefused) {
  McapBytes records;
  records.message(1, 5, {5});
  McapBytes f = McapBytes::file();
  const uint64_t chunk = f.bytes.size();
  f.chunk(records.bytes, true);
  const uint64_t chunk_length = f.bytes.size() - chunk;
  const uint64_t summary = f.bytes.size();
  f.schema(1, "std_msgs/msg/String");
  f.channel(1, 1, "/a");
  f.chunk_index(chunk, chunk_length, records.bytes.size());
  f.chunk_index(chunk, chunk_length, records.bytes.size());
  f.footer(summary, 0, 0);
  EXPECT_NE(error_of(write_scratch("two_indexes.mcap", f.bytes)).find("inside the chunk that another"),
            std::string::npos);
}

TEST(McapHandmade, BadFilesAreInvalidInputWithTheByte) {
  {
    McapBytes f = McapBytes::file();
    f.schema(1, "std_msgs/msg/String");
    f.channel(1, 1, "/a");
    f.message(1, uint64_t{1} << 63, {1});
    EXPECT_NE(error_of(write_scratch("time.mcap", f.bytes)).find("INT64_MAX"), std::string::npos);
  }
  {
    McapBytes chunk;
    chunk.schema(1, "std_msgs/msg/String");
    chunk.channel(1, 1, "/a");
    chunk.message(1, 5, {1, 2});
    McapBytes f = McapBytes::file();
    f.chunk(chunk.bytes, true, 0x12345678);
    EXPECT_NE(error_of(write_scratch("crc.mcap", f.bytes)).find("uncompressed_crc"), std::string::npos);
  }
  {
    McapBytes f = McapBytes::file();
    f.message(3, 5, {1});
    const std::string e = error_of(write_scratch("no_channel.mcap", f.bytes));
    EXPECT_NE(e.find("at byte 25: a message on channel 3"), std::string::npos) << e;  // 8 magic + 17 header
  }
  {
    McapBytes chunk;
    chunk.message(1, 5, {1});
    McapBytes f = McapBytes::file();
    f.chunk(chunk.bytes, false, 0, "bz2");
    EXPECT_NE(error_of(write_scratch("bz2.mcap", f.bytes)).find("\"bz2\""), std::string::npos);
  }
  {
    McapBytes f = McapBytes::file();
    f.schema(1, "std_msgs/msg/String");
    f.channel(1, 1, "/a");
    const uint64_t summary = f.bytes.size();
    f.channel(1, 1, "/a");
    f.footer(summary, 0, 0xDEADBEEF);
    EXPECT_NE(error_of(write_scratch("summary_crc.mcap", f.bytes)).find("CRC"), std::string::npos);
  }
  {
    McapBytes f = McapBytes::file();
    f.footer(1u << 20, 0, 0);
    EXPECT_NE(error_of(write_scratch("summary_outside.mcap", f.bytes)).find("summary_start (1048576)"),
              std::string::npos);
  }
  EXPECT_NE(error_of(write_scratch("not_mcap.mcap", {'#', 'R', 'O', 'S'})).find("not an MCAP file"),
            std::string::npos);
}

}  // namespace

namespace {

// CRC-32 bit by bit, straight from the polynomial: the reference for the reader's sliced tables.
uint32_t crc32_bitwise(const uint8_t* p, size_t n) {
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xFFFFFFFFu;
}

TEST(McapCrc, MatchesTheBitwiseDefinitionAtEveryLengthAndAlignment) {
  const char* check = "123456789";  // the standard check value of CRC-32
  EXPECT_EQ(planarvo::io::bag::mcap::crc32(reinterpret_cast<const uint8_t*>(check), 9), 0xCBF43926u);
  std::vector<uint8_t> bytes(300);
  uint32_t x = 12345;
  for (uint8_t& b : bytes) b = static_cast<uint8_t>((x = x * 1103515245u + 12345u) >> 24);
  for (size_t start = 0; start < 9; ++start)
    for (size_t n = 0; start + n <= bytes.size(); n += 7) {
      EXPECT_EQ(planarvo::io::bag::mcap::crc32(bytes.data() + start, n), crc32_bitwise(bytes.data() + start, n))
          << start << " " << n;
      // Continued over two calls, as the summary's CRC is.
      const size_t half = n / 2;
      const uint32_t first = planarvo::io::bag::mcap::crc32(bytes.data() + start, half);
      EXPECT_EQ(planarvo::io::bag::mcap::crc32(bytes.data() + start + half, n - half, first),
                crc32_bitwise(bytes.data() + start, n));
    }
}

}  // namespace
