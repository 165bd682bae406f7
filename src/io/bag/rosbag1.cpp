// planarvo's reader of ROS 1 bags, format 2.0, written on its specification
// (http://wiki.ros.org/Bags/Format/2.0). Layout: "#ROSBAG V2.0\n", the bag header record (op 0x03:
// index_pos, conn_count, chunk_count; padded to 4096 bytes), then chunks (op 0x05), each holding
// connection (0x07) and message data (0x02) records and followed by one index data record (0x04)
// per connection in it; at index_pos the connection records and one chunk info record (0x06) per
// chunk.
//
// A bag closed properly (index_pos != 0 and the records there valid) is read through its index:
// opening reads the connections and chunk infos, index() the index data records after the chunks
// that hold the asked topics. Any other bag (recording killed: index_pos 0; truncated; index
// unreadable) is scanned from the first record after the bag header when it is opened,
// decompressing every chunk, collecting connections and where every message is; a chunk cut by
// the end of the file is an error naming its byte, never skipped.
//
// MessageRef: location = the chunk record's file offset, offset = the message's data inside the
// chunk's uncompressed data, size = its length. Messages of uncompressed chunks are read straight
// from the file; the last decompressed chunk is kept.
#include <algorithm>
#include <map>
#include <set>
#include <unordered_map>

#include "core/error.h"
#include "io/bag/bag.h"
#include "io/bag/messages.h"
#include "io/bag/messages_internal.h"
#include "io/bag/rosbag1_decompress.h"
#include "io/bag/rosbag1_records.h"

namespace planarvo::io::bag {

namespace {

using namespace rosbag1;

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr size_t kMagicSize = sizeof kMagic - 1;

struct Connection {
  uint32_t id = 0;
  std::string topic, type, md5sum;
};

struct Chunk {
  uint64_t pos = 0;  // the chunk record's offset in the file
  std::string compression;
  uint32_t size = 0;  // uncompressed
  uint64_t data_pos = 0;
  uint32_t data_size = 0;
  uint64_t end = 0;  // just after the data: the chunk's index data records follow
  std::map<uint32_t, uint32_t> counts;  // chunk info: connection -> messages; indexed bags
};

// A message found by scanning.
struct ScannedMessage {
  int64_t time_ns;
  uint32_t conn;
  uint32_t chunk;  // index into chunks_
  uint32_t offset;
  uint32_t size;
};

struct Topic {
  TopicInfo info;
  std::string conflict;  // why the topic cannot be indexed (two types or definitions), or empty
};

// "Connection": the record header has conn and topic; the data are a connection header
// (topic, type, md5sum, message_definition, ...) in the header format.
Connection parse_connection(const Fields& header, const uint8_t* data, size_t n, const Place& place,
                            uint64_t data_pos) {
  const Fields fields(data, n, place, data_pos);
  return Connection{header.u32("conn"), header.str("topic"), fields.str("type"), fields.str("md5sum")};
}

bool ref_before(const MessageRef& a, const MessageRef& b) {
  if (a.receive_time_ns != b.receive_time_ns) return a.receive_time_ns < b.receive_time_ns;
  if (a.location != b.location) return a.location < b.location;
  return a.offset < b.offset;
}

class Rosbag1File final : public BagFile {
 public:
  explicit Rosbag1File(const std::string& path) : file_(path) {
    place_.path = path;
    const uint64_t first = read_bag_header();
    if (index_pos_ != 0) {
      try {
        read_index();
        indexed_ = true;
      } catch (const Error& e) {
        if (e.code() != ErrorCode::InvalidInput) throw;
        connections_.clear();
        chunks_.clear();
      }
    }
    if (!indexed_) scan(first);
    for (uint32_t i = 0; i < chunks_.size(); ++i) chunk_by_pos_[chunks_[i].pos] = i;
    build_topics();
  }

  const std::string& path() const override { return place_.path; }
  Serialization serialization() const override { return Serialization::Ros1; }
  const std::vector<TopicInfo>& topics() const override { return infos_; }

  std::vector<MessageRef> index(const std::vector<uint32_t>& topics, const IndexProgress& progress) override {
    std::vector<bool> wanted_topic(topics_.size(), false);
    for (const uint32_t t : topics) {
      check_topic(t);
      wanted_topic[t] = true;
    }
    std::unordered_map<uint32_t, uint32_t> wanted;  // connection -> topic
    for (const auto& [id, topic] : conn_topic_)
      if (wanted_topic[topic]) wanted.emplace(id, topic);
    std::vector<MessageRef> refs = indexed_ ? index_from_index(wanted, progress) : index_from_scan(wanted);
    std::sort(refs.begin(), refs.end(), ref_before);
    for (size_t i = 1; i < refs.size(); ++i)
      if (refs[i].location == refs[i - 1].location && refs[i].offset == refs[i - 1].offset)
        throw_invalid_input(place_.at(refs[i].location) + ": the index lists a message of this chunk twice");
    report(progress, 1.0);
    return refs;
  }

  void read(const MessageRef& message, std::vector<uint8_t>& out) override {
    const auto it = chunk_by_pos_.find(message.location);
    if (it == chunk_by_pos_.end())
      throw_invalid_argument(place_.path + ": a message reference that is not of this bag (no chunk at byte " +
                             std::to_string(message.location) + ")");
    const Chunk& c = chunks_[it->second];
    if (message.offset > c.size || message.size > c.size - message.offset)
      throw_invalid_argument(place_.at(c.pos) + ": a message reference past the end of the chunk");
    if (c.compression == "none") {
      out.resize(message.size);
      file_.read(c.data_pos + message.offset, out.data(), message.size, "a chunk");
      return;
    }
    const std::vector<uint8_t>& data = decompressed(it->second);
    const auto begin = data.begin() + static_cast<std::ptrdiff_t>(message.offset);
    out.assign(begin, begin + static_cast<std::ptrdiff_t>(message.size));
  }

 private:
  // "Bag header": op 0x03 with index_pos, conn_count, chunk_count. Returns the first record's offset.
  uint64_t read_bag_header() {
    char magic[kMagicSize] = {};
    if (file_.size() < kMagicSize) throw_invalid_input(place_.path + ": too short for a ROS bag (#ROSBAG V2.0)");
    file_.read(0, magic, kMagicSize, "the magic");
    if (std::string(magic, kMagicSize) != kMagic) {
      if (std::string(magic, 9) == "#ROSBAG V")
        throw_invalid_input(place_.path + ": a ROS bag of version " + std::string(magic + 9, 3) +
                            "; planarvo reads version 2.0");
      throw_invalid_input(place_.path + ": not a ROS bag (no #ROSBAG V2.0 at its start)");
    }
    const FileRecord r = read_file_record(file_, kMagicSize, place_);
    if (r.header.op() != kOpBagHeader)
      place_.fail(kMagicSize, "the first record is a " + op_name(r.header.op()) + ", not the bag header");
    const std::string* encryptor = r.header.find("encryptor");
    if (encryptor && !encryptor->empty())
      place_.fail(kMagicSize, "the bag is encrypted (" + *encryptor +
                                  "); planarvo reads unencrypted bags (`rosbag decrypt` writes one)");
    index_pos_ = r.header.u64("index_pos");
    conn_count_ = r.header.u32("conn_count");
    chunk_count_ = r.header.u32("chunk_count");
    first_record_ = r.end;
    return r.end;
  }

  // "Chunk": op 0x05 with compression and size (uncompressed); the data are the records.
  Chunk read_chunk_header(uint64_t pos) {
    const FileRecord r = read_file_record(file_, pos, place_);
    if (r.header.op() != kOpChunk) place_.fail(pos, "a " + op_name(r.header.op()) + " where a chunk should be");
    Chunk c;
    c.pos = pos;
    c.compression = r.header.str("compression");
    c.size = r.header.u32("size");
    c.data_pos = r.data_pos;
    c.data_size = r.data_size;
    c.end = r.end;
    // rosbag writes a chunk's header with both lengths 0 and fills them in when the chunk is
    // complete; no writer leaves a chunk empty. Its records follow, but where they end is unknown.
    if (c.data_size == 0)
      place_.fail(pos, "a chunk whose length was never written: the recording stopped inside it (truncated?); "
                       "`rosbag reindex` keeps the chunks before it");
    if (c.compression == "none" && c.size != c.data_size)
      place_.fail(pos, "an uncompressed chunk of " + std::to_string(c.data_size) + " bytes whose header says " +
                           std::to_string(c.size));
    return c;
  }

  void add_connection(const Connection& c, uint64_t pos, const Place& place) {
    const auto [it, added] = connections_.emplace(c.id, c);
    const Connection& known = it->second;
    if (!added && (known.topic != c.topic || known.type != c.type || known.md5sum != c.md5sum))
      place.fail(pos, "connection " + std::to_string(c.id) + " is recorded again with another topic or type (" +
                          known.topic + " " + known.type + ", then " + c.topic + " " + c.type + ")");
  }

  // "Connection" and "Chunk info" records at index_pos (the index section).
  void read_index() {
    if (index_pos_ < first_record_ || index_pos_ >= file_.size())
      place_.fail(kMagicSize, "index_pos " + std::to_string(index_pos_) + " is outside the file");
    uint64_t pos = index_pos_;
    for (uint32_t i = 0; i < conn_count_; ++i) {
      const FileRecord r = read_file_record(file_, pos, place_);
      if (r.header.op() != kOpConnection)
        place_.fail(pos, "a " + op_name(r.header.op()) + " where the index's connection records should be");
      const std::vector<uint8_t> data = file_.read_vector(r.data_pos, r.data_size, "a connection record");
      add_connection(parse_connection(r.header, data.data(), data.size(), place_, r.data_pos), pos, place_);
      pos = r.end;
    }
    for (uint32_t i = 0; i < chunk_count_; ++i) {
      const FileRecord r = read_file_record(file_, pos, place_);
      chunks_.push_back(read_chunk_info(r));
      pos = r.end;
    }
    std::sort(chunks_.begin(), chunks_.end(), [](const Chunk& a, const Chunk& b) { return a.pos < b.pos; });
    for (size_t i = 1; i < chunks_.size(); ++i)
      if (chunks_[i].pos < chunks_[i - 1].end) place_.fail(chunks_[i].pos, "the index's chunks overlap");
  }

  // "Chunk info": ver 1, chunk_pos, start_time, end_time, count; data: count x (conn, count).
  Chunk read_chunk_info(const FileRecord& r) {
    if (r.header.op() != kOpChunkInfo)
      place_.fail(r.pos, "a " + op_name(r.header.op()) + " where the index's chunk info records should be");
    if (r.header.u32("ver") != 1)
      place_.fail(r.pos, "chunk info version " + std::to_string(r.header.u32("ver")) + "; planarvo reads version 1");
    const uint64_t chunk_pos = r.header.u64("chunk_pos");
    const uint32_t count = r.header.u32("count");
    if (static_cast<uint64_t>(count) * 8 != r.data_size)
      place_.fail(r.pos, "a chunk info record of " + std::to_string(count) + " connections with " +
                             std::to_string(r.data_size) + " bytes of data, not 8 each");
    if (chunk_pos < first_record_ || chunk_pos >= index_pos_)
      place_.fail(r.pos, "a chunk info record whose chunk_pos " + std::to_string(chunk_pos) +
                             " is outside the chunks' part of the file");
    Chunk c = read_chunk_header(chunk_pos);
    if (c.end > index_pos_) place_.fail(chunk_pos, "a chunk that runs into the index section");
    const std::vector<uint8_t> data = file_.read_vector(r.data_pos, r.data_size, "a chunk info record");
    for (uint32_t k = 0; k < count; ++k) {
      const uint32_t conn = load_u32(data.data() + 8 * k);
      if (!connections_.count(conn))
        place_.fail(r.pos, "a chunk info record names connection " + std::to_string(conn) +
                               ", which the index does not have");
      if (!c.counts.emplace(conn, load_u32(data.data() + 8 * k + 4)).second)
        place_.fail(r.pos, "a chunk info record names connection " + std::to_string(conn) + " twice");
    }
    return c;
  }

  // The linear scan of a bag without a usable index.
  void scan(uint64_t pos) {
    while (pos < file_.size()) {
      const FileRecord r = read_file_record(file_, pos, place_);
      const uint8_t op = r.header.op();
      if (op == kOpChunk) {
        scan_chunk(read_chunk_header(pos));
      } else if (op == kOpConnection) {
        const std::vector<uint8_t> data = file_.read_vector(r.data_pos, r.data_size, "a connection record");
        add_connection(parse_connection(r.header, data.data(), data.size(), place_, r.data_pos), pos, place_);
      } else if (op == kOpMessageData) {
        place_.fail(pos, "a message data record outside any chunk");
      }  // index data, chunk info and unknown records: skipped (the spec's rule for readers)
      pos = r.end;
    }
    for (const ScannedMessage& m : scanned_)
      if (!connections_.count(m.conn))
        place_.fail(chunks_[m.chunk].pos, "a message of connection " + std::to_string(m.conn) +
                                              ", which no connection record in the bag defines");
  }

  void scan_chunk(Chunk c) {
    const uint32_t index = static_cast<uint32_t>(chunks_.size());
    chunks_.push_back(std::move(c));
    const std::vector<uint8_t>& data = chunk_data(index);
    const Chunk& chunk = chunks_[index];
    const Place inner{place_.path, true, chunk.pos};
    uint64_t pos = 0;
    while (pos < data.size()) {
      const Record r = parse_record(data.data(), data.size(), pos, inner);
      const uint8_t op = r.header.op();
      if (op == kOpConnection) {
        add_connection(parse_connection(r.header, data.data() + r.data_pos, r.data_size, inner, r.data_pos), pos,
                       inner);
      } else if (op == kOpMessageData) {
        scanned_.push_back(ScannedMessage{r.header.time_ns("time"), r.header.u32("conn"), index,
                                          static_cast<uint32_t>(r.data_pos), r.data_size});
      }  // other records inside a chunk: skipped
      pos = r.end;
    }
  }

  // The chunk's uncompressed data: the file's bytes (scan) or the cached decompressed data.
  const std::vector<uint8_t>& chunk_data(uint32_t index) {
    const Chunk& c = chunks_[index];
    if (c.compression != "none") return decompressed(index);
    raw_ = file_.read_vector(c.data_pos, c.data_size, "a chunk");
    return raw_;
  }

  const std::vector<uint8_t>& decompressed(uint32_t index) {
    if (cached_ == static_cast<int64_t>(index)) return cache_;
    const Chunk& c = chunks_[index];
    cached_ = -1;
    const std::vector<uint8_t> compressed = file_.read_vector(c.data_pos, c.data_size, "a chunk");
    decompress_chunk(c.compression, compressed.data(), compressed.size(), c.size, cache_, place_, c.pos);
    cached_ = index;
    return cache_;
  }

  // One TopicInfo per (topic, type); the connections in id order.
  void build_topics() {
    std::map<uint32_t, int64_t> counts;
    for (const Chunk& c : chunks_)
      for (const auto& [conn, n] : c.counts) counts[conn] += n;
    for (const ScannedMessage& m : scanned_) ++counts[m.conn];
    std::map<std::string, std::vector<uint32_t>> by_name;
    std::map<std::pair<std::string, std::string>, uint32_t> by_name_and_type;
    for (const auto& [id, c] : connections_) {
      const auto [it, added] =
          by_name_and_type.emplace(std::make_pair(c.topic, c.type), static_cast<uint32_t>(topics_.size()));
      const uint32_t t = it->second;
      if (added) {
        topics_.push_back(Topic{TopicInfo{c.topic, c.type, 0, c.md5sum}, {}});
        by_name[c.topic].push_back(t);
      } else if (topics_[t].info.md5sum != c.md5sum && topics_[t].conflict.empty()) {
        topics_[t].conflict = "topic " + c.topic + " is recorded with two definitions of " + c.type + " (md5sum " +
                              topics_[t].info.md5sum + " and " + c.md5sum + ")";
      }
      topics_[t].info.count += counts[id];
      conn_topic_.emplace(id, t);
    }
    for (const auto& [name, ids] : by_name)
      if (ids.size() > 1)
        for (const uint32_t t : ids)
          topics_[t].conflict = "topic " + name + " is recorded with two types, " + topics_[ids[0]].info.type +
                                " and " + topics_[ids[1]].info.type;
    for (const Topic& t : topics_) infos_.push_back(t.info);
  }

  // A topic asked for: in range, one type, and for the four kinds planarvo decodes, the
  // definition it decodes (the md5sum of the message definition).
  void check_topic(uint32_t t) const {
    if (t >= topics_.size())
      throw_invalid_argument(place_.path + ": topic index " + std::to_string(t) + " out of range (" +
                             std::to_string(topics_.size()) + " topics)");
    const Topic& topic = topics_[t];
    if (!topic.conflict.empty()) throw_invalid_input(place_.path + ": " + topic.conflict);
    const MessageKind kind = message_kind(topic.info.type);
    if (kind == MessageKind::Other) return;
    const std::string expected = ros1::definition_md5(kind);
    if (topic.info.md5sum != expected)
      throw_invalid_input(place_.path + ": topic " + topic.info.name + " has type " + topic.info.type +
                          " with md5sum " + topic.info.md5sum + ", but planarvo decodes " + topic.info.type +
                          " as defined with md5sum " + expected + " (a different message definition)");
  }

  std::vector<MessageRef> index_from_scan(const std::unordered_map<uint32_t, uint32_t>& wanted) const {
    std::vector<MessageRef> refs;
    for (const ScannedMessage& m : scanned_) {
      const auto it = wanted.find(m.conn);
      if (it != wanted.end())
        refs.push_back(MessageRef{m.time_ns, it->second, chunks_[m.chunk].pos, m.offset, m.size});
    }
    return refs;
  }

  std::vector<MessageRef> index_from_index(const std::unordered_map<uint32_t, uint32_t>& wanted,
                                           const IndexProgress& progress) {
    std::vector<MessageRef> refs;
    for (uint32_t i = 0; i < chunks_.size(); ++i) {
      report(progress, static_cast<double>(i) / static_cast<double>(chunks_.size()));
      const Chunk& c = chunks_[i];
      const bool needed = std::any_of(c.counts.begin(), c.counts.end(),
                                      [&](const auto& cn) { return cn.second > 0 && wanted.count(cn.first); });
      if (needed) index_chunk(i, wanted, refs);
    }
    return refs;
  }

  // "Index data": ver 1, conn, count; data: count x (time, uint32 offset of the message data
  // record in the chunk's uncompressed data). One per connection of the chunk, after it.
  void index_chunk(uint32_t index, const std::unordered_map<uint32_t, uint32_t>& wanted,
                   std::vector<MessageRef>& refs) {
    uint64_t pos = chunks_[index].end;
    std::set<uint32_t> seen;  // each listed connection once
    for (size_t k = 0; k < chunks_[index].counts.size(); ++k) {
      const FileRecord r = read_file_record(file_, pos, place_);
      const Chunk& c = chunks_[index];
      if (r.header.op() != kOpIndexData)
        place_.fail(pos, "a " + op_name(r.header.op()) + " where the chunk's index data records should be");
      if (r.header.u32("ver") != 1)
        place_.fail(pos, "index data version " + std::to_string(r.header.u32("ver")) + "; planarvo reads version 1");
      const uint32_t conn = r.header.u32("conn");
      const uint32_t count = r.header.u32("count");
      const auto listed = c.counts.find(conn);
      if (listed == c.counts.end() || listed->second != count || !seen.insert(conn).second)
        place_.fail(pos, "index data for connection " + std::to_string(conn) + " with " + std::to_string(count) +
                             " messages, which the chunk info does not list (or lists once)");
      if (static_cast<uint64_t>(count) * 12 != r.data_size)
        place_.fail(pos, "index data of " + std::to_string(count) + " messages with " + std::to_string(r.data_size) +
                             " bytes of data, not 12 each");
      const auto topic = wanted.find(conn);
      if (topic != wanted.end()) {
        const std::vector<uint8_t> entries = file_.read_vector(r.data_pos, r.data_size, "an index data record");
        for (uint32_t e = 0; e < count; ++e)
          refs.push_back(locate(index, conn, topic->second, load_time_ns(entries.data() + 12 * e),
                                load_u32(entries.data() + 12 * e + 8)));
      }
      pos = r.end;
    }
  }

  // The message data record an index entry points at, checked against the entry.
  MessageRef locate(uint32_t index, uint32_t conn, uint32_t topic, int64_t time_ns, uint32_t offset) {
    const Chunk& c = chunks_[index];
    const Place inner{place_.path, true, c.pos};
    const Record r = c.compression == "none" ? record_in_file(c, offset, inner)
                                             : parse_record(decompressed(index).data(), c.size, offset, inner);
    if (r.header.op() != kOpMessageData)
      inner.fail(offset, "the index points at a " + op_name(r.header.op()) + ", not a message data record");
    if (r.header.u32("conn") != conn || r.header.time_ns("time") != time_ns)
      inner.fail(offset, "the message's connection and time are not the ones the index gives");
    return MessageRef{time_ns, topic, c.pos, r.data_pos, r.data_size};
  }

  // A record of an uncompressed chunk: its header read from the file, its data left there.
  Record record_in_file(const Chunk& c, uint32_t offset, const Place& inner) {
    if (offset > c.size || c.size - offset < 8) inner.fail(offset, "a record runs past the end of the chunk");
    uint8_t len[4];
    file_.read(c.data_pos + offset, len, 4, "a chunk");
    const uint32_t header_len = load_u32(len);
    if (header_len > c.size - offset - 8)
      inner.fail(offset, "a record header of " + std::to_string(header_len) + " bytes runs past the end of the chunk");
    const std::vector<uint8_t> w = file_.read_vector(c.data_pos + offset + 4, header_len + size_t{4}, "a chunk");
    Record r{Fields(w.data(), header_len, inner, offset), offset + 8 + uint64_t{header_len},
             load_u32(w.data() + header_len), 0};
    if (r.data_size > c.size - r.data_pos)
      inner.fail(offset, "a record's data of " + std::to_string(r.data_size) + " bytes run past the end of the chunk");
    r.end = r.data_pos + r.data_size;
    return r;
  }

  void report(const IndexProgress& progress, double fraction) const {
    if (progress && !progress(fraction)) throw Error(ErrorCode::Cancelled, place_.path + ": indexing cancelled");
  }

  Place place_;
  BagStream file_;
  uint64_t index_pos_ = 0;
  uint32_t conn_count_ = 0, chunk_count_ = 0;
  uint64_t first_record_ = 0;
  bool indexed_ = false;
  std::map<uint32_t, Connection> connections_;
  std::vector<Chunk> chunks_;  // in file order
  std::unordered_map<uint64_t, uint32_t> chunk_by_pos_;
  std::vector<ScannedMessage> scanned_;
  std::vector<Topic> topics_;
  std::vector<TopicInfo> infos_;
  std::map<uint32_t, uint32_t> conn_topic_;
  std::vector<uint8_t> raw_;  // an uncompressed chunk while it is scanned
  std::vector<uint8_t> cache_;
  int64_t cached_ = -1;  // the chunk in cache_
};

}  // namespace

std::unique_ptr<BagFile> open_rosbag1(const std::string& path) { return std::make_unique<Rosbag1File>(path); }

}  // namespace planarvo::io::bag
