// Helpers shared by the fuzz targets: a scratch directory of this process's own (removed at exit)
// where the input bytes are written for readers that take a path, and the checks every target
// makes on what the C API returns.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "planarvo/planarvo.h"

namespace planarvo_fuzz {

namespace detail {
inline std::string make_work_dir() {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/planarvo-fuzz-XXXXXX";
  if (!mkdtemp(pattern.data())) {
    std::perror("planarvo fuzz: mkdtemp");
    std::abort();
  }
  return pattern;
}
}  // namespace detail

// This process's scratch directory, created on first use and removed when the process exits.
inline const std::string& work_dir() {
  static const std::string dir = [] {
    std::string d = detail::make_work_dir();
    static std::string to_remove;
    to_remove = d;
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(to_remove, ec);
    });
    return d;
  }();
  return dir;
}

// Replaces the file at path with the bytes; aborts when it cannot (a harness fault, not a finding).
inline void write_file(const std::string& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "planarvo fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

// A broken promise of the API (not a crash the sanitizers would see): reported as a crash.
[[noreturn]] inline void broken(const char* what) {
  std::fprintf(stderr, "planarvo fuzz: broken promise: %s\n", what);
  std::abort();
}

// Every failed call leaves a message, and a status the API knows. PLANARVO_ERROR_INTERNAL means "a
// bug in planarvo" (an exception the library did not expect, e.g. an OpenCV assertion), so bad
// arguments or input must never give it (running out of memory is PLANARVO_ERROR_OUT_OF_MEMORY).
// The message is printable (no control character but newline and tab) and at most
// 4096 bytes, whatever the input held.
inline void check_status(planarvo_status st) {
  if (st == PLANARVO_OK) return;
  const char* name = planarvo_status_name(st);
  if (!name || !*name) broken("a failure status without a name");
  const char* msg = planarvo_last_error();
  if (!msg || !*msg) broken("a failure without a message");
  const std::string text(msg);
  if (text.size() > 4096) broken("a message longer than 4096 bytes");
  for (const char c : text)
    if ((static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t') || c == 0x7f)
      broken("a message with a control character");
  if (st == PLANARVO_ERROR_INTERNAL) {
    std::fprintf(stderr, "planarvo fuzz: PLANARVO_ERROR_INTERNAL: %s\n", msg);
    broken("bad input or arguments gave PLANARVO_ERROR_INTERNAL");
  }
}

inline bool is_finite(double v) { return std::isfinite(v); }

}  // namespace planarvo_fuzz
