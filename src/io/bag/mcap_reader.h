// The MCAP reader behind open_mcap (https://mcap.dev/spec; bag.h has the contract). mcap.cpp opens
// the file, reads the summary and answers topics() and read(); mcap_index.cpp finds the messages.
//
// How a file is read:
// - Opening reads the magic and the Header record, then the Footer before the closing magic. A
//   footer whose summary_start is not zero points at the summary section: its Schema, Channel,
//   Chunk Index and Statistics records give the topics (with counts from the Statistics) without
//   touching the data. Anything wrong in a summary that a footer points at (offsets outside the
//   file, a bad CRC, a record cut short) is InvalidInput.
// - No closing magic and footer (a recording cut off), or a footer without a summary, or a
//   summary that lists no channels: opening scans the data section from the start: top-level
//   records, and every chunk's records (decompressed). The scan stops at the Data End record, at
//   a Footer, or at the end of the file when it ends between two records; a file that ends inside
//   a record is InvalidInput "at byte N: the file ends inside a record (truncated?)".
// - index() with Chunk Index records uses them: a chunk none of whose channels is asked for is
//   not read; an uncompressed chunk's messages are found through its Message Index records and
//   checked against their records' headers in the file (no pixels are read); a compressed chunk
//   is decompressed and its records walked. When the summary's Statistics count a different
//   number of messages for an asked channel than the chunk indexes gave (messages outside chunks,
//   or an incomplete index), the data section is scanned instead. Without Chunk Index records
//   index() scans the data section (once; the result is kept; when it finds the file bad, every
//   later index() gives the same error).
// - Unknown record opcodes are skipped by their length, as the spec requires.
//
// MessageRef: location is the Chunk record's file offset and offset the message data's offset in
// the chunk's (decompressed) records; for a message outside chunks location is 0 and offset the
// data's file offset. Chunk CRCs are checked whenever a chunk's records are read whole (scan,
// compressed chunks); an uncompressed chunk read through its index is not checked.
#pragma once
#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "io/bag/bag.h"
#include "io/bag/mcap_records.h"

namespace planarvo::io::bag::mcap {

constexpr uint32_t kNoTopic = UINT32_MAX;

// A message found while indexing, with what orders it: log_time, then its place in the file.
struct Found {
  uint64_t log_time = 0;
  uint64_t file_pos = 0;   // the Message record's file offset, or its chunk's
  uint64_t inner_pos = 0;  // the Message record's offset in the chunk's records (0 outside chunks)
  uint16_t channel = 0;
  uint64_t location = 0;
  uint64_t offset = 0;
  uint32_t size = 0;
};

// Where a chunk's records are, for read().
struct ChunkPlace {
  uint64_t records_offset = 0;  // file offset of the records field
  uint64_t records_size = 0;    // as stored (compressed)
  uint64_t uncompressed_size = 0;
  uint32_t crc = 0;
  std::string compression;
};

struct ChannelInfo {
  Channel record;
  std::string defined_at;  // where(...) of its record, for errors found later
  uint32_t topic = kNoTopic;
};

class Reader final : public BagFile {
 public:
  explicit Reader(const std::string& path);
  const std::string& path() const override { return path_; }
  Serialization serialization() const override { return Serialization::Cdr; }
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::vector<MessageRef> index(const std::vector<uint32_t>& topics, const IndexProgress& progress) override;
  void read(const MessageRef& message, std::vector<uint8_t>& out) override;

 private:
  enum class Mode { Scan, Indexed };  // Scan defines channels and keeps every message

  // mcap.cpp: the file, the summary, channels and topics.
  void read_exact(uint64_t offset, uint64_t size, uint8_t* out);
  RecordPrefix read_prefix(uint64_t offset, uint64_t end);
  std::vector<uint8_t> read_content(uint64_t offset, const RecordPrefix& prefix);
  Origin at_file(uint64_t base) const { return Origin{&path_, base, kNoChunk}; }
  void read_header();
  bool read_summary();
  void check_summary_crc(uint64_t summary_start, uint64_t footer_pos, uint32_t expected);
  void check_chunk_index(const ChunkIndex& ci) const;
  void add_schema(const Schema& s, const Cursor& c, size_t pos);
  void add_channel(const Channel& ch, const Cursor& c, size_t pos, Mode mode);
  void assign_topics();
  void check_asked(uint32_t topic) const;
  void cancel_if_asked(const IndexProgress& progress, double fraction) const;

  // mcap_index.cpp: finding messages.
  void scan(const IndexProgress& progress);
  ChunkPlace& chunk_at(uint64_t pos, const RecordPrefix& prefix);
  const std::vector<uint8_t>& chunk_records(uint64_t pos);
  void walk_chunk(uint64_t pos, Mode mode, const std::vector<bool>& wanted, std::vector<Found>& out);
  Found message_found(const MessageFixed& m, uint64_t record_length, const Cursor& c, size_t pos) const;
  std::vector<Found> by_chunk_indexes(const std::vector<bool>& wanted, const IndexProgress& progress);
  void by_message_index(const ChunkIndex& ci, const ChunkPlace& place, const std::vector<bool>& wanted,
                        std::vector<Found>& out);
  bool statistics_agree(const std::vector<Found>& found, const std::vector<bool>& wanted) const;

  std::string path_;
  std::ifstream file_;
  uint64_t file_size_ = 0;
  uint64_t data_start_ = 0;  // after the Header record
  uint64_t data_end_ = 0;    // the summary's start, or the file's end

  std::map<uint16_t, Schema> schemas_;
  std::map<uint16_t, ChannelInfo> channels_;
  std::vector<TopicInfo> topics_;
  std::vector<std::string> topic_problem_;  // per topic: why it cannot be indexed ("" when it can)

  std::vector<ChunkIndex> chunk_indexes_;       // sorted by chunk_start_offset
  std::map<uint16_t, uint64_t> stat_counts_;    // Statistics' channel_message_counts (may be empty)
  bool scanned_ = false;
  std::string scan_error_;                      // why the scan in index() failed, if it did
  std::vector<Found> all_;                      // every message, after a scan

  std::map<uint64_t, ChunkPlace> chunks_;       // by the Chunk record's file offset
  uint64_t cached_chunk_ = kNoChunk;
  std::vector<uint8_t> cached_;                 // the last chunk's records, decompressed
  std::vector<uint8_t> scratch_;                // compressed bytes being decompressed
};

}  // namespace planarvo::io::bag::mcap
