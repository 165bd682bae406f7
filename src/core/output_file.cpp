#include "core/output_file.h"

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <random>
#include <system_error>

#include <fcntl.h>
#include <unistd.h>

#include "core/error.h"

namespace planarvo {

namespace {

// A destination to write directly: one that exists and is not a regular file.
bool write_directly(const std::string& path) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  return !ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st);
}

// A suffix no other writer (thread or process) picks at the same time.
std::string unique_suffix() {
  static std::atomic<uint64_t> counter{0};
  const uint64_t unique =
      (static_cast<uint64_t>(std::random_device{}()) << 32) ^
      static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) ^
      (counter.fetch_add(1) * 0x9e3779b97f4a7c15ull);
  char buf[20];
  std::snprintf(buf, sizeof buf, "-%016llx", static_cast<unsigned long long>(unique));
  return buf;
}

}  // namespace

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
  if (write_directly(path_)) {
    temporary_ = path_;
    file_ = std::fopen(temporary_.c_str(), "wb");
    if (!file_) fail("cannot open for writing", errno);
    return;
  }
  int err = EEXIST;
  for (int attempt = 0; attempt < 16 && err == EEXIST; ++attempt) {
    temporary_ = path_ + kSuffix + unique_suffix();
    // Exclusive, and never through a link: a name someone else made is not ours to write.
    const int fd = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0) {
      err = errno;
      continue;
    }
    file_ = ::fdopen(fd, "wb");
    if (!file_) {
      err = errno;
      ::close(fd);
      std::remove(temporary_.c_str());
      fail("cannot open for writing", err);
    }
    return;
  }
  fail("cannot create a temporary file beside it", err);
}

OutputFile::~OutputFile() { discard(); }

void OutputFile::commit() {
  if (!file_) throw Error(ErrorCode::Internal, path_ + ": committed after it was closed");
  int err = std::ferror(file_) ? EIO : 0;  // a write that failed earlier
  errno = 0;
  if (std::fflush(file_) != 0 && err == 0) err = errno != 0 ? errno : EIO;
  errno = 0;
  if (std::fclose(file_) != 0 && err == 0) err = errno != 0 ? errno : EIO;
  file_ = nullptr;
  if (err != 0) {
    if (temporary_ != path_) std::remove(temporary_.c_str());
    fail("write failed", err);
  }
  if (temporary_ != path_ && std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    const int rename_errno = errno;
    std::remove(temporary_.c_str());
    fail("cannot replace the file with the completed " + temporary_, rename_errno);
  }
}

void OutputFile::discard() noexcept {
  if (!file_) return;
  std::fclose(file_);
  file_ = nullptr;
  if (temporary_ != path_) std::remove(temporary_.c_str());
}

void OutputFile::fail(const std::string& what, int err) {
  throw Error(ErrorCode::Io, path_ + ": " + what + " (" + std::generic_category().message(err) + ")");
}

}  // namespace planarvo
