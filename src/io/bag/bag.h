// Recorded robot logs: ROS 1 bags (format 2.0) and MCAP files (ROS 2), read by planarvo's own
// readers on the formats' published specifications. A BagFile lists its topics, indexes the
// messages of the topics asked for, and hands back one message's serialised bytes on demand,
// so a 20-minute log is never held in memory. The messages are decoded by messages.h.
//
// Errors: a file that is not a bag, a truncated or corrupt one, a compression this build lacks:
// Error(InvalidInput) whose message names the file and, where it applies, the byte offset
// ("log.bag: at byte 1234: a record header runs past the end of the file"). Never a crash, never
// a silently skipped message, whatever the bytes (the readers are fuzzed).
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace planarvo::io::bag {

// How the messages' bytes are serialised.
enum class Serialization { Ros1, Cdr };

struct TopicInfo {
  std::string name;      // "/camera/image_raw"
  std::string type;      // as recorded: "sensor_msgs/Image" (ROS 1), "sensor_msgs/msg/Image" (ROS 2)
  int64_t count = 0;     // messages on the topic; -1 when the file does not say (an MCAP file
                         // without a summary lists the topic with -1 until indexed)
  std::string md5sum;    // ROS 1: the md5sum of the message definition the connection recorded
                         // (a reader checks it for the types it decodes); empty for MCAP
};

// Where one message is, so that its bytes can be read back later.
struct MessageRef {
  // The time the recorder received the message, integer nanoseconds since the Unix epoch:
  // ROS 1 the message record's `time`, MCAP the Message record's log_time.
  int64_t receive_time_ns = 0;
  uint32_t topic = 0;    // index into BagFile::topics()
  // Reader-defined location (e.g. the chunk's file offset and the offset inside the
  // decompressed chunk); only the BagFile that made the ref understands it.
  uint64_t location = 0;
  uint64_t offset = 0;
  uint32_t size = 0;     // bytes of the serialised message
};

// Called while indexing with the fraction of the file done (0..1); returning false cancels
// with Error(Cancelled).
using IndexProgress = std::function<bool(double fraction)>;

class BagFile {
 public:
  virtual ~BagFile() = default;
  virtual const std::string& path() const = 0;
  virtual Serialization serialization() const = 0;
  // Every topic (ROS 1: connection; MCAP: channel with its schema's name as type) in the file.
  // Two connections of the same topic name with the same type are one topic.
  virtual const std::vector<TopicInfo>& topics() const = 0;
  // Every message on the listed topics (indices into topics()), sorted by receive time
  // (stable: messages with equal times keep their order in the file). Reads the index when the
  // file has one and it is complete; otherwise scans the file. Fills in TopicInfo::count for
  // the listed topics when it was -1.
  virtual std::vector<MessageRef> index(const std::vector<uint32_t>& topics,
                                        const IndexProgress& progress = {}) = 0;
  // The serialised bytes of one message (replaces `out`'s contents). Decompresses the message's
  // chunk when needed and keeps the last decompressed chunk, so reading messages in index order
  // decompresses each chunk once. Not safe to call from two threads at once.
  virtual void read(const MessageRef& message, std::vector<uint8_t>& out) = 0;
};

// Opens by content, not by name: "#ROSBAG V2.0\n" is a ROS 1 bag, the MCAP magic
// (0x89 'M' 'C' 'A' 'P' 0x30 '\r' '\n') an MCAP file. Reads the header and what the file's
// index or summary says about its topics; anything else is InvalidInput naming what the first
// bytes look like.
std::unique_ptr<BagFile> open_bag(const std::string& path);

// The two readers, for tests; open_bag picks one.
std::unique_ptr<BagFile> open_rosbag1(const std::string& path);
std::unique_ptr<BagFile> open_mcap(const std::string& path);

// True when the first bytes of the file are a ROS 1 bag's or an MCAP file's magic.
bool looks_like_bag(const std::string& path);

}  // namespace planarvo::io::bag
