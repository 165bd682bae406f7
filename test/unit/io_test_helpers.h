// Helpers for the io_* and image_* tests: writing small text files and checking that an
// InvalidInput error names the file (and line).
#pragma once
#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"

namespace planarvo::test {

inline void write_text(const std::filesystem::path& file, const std::string& content) {
  std::filesystem::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out << content;
  ASSERT_TRUE(out.good()) << file;
}

inline std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Runs f, expecting Error(code) whose message contains `file`, and "file:line:" when line > 0.
// Returns the message (empty when nothing was thrown).
template <typename F>
std::string expect_error(F&& f, ErrorCode code, const std::string& file, int line = 0) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(static_cast<int>(e.code()), static_cast<int>(code)) << e.what();
    EXPECT_THAT(e.what(), ::testing::HasSubstr(file));
    if (line > 0) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr(file + ":" + std::to_string(line) + ":"));
    }
    return e.what();
  }
  ADD_FAILURE() << "no planarvo::Error was thrown (expected one naming " << file << ")";
  return std::string();
}

template <typename F>
std::string expect_invalid_input(F&& f, const std::string& file, int line = 0) {
  return expect_error(std::forward<F>(f), ErrorCode::InvalidInput, file, line);
}

}  // namespace planarvo::test
