// Internal to src/io: reading line-oriented text files with errors that name the file and line,
// locale-independent number parsing and formatting, and a checked writer. Not part of the
// interface other layers use (that is formats.h, stats.h, dataset.h).
#pragma once
#include <cstdio>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/output_file.h"

namespace planarvo::io::detail {

// "path:line: message", the form compilers use, so editors can jump to it.
std::string where(const std::string& path, int line);

// Why path cannot be read as an input file ("does not exist", "is a directory, not a file", "is a
// named pipe (FIFO), not a regular file", "cannot be read (Permission denied)", ...), or "" when
// it is a regular file this process may read. Called before opening, so that a FIFO never blocks
// the reader and each case gets its own words instead of a decoder's.
std::string input_file_problem(const std::string& path);
// Throws InvalidInput "path: <problem> (context)" when there is one; context may be empty.
void check_input_file(const std::string& path, const std::string& context = std::string());

// Reads a text file line by line, skipping blank lines and lines whose first non-blank character
// is '#'. Strips a trailing '\r' (files written on Windows) and surrounding blanks. Throws
// InvalidInput naming the file when it cannot be opened or read.
class LineReader {
 public:
  explicit LineReader(std::string path);
  // The next content line into `line`; false at the end of the file.
  bool next(std::string& line);
  int line_number() const { return line_number_; }
  const std::string& path() const { return path_; }
  // Throws InvalidInput "path:line: message" for the current line.
  [[noreturn]] void fail(const std::string& message) const;

 private:
  std::string path_;
  std::ifstream in_;
  int line_number_ = 0;
};

// Whitespace-separated fields of a line.
std::vector<std::string_view> split_fields(std::string_view line);

// Parses a whole field as a finite double (locale-independent; a leading '+' is accepted).
// On failure reader.fail() with a message naming `what`.
double parse_number(const LineReader& reader, std::string_view field, const char* what);

// Locale-independent formatting: the shortest text that reads back to the same double, and a
// fixed-point form with `decimals` digits after the point (timestamps).
std::string format_exact(double v);
std::string format_fixed(double v, int decimals);

// A file opened for writing whose every failure is Error(Io) naming the file. It appears
// complete or not at all (core/output_file.h): close() renames the finished file onto the
// path; destroyed without close(), it leaves the path as it was.
class TextWriter {
 public:
  explicit TextWriter(std::string path);
  ~TextWriter();
  TextWriter(const TextWriter&) = delete;
  TextWriter& operator=(const TextWriter&) = delete;

  void write(std::string_view text);
  // Hands the written text to the operating system, so that a crash of this process loses none
  // (it is then in the path's temporary, PATH.partial-<random>: temporary_path()).
  void flush();
  // Completes the file: flushes, closes and renames it onto the path, reporting any failure.
  // The destructor, without close(), removes the temporary and leaves the path as it was.
  void close();
  const std::string& path() const { return file_.path(); }
  const std::string& temporary_path() const { return file_.temporary_path(); }

 private:
  [[noreturn]] void fail(const char* what) const;
  OutputFile file_;
};

}  // namespace planarvo::io::detail
