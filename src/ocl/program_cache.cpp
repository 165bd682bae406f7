// The on-disk program cache: key, location, entry format (see program_cache.h).
#include "ocl/program_cache.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <system_error>

#include "core/error.h"
#include "core/output_file.h"
#include "ocl/cache_dirs.h"

namespace planarvo::ocl {

uint64_t fnv1a64(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

namespace detail {
namespace {

constexpr char kMagic[8] = {'P', 'V', 'C', 'L', 'P', 'R', 'O', 'G'};

// A second, differently ordered pass, so that file names carry 128 bits: two keys that collide
// in one are unlikely to collide in both. (A collision would only cost a rebuild: the header
// holds the full key.)
uint64_t fnv1a64_reversed(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (auto it = s.rbegin(); it != s.rend(); ++it) {
    h ^= static_cast<unsigned char>(*it);
    h *= 0x100000001b3ull;
  }
  return h;
}

uint64_t fnv1a64(const unsigned char* p, size_t n) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

void put_u32(std::vector<unsigned char>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<unsigned char>(v >> (8 * i)));
}
void put_u64(std::vector<unsigned char>& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

// Reads little-endian integers from a byte range, remembering whether it ran past the end.
class Reader {
 public:
  explicit Reader(const std::vector<unsigned char>& b) : b_(b) {}
  bool take(size_t n) {
    if (n > b_.size() - pos_) return false;
    pos_ += n;
    return true;
  }
  bool u32(uint32_t& v) {
    if (4 > b_.size() - pos_) return false;
    v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(b_[pos_ + i]) << (8 * i);
    pos_ += 4;
    return true;
  }
  bool u64(uint64_t& v) {
    if (8 > b_.size() - pos_) return false;
    v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(b_[pos_ + i]) << (8 * i);
    pos_ += 8;
    return true;
  }
  size_t pos() const { return pos_; }
  size_t left() const { return b_.size() - pos_; }

 private:
  const std::vector<unsigned char>& b_;
  size_t pos_ = 0;
};

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string();
}

}  // namespace

std::string hex64(uint64_t v) {
  static const char digits[] = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, v >>= 4) s[static_cast<size_t>(i)] = digits[v & 0xf];
  return s;
}

std::string resolve_cache_dir(const RuntimeOptions& options) {
  if (!options.use_cache) return {};
  if (!options.cache_dir.empty()) return options.cache_dir;
  if (std::string d = env("PLANARVO_CACHE_DIR"); !d.empty()) return d;
  // The user's cache directory; for a service user with no home (or one it cannot write), a
  // private directory under the temp directory; failing both, nothing is cached.
  if (const auto user = user_cache_dir("planarvo"); cache_dir_usable(user)) return user.string();
  if (const auto temp = private_temp_dir(); !temp.empty()) return (temp / "programs").string();
  return {};
}

std::string cache_key(const std::string& name, const std::string& source,
                      const std::string& effective_options, const DeviceInfo& device) {
  // One field per line; the source enters as its length and two hashes so that the key (which
  // every entry's header repeats) stays small.
  std::string key = "planarvo program cache key 1\n";
  key += "program: " + name + "\n";
  key += "source: " + std::to_string(source.size()) + " " + hex64(ocl::fnv1a64(source)) + " " +
         hex64(fnv1a64_reversed(source)) + "\n";
  key += "options: " + effective_options + "\n";
  key += "platform: " + device.platform_name + " | " + device.platform_version + "\n";
  key += "device: " + device.device_name + " | " + device.device_version + "\n";
  key += "driver: " + device.driver_version + "\n";
  return key;
}

std::filesystem::path cache_entry_path(const std::string& cache_dir, const std::string& name,
                                       const std::string& key) {
  return std::filesystem::path(cache_dir) /
         (name + "-" + hex64(ocl::fnv1a64(key)) + hex64(fnv1a64_reversed(key)) + ".clbin");
}

std::vector<unsigned char> encode_cache_entry(const std::string& key,
                                              const std::vector<unsigned char>& binary) {
  std::vector<unsigned char> out(kMagic, kMagic + sizeof kMagic);
  put_u32(out, kCacheFormatVersion);
  put_u32(out, static_cast<uint32_t>(key.size()));
  out.insert(out.end(), key.begin(), key.end());
  put_u64(out, binary.size());
  put_u64(out, fnv1a64(binary.data(), binary.size()));
  out.insert(out.end(), binary.begin(), binary.end());
  return out;
}

std::optional<std::vector<unsigned char>> decode_cache_entry(
    const std::vector<unsigned char>& bytes, const std::string& key) {
  Reader r(bytes);
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    return std::nullopt;
  r.take(sizeof kMagic);
  uint32_t version = 0, key_size = 0;
  if (!r.u32(version) || version != kCacheFormatVersion) return std::nullopt;
  if (!r.u32(key_size) || key_size != key.size() || r.left() < key_size) return std::nullopt;
  if (std::memcmp(bytes.data() + r.pos(), key.data(), key.size()) != 0) return std::nullopt;
  r.take(key_size);
  uint64_t size = 0, hash = 0;
  if (!r.u64(size) || !r.u64(hash)) return std::nullopt;
  if (size == 0 || size != r.left()) return std::nullopt;  // truncated, or trailing bytes
  const unsigned char* p = bytes.data() + r.pos();
  if (fnv1a64(p, static_cast<size_t>(size)) != hash) return std::nullopt;
  return std::vector<unsigned char>(p, p + size);
}

std::optional<std::vector<unsigned char>> read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  if (in.bad()) return std::nullopt;
  return bytes;
}

bool write_file_atomically(const std::filesystem::path& path, const unsigned char* data,
                           size_t size) {
  // Other threads and processes may write the same entry: each writes a temporary of its own
  // (core/output_file.h).
  try {
    OutputFile out(path.string());
    if (size > 0 && std::fwrite(data, 1, size, out.stream()) != size) return false;  // discarded
    out.commit();
    return true;
  } catch (const Error&) {
    return false;
  }
}

}  // namespace detail
}  // namespace planarvo::ocl
