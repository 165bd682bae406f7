// Chunk decompression for ROS bags (Bags/Format/2.0 "Chunk"): bz2 through libbz2's stream API
// and lz4 through liblz4's frame API (roslz4 writes LZ4 frames). PLANARVO_HAVE_BZ2 and
// PLANARVO_HAVE_LZ4 come from cmake/PlanarvoCompression.cmake; a compile that does not set them
// (a direct compile of the bag sources) links both libraries.
#include "io/bag/rosbag1_decompress.h"

#include <algorithm>
#include <climits>
#include <memory>

#include "core/error.h"

#ifndef PLANARVO_HAVE_BZ2
#define PLANARVO_HAVE_BZ2 1
#endif
#ifndef PLANARVO_HAVE_LZ4
#define PLANARVO_HAVE_LZ4 1
#endif
#if PLANARVO_HAVE_BZ2
#include <bzlib.h>
#endif
#if PLANARVO_HAVE_LZ4
#include <lz4frame.h>
#endif

namespace planarvo::io::bag::rosbag1 {

namespace {

// The output buffer: starts at a few times the input and doubles as the stream yields bytes, up
// to size + 1 (one byte more than the header says, so that a longer stream is caught).
class Output {
 public:
  Output(std::vector<uint8_t>& out, size_t n, uint32_t size) : out_(out), limit_(static_cast<size_t>(size) + 1) {
    out_.clear();
    out_.resize(std::min(limit_, std::max<size_t>(65536, 4 * n)));
  }
  // Room for more output; false when the buffer is at its limit and full.
  bool make_room() {
    if (produced_ < out_.size()) return true;
    if (out_.size() == limit_) return false;
    out_.resize(std::min(limit_, 2 * out_.size()));
    return true;
  }
  uint8_t* next() { return out_.data() + produced_; }
  size_t room() const { return out_.size() - produced_; }
  void advance(size_t n) { produced_ += n; }
  size_t produced() const { return produced_; }
  void finish() { out_.resize(produced_); }

 private:
  std::vector<uint8_t>& out_;
  size_t limit_;
  size_t produced_ = 0;
};

#if PLANARVO_HAVE_BZ2
void decompress_bz2(const uint8_t* data, size_t n, Output& out, const std::string& where) {
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) throw_invalid_input(where + ": bz2 decompression cannot start");
  std::unique_ptr<bz_stream, int (*)(bz_stream*)> end(&s, BZ2_bzDecompressEnd);
  s.next_in = const_cast<char*>(reinterpret_cast<const char*>(data));
  s.avail_in = static_cast<unsigned>(n);  // n <= UINT32_MAX: a record's data_len
  for (;;) {
    if (!out.make_room()) throw_invalid_input(where + ": the bz2 data decompress to more than the chunk's size");
    const unsigned room = static_cast<unsigned>(std::min<size_t>(out.room(), UINT_MAX));
    const unsigned in_before = s.avail_in;
    s.next_out = reinterpret_cast<char*>(out.next());
    s.avail_out = room;
    const int ret = BZ2_bzDecompress(&s);
    out.advance(room - s.avail_out);
    if (ret == BZ_STREAM_END) break;
    if (ret != BZ_OK)
      throw_invalid_input(where + ": the bz2 data are corrupt (libbz2 error " + std::to_string(ret) + ")");
    if (s.avail_in == in_before && s.avail_out == room)
      throw_invalid_input(where + ": the bz2 stream ends before its end marker");
  }
  if (s.avail_in != 0)
    throw_invalid_input(where + ": " + std::to_string(s.avail_in) + " bytes after the end of the bz2 stream");
}
#endif

#if PLANARVO_HAVE_LZ4
void decompress_lz4(const uint8_t* data, size_t n, Output& out, const std::string& where) {
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
    throw_invalid_input(where + ": lz4 decompression cannot start");
  std::unique_ptr<LZ4F_dctx, size_t (*)(LZ4F_dctx*)> free_ctx(ctx, LZ4F_freeDecompressionContext);
  size_t in_pos = 0;
  for (;;) {
    if (!out.make_room()) throw_invalid_input(where + ": the lz4 data decompress to more than the chunk's size");
    size_t dst = out.room();
    size_t src = n - in_pos;
    const size_t ret = LZ4F_decompress(ctx, out.next(), &dst, data + in_pos, &src, nullptr);
    if (LZ4F_isError(ret))
      throw_invalid_input(where + ": the lz4 data are corrupt (" + LZ4F_getErrorName(ret) + ")");
    in_pos += src;
    out.advance(dst);
    if (ret == 0) break;  // the frame is complete
    if (src == 0 && dst == 0) throw_invalid_input(where + ": the lz4 frame ends early");
  }
  if (in_pos != n)
    throw_invalid_input(where + ": " + std::to_string(n - in_pos) + " bytes after the end of the lz4 frame");
}
#endif

}  // namespace

void decompress_chunk(const std::string& compression, const uint8_t* data, size_t n, uint32_t size,
                      std::vector<uint8_t>& out, const Place& place, uint64_t chunk_pos) {
  const std::string where = place.at(chunk_pos) + ": chunk compressed with " + compression;
  Output output(out, n, size);
  if (compression == "bz2") {
#if PLANARVO_HAVE_BZ2
    decompress_bz2(data, n, output, where);
#else
    throw_invalid_input(where + ": this build of planarvo has no bz2 support (Debian: libbz2-dev)");
#endif
  } else if (compression == "lz4") {
#if PLANARVO_HAVE_LZ4
    decompress_lz4(data, n, output, where);
#else
    throw_invalid_input(where + ": this build of planarvo has no lz4 support (Debian: liblz4-dev)");
#endif
  } else {
    throw_invalid_input(where + ": an unknown compression (ROS bags use none, bz2 or lz4)");
  }
  if (output.produced() != size)
    throw_invalid_input(where + ": the data decompress to " + std::to_string(output.produced()) +
                        " bytes, the chunk header says " + std::to_string(size));
  output.finish();
}

}  // namespace planarvo::io::bag::rosbag1
