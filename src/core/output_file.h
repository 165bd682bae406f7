// A file that appears complete or not at all: written under a temporary name of its own beside
// its destination (DEST.partial-<random>) and renamed onto it by commit(), which on POSIX
// replaces an existing file atomically. Until then an existing DEST is untouched, and a writer
// that is destroyed or discarded without commit() removes its temporary: a command that stops on
// an error writes nothing and overwrites nothing. A crash of the process leaves what was written
// in its DEST.partial-<random>. A destination that exists and is not a regular file (a device
// such as /dev/stdout, a pipe) is written directly, as there is nothing to rename onto.
//
// The temporary is created exclusively (O_CREAT | O_EXCL) and never through a symbolic link
// (O_NOFOLLOW), mode 0666 less the umask: two writers of one destination (two processes, or
// threads sharing a cache) each write their own temporary and the last rename wins, so the file
// is one writer's, whole, never a splice of both; a link planted at a temporary's name in a
// shared directory is refused rather than followed to its target.
#pragma once
#include <cstdio>
#include <string>

namespace planarvo {

class OutputFile {
 public:
  // Opens a new temporary for writing (binary). Error(Io) naming the destination when it cannot.
  explicit OutputFile(std::string path);
  ~OutputFile();  // discard() without reporting
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // The open stream; nullptr after commit() or discard().
  std::FILE* stream() const { return file_; }
  bool is_open() const { return file_ != nullptr; }
  // Flushes, closes and renames onto the destination. Error(Io) naming the destination on any
  // failure (a failed write that the stream recorded included), after removing the temporary.
  void commit();
  // Closes and removes the temporary; the destination is left as it was.
  void discard() noexcept;
  const std::string& path() const { return path_; }
  // Where the bytes are until commit(): DEST.partial-<random>, or DEST when written directly.
  const std::string& temporary_path() const { return temporary_; }

  // The temporary's name is the destination's, this, and a dash with 16 hex digits.
  static constexpr const char* kSuffix = ".partial";

 private:
  [[noreturn]] void fail(const std::string& what, int err);
  std::string path_, temporary_;  // temporary_ == path_ when written directly
  std::FILE* file_ = nullptr;
};

}  // namespace planarvo
