// A ROS 1 bag through planarvo's reader (src/io/bag/rosbag1.cpp): opened, its topics listed,
// every topic indexed (each alone, then all that index together), every message read and the
// four kinds planarvo uses decoded. Bad bytes must be Error(InvalidInput) with a message naming
// the file; the promises of bag.h are checked on what opens: the index sorted by receive time,
// each topic's count equal to its messages, each read as long as its ref says.
#include <string>
#include <vector>

#include "core/error.h"
#include "fuzz_common.h"
#include "io/bag/bag.h"
#include "io/bag/messages.h"

namespace {

using namespace planarvo::io::bag;

void check_error(const planarvo::Error& e, const std::string& path) {
  if (e.code() != planarvo::ErrorCode::InvalidInput) {
    std::fprintf(stderr, "planarvo fuzz: %s\n", e.what());
    planarvo_fuzz::broken("a bad bag gave an error other than InvalidInput");
  }
  if (std::string(e.what()).find(path) == std::string::npos) {
    std::fprintf(stderr, "planarvo fuzz: %s\n", e.what());
    planarvo_fuzz::broken("an error about a bag that does not name the file");
  }
}

// Decodes one message of a known kind; a decoding error is fine (the caller's bytes are bad).
void decode(MessageKind kind, const std::vector<uint8_t>& raw) {
  const uint8_t* p = raw.data();
  const size_t n = raw.size();
  try {
    switch (kind) {
      case MessageKind::Image: {
        const ImageMessage m = decode_image(Serialization::Ros1, p, n);
        if (m.data.size() > n) planarvo_fuzz::broken("an image with more pixels than bytes");
        break;
      }
      case MessageKind::CompressedImage: decode_compressed_image(Serialization::Ros1, p, n); break;
      case MessageKind::CameraInfo: decode_camera_info(Serialization::Ros1, p, n); break;
      case MessageKind::Odometry: decode_odometry(Serialization::Ros1, p, n); break;
      case MessageKind::Other: decode_header(Serialization::Ros1, p, n); break;
    }
  } catch (const planarvo::Error& e) {
    if (e.code() != planarvo::ErrorCode::InvalidInput)
      planarvo_fuzz::broken("a decoder gave an error other than InvalidInput");
  }
}

void read_everything(BagFile& bag, const std::string& path) {
  const std::vector<TopicInfo>& topics = bag.topics();
  std::vector<uint32_t> good;
  for (uint32_t t = 0; t < topics.size(); ++t) {
    try {
      const std::vector<MessageRef> refs = bag.index({t});
      if (topics[t].count >= 0 && static_cast<size_t>(topics[t].count) != refs.size())
        planarvo_fuzz::broken("a topic's count differs from its indexed messages");
      good.push_back(t);
    } catch (const planarvo::Error& e) {
      check_error(e, path);
    }
  }
  const std::vector<MessageRef> refs = bag.index(good);
  std::vector<uint8_t> raw;
  for (size_t i = 0; i < refs.size(); ++i) {
    if (i > 0 && refs[i].receive_time_ns < refs[i - 1].receive_time_ns) planarvo_fuzz::broken("an unsorted index");
    if (refs[i].topic >= topics.size()) planarvo_fuzz::broken("a ref to a topic out of range");
    bag.read(refs[i], raw);
    if (raw.size() != refs[i].size) planarvo_fuzz::broken("a read whose length differs from its ref's size");
    decode(message_kind(topics[refs[i].topic].type), raw);
  }
  if (!refs.empty()) bag.read(refs.front(), raw);  // back to the first chunk after the last
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = planarvo_fuzz::work_dir() + "/input.bag";
  planarvo_fuzz::write_file(path, data, size);
  try {
    const std::unique_ptr<BagFile> bag = open_rosbag1(path);
    read_everything(*bag, path);
  } catch (const planarvo::Error& e) {
    check_error(e, path);
  }
  return 0;
}
