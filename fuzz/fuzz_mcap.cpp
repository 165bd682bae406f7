// An MCAP file through planarvo's MCAP reader (src/io/bag/mcap*.cpp) as the bag data-set source
// uses it: open, list the topics, index each topic and then all of them, read every message and
// decode those of the four kinds planarvo reads (ROS 2 CDR). Bad input must be
// Error(InvalidInput) with a message; the index must be sorted, fill in the counts, and give
// references whose bytes read back at the size it claimed.
#include <algorithm>
#include <vector>

#include "core/error.h"
#include "fuzz_common.h"
#include "io/bag/bag.h"
#include "io/bag/messages.h"

namespace {

using namespace planarvo::io::bag;

void expect_invalid_input(const planarvo::Error& e) {
  if (e.code() != planarvo::ErrorCode::InvalidInput) planarvo_fuzz::broken("an MCAP file gave an error other than InvalidInput");
  if (!*e.what()) planarvo_fuzz::broken("an error without a message");
}

void decode(MessageKind kind, const std::vector<uint8_t>& bytes) {
  try {
    const uint8_t* p = bytes.data();
    const size_t n = bytes.size();
    const Header h = decode_header(Serialization::Cdr, p, n);
    (void)h;
    if (kind == MessageKind::Image) (void)decode_image(Serialization::Cdr, p, n);
    if (kind == MessageKind::CompressedImage) (void)decode_compressed_image(Serialization::Cdr, p, n);
    if (kind == MessageKind::CameraInfo) (void)decode_camera_info(Serialization::Cdr, p, n);
    if (kind == MessageKind::Odometry) (void)decode_odometry(Serialization::Cdr, p, n);
  } catch (const planarvo::Error& e) {
    expect_invalid_input(e);
  }
}

// Indexes the topics and reads every message back; false when the index was refused.
bool index_and_read(BagFile& bag, const std::vector<uint32_t>& topics) {
  std::vector<MessageRef> refs;
  try {
    refs = bag.index(topics);
  } catch (const planarvo::Error& e) {
    expect_invalid_input(e);
    return false;
  }
  for (size_t i = 1; i < refs.size(); ++i)
    if (refs[i - 1].receive_time_ns > refs[i].receive_time_ns) planarvo_fuzz::broken("an index out of time order");
  std::vector<int64_t> counts(bag.topics().size(), 0);
  for (const MessageRef& r : refs) {
    if (std::find(topics.begin(), topics.end(), r.topic) == topics.end())
      planarvo_fuzz::broken("a message of a topic not asked for");
    ++counts[r.topic];
  }
  for (uint32_t t : topics)
    if (bag.topics()[t].count != counts[t]) planarvo_fuzz::broken("a topic's count is not its indexed messages'");
  std::vector<uint8_t> bytes;
  for (const MessageRef& r : refs) {
    try {
      bag.read(r, bytes);
    } catch (const planarvo::Error& e) {
      expect_invalid_input(e);
      continue;
    }
    if (bytes.size() != r.size) planarvo_fuzz::broken("a message's bytes are not the size the index gave");
    const MessageKind kind = message_kind(bag.topics()[r.topic].type);
    if (kind != MessageKind::Other) decode(kind, bytes);
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace planarvo_fuzz;
  static const std::string path = work_dir() + "/input.mcap";
  write_file(path, data, size);
  std::unique_ptr<BagFile> bag;
  try {
    bag = open_mcap(path);
  } catch (const planarvo::Error& e) {
    expect_invalid_input(e);
    return 0;
  }
  if (bag->serialization() != Serialization::Cdr) broken("an MCAP file that is not CDR");
  std::vector<uint32_t> good;
  for (uint32_t t = 0; t < bag->topics().size(); ++t)
    if (index_and_read(*bag, {t})) good.push_back(t);
  index_and_read(*bag, good);
  return 0;
}
