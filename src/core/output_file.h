// A file that appears complete or not at all: written under a temporary name beside its
// destination (DEST.partial) and renamed onto it by commit(), which on POSIX replaces an
// existing file atomically. Until then an existing DEST is untouched, and a writer that is
// destroyed or discarded without commit() removes its temporary: a command that stops on an
// error writes nothing and overwrites nothing. A crash of the process leaves what was written
// in DEST.partial. A destination that exists and is not a regular file (a device such as
// /dev/stdout, a pipe) is written directly, as there is nothing to rename onto. Where several
// threads or processes may write the same file at once (a shared cache), each takes a
// temporary name of its own (Temporary::Unique, DEST.partial-<random>) and the last rename wins.
#pragma once
#include <cstdio>
#include <string>

namespace planarvo {

class OutputFile {
 public:
  enum class Temporary { Fixed, Unique };
  // Opens the temporary for writing (binary). Error(Io) naming the destination when it cannot.
  explicit OutputFile(std::string path, Temporary temporary = Temporary::Fixed);
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

  static constexpr const char* kSuffix = ".partial";

 private:
  [[noreturn]] void fail(const std::string& what, int err);
  std::string path_, temporary_;  // temporary_ == path_ when written directly
  std::FILE* file_ = nullptr;
};

}  // namespace planarvo
