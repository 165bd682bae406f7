#include "io/bag/mcap_decompress.h"

#include <algorithm>
#include <memory>

#include "core/error.h"

// The build defines PLANARVO_HAVE_ZSTD / _LZ4 as 0 or 1 (cmake/PlanarvoCompression.cmake); a
// compile by hand without them uses what the system has.
#ifndef PLANARVO_HAVE_ZSTD
#if __has_include(<zstd.h>)
#define PLANARVO_HAVE_ZSTD 1
#else
#define PLANARVO_HAVE_ZSTD 0
#endif
#endif
#ifndef PLANARVO_HAVE_LZ4
#if __has_include(<lz4frame.h>)
#define PLANARVO_HAVE_LZ4 1
#else
#define PLANARVO_HAVE_LZ4 0
#endif
#endif

#if PLANARVO_HAVE_ZSTD
#include <zstd.h>
#endif
#if PLANARVO_HAVE_LZ4
#include <lz4frame.h>
#endif

namespace planarvo::io::bag::mcap {

namespace {

// The output buffer, grown as the decoder fills it, up to the declared size.
class Output {
 public:
  Output(std::vector<uint8_t>& out, uint64_t expected, size_t input_size) : out_(out), expected_(expected) {
    const uint64_t first = std::max<uint64_t>(uint64_t{input_size} * 4, uint64_t{1} << 20);
    out_.resize(static_cast<size_t>(std::min(expected_, first)));
  }
  // Room for more output; false when the declared size is reached.
  bool grow_if_full() {
    if (produced_ < out_.size()) return true;
    if (out_.size() >= expected_) return false;
    out_.resize(static_cast<size_t>(std::min<uint64_t>(expected_, uint64_t{out_.size()} * 2)));
    return true;
  }
  uint8_t* free_begin() { return out_.data() + produced_; }
  size_t free_size() const { return out_.size() - produced_; }
  void advance(size_t n) { produced_ += n; }
  size_t produced() const { return produced_; }

 private:
  std::vector<uint8_t>& out_;
  uint64_t expected_;
  size_t produced_ = 0;
};

#if PLANARVO_HAVE_ZSTD || PLANARVO_HAVE_LZ4
// The declared size is full but the data go on (more input, or a frame not yet complete).
[[noreturn]] void not_that_size(const std::string& context, const char* name, uint64_t expected) {
  throw_invalid_input(context + "the chunk's " + name + " data do not decompress to its uncompressed_size (" +
                      std::to_string(expected) + " bytes): more data or an unfinished frame follow");
}
#endif

#if PLANARVO_HAVE_ZSTD
size_t zstd(const uint8_t* data, size_t size, Output& out, uint64_t expected, const std::string& context) {
  struct Free {
    void operator()(ZSTD_DCtx* d) const { ZSTD_freeDCtx(d); }
  };
  std::unique_ptr<ZSTD_DCtx, Free> ctx(ZSTD_createDCtx());
  if (!ctx) throw Error(ErrorCode::Internal, "zstd: out of memory");
  ZSTD_inBuffer in{data, size, 0};
  size_t last = 1;  // ZSTD_decompressStream's result: 0 when a frame is complete
  while (in.pos < in.size || last != 0) {
    if (!out.grow_if_full()) {
      if (in.pos < in.size || last != 0) not_that_size(context, "zstd", expected);
      break;
    }
    ZSTD_outBuffer o{out.free_begin(), out.free_size(), 0};
    const size_t before_in = in.pos;
    last = ZSTD_decompressStream(ctx.get(), &o, &in);
    if (ZSTD_isError(last))
      throw_invalid_input(context + "the chunk's zstd data are corrupt (" + ZSTD_getErrorName(last) + ")");
    out.advance(o.pos);
    if (o.pos == 0 && in.pos == before_in && in.pos == in.size && last != 0)
      throw_invalid_input(context + "the chunk's zstd data end inside a frame");
  }
  return out.produced();
}
#endif

#if PLANARVO_HAVE_LZ4
size_t lz4(const uint8_t* data, size_t size, Output& out, uint64_t expected, const std::string& context) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION)))
    throw Error(ErrorCode::Internal, "lz4: cannot create a decompression context");
  struct Free {
    void operator()(LZ4F_dctx* d) const { LZ4F_freeDecompressionContext(d); }
  };
  std::unique_ptr<LZ4F_dctx, Free> ctx(raw);
  size_t pos = 0;
  size_t hint = 1;  // LZ4F_decompress's result: 0 when a frame is complete
  while (pos < size || hint != 0) {
    if (!out.grow_if_full()) {
      if (pos < size || hint != 0) not_that_size(context, "lz4", expected);
      break;
    }
    size_t dst_size = out.free_size();
    size_t src_size = size - pos;
    hint = LZ4F_decompress(ctx.get(), out.free_begin(), &dst_size, data + pos, &src_size, nullptr);
    if (LZ4F_isError(hint))
      throw_invalid_input(context + "the chunk's lz4 data are corrupt (" + LZ4F_getErrorName(hint) + ")");
    pos += src_size;
    out.advance(dst_size);
    if (dst_size == 0 && src_size == 0 && pos == size && hint != 0)
      throw_invalid_input(context + "the chunk's lz4 data end inside a frame");
  }
  return out.produced();
}
#endif

#if !PLANARVO_HAVE_ZSTD || !PLANARVO_HAVE_LZ4
[[noreturn]] void missing_library(const std::string& context, const std::string& compression, const char* package) {
  throw_invalid_input(context + "the chunk is compressed with " + compression + ", which this build of planarvo " +
                      "cannot read (rebuild with the Debian package " + package + ")");
}
#endif

}  // namespace

void decompress_chunk(const std::string& compression, const uint8_t* data, size_t size,
                      uint64_t uncompressed_size, std::vector<uint8_t>& out, const std::string& context) {
  if (compression != "zstd" && compression != "lz4")
    throw_invalid_input(context + "the chunk's compression \"" + compression +
                        "\" is none that MCAP defines (\"\", \"zstd\", \"lz4\")");
  if (uncompressed_size > kMaxChunkSize)
    throw_invalid_input(context + "the chunk's uncompressed_size (" + std::to_string(uncompressed_size) +
                        " bytes) is over planarvo's limit of " + std::to_string(kMaxChunkSize) + " bytes");
  Output output(out, uncompressed_size, size);
  size_t produced = 0;
  if (compression == "zstd") {
#if PLANARVO_HAVE_ZSTD
    produced = zstd(data, size, output, uncompressed_size, context);
#else
    missing_library(context, compression, "libzstd-dev");
#endif
  } else {
#if PLANARVO_HAVE_LZ4
    produced = lz4(data, size, output, uncompressed_size, context);
#else
    missing_library(context, compression, "liblz4-dev");
#endif
  }
  if (produced != uncompressed_size)
    throw_invalid_input(context + "the chunk's " + compression + " data decompress to " + std::to_string(produced) +
                        " bytes, not its uncompressed_size of " + std::to_string(uncompressed_size));
}

}  // namespace planarvo::io::bag::mcap
