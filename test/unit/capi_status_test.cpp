// The C API's translation of exceptions into statuses (capi/status.h): an allocation that fails,
// in planarvo, in OpenCV or in the OpenCL driver, is PLANARVO_ERROR_OUT_OF_MEMORY, not
// PLANARVO_ERROR_INTERNAL ("a bug in planarvo"; issue 27), and messages reach the caller whole.
#include <new>
#include <string>

#include <CL/opencl.hpp>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "capi/status.h"
#include "core/error.h"

namespace planarvo::capi {
namespace {

template <class E>
planarvo_status status_of(const E& e) {
  return guard([&] { throw e; });
}

TEST(CApiStatus, AllocationFailuresAreOutOfMemoryWhereverTheyHappen) {
  EXPECT_EQ(status_of(std::bad_alloc()), PLANARVO_ERROR_OUT_OF_MEMORY);
  EXPECT_EQ(status_of(Error(ErrorCode::OutOfMemory, "the mosaic's tiles")), PLANARVO_ERROR_OUT_OF_MEMORY);
  EXPECT_EQ(std::string(planarvo_last_error()), "the mosaic's tiles");
  EXPECT_EQ(status_of(cv::Exception(cv::Error::StsNoMem, "Failed to allocate", "f", "file.cpp", 1)),
            PLANARVO_ERROR_OUT_OF_MEMORY);
  EXPECT_EQ(status_of(cl::Error(CL_OUT_OF_HOST_MEMORY, "clCreateBuffer")), PLANARVO_ERROR_OUT_OF_MEMORY);
  EXPECT_EQ(status_of(cl::Error(CL_MEM_OBJECT_ALLOCATION_FAILURE, "clEnqueueNDRangeKernel")),
            PLANARVO_ERROR_OUT_OF_MEMORY);
  // Other failures keep their statuses.
  EXPECT_EQ(status_of(cv::Exception(cv::Error::StsAssert, "assertion", "f", "file.cpp", 1)), PLANARVO_ERROR_INTERNAL);
  EXPECT_EQ(status_of(cl::Error(CL_INVALID_VALUE, "clSetKernelArg")), PLANARVO_ERROR_OPENCL);
  EXPECT_EQ(status_of(Error(ErrorCode::InvalidInput, "x")), PLANARVO_ERROR_INVALID_INPUT);
}

// printable_message: control bytes escaped, newline and tab kept, long messages keep their start
// and end and stop at 4096 bytes, and a second pass changes nothing.
TEST(CApiStatus, MessagesAreEscapedAndCappedOnce) {
  static const char kRaw[] = "a\0b\x1b[31m\n\tc\x7f";
  const std::string raw(kRaw, sizeof kRaw - 1);
  EXPECT_EQ(printable_message(raw), "a\\x00b\\x1b[31m\n\tc\\x7f");
  std::string long_one = "start " + std::string(100000, 'x') + " end";
  const std::string capped = printable_message(long_one);
  EXPECT_LE(capped.size(), kMaxErrorMessage);
  EXPECT_EQ(capped.substr(0, 6), "start ");
  EXPECT_EQ(capped.substr(capped.size() - 4), " end");
  EXPECT_EQ(printable_message(capped), capped);
  // A cut never splits a UTF-8 character (é is two bytes).
  std::string accents;
  while (accents.size() < 10000) accents += "\xc3\xa9";
  const std::string cut = printable_message(accents);
  const size_t marker = cut.find(" [... ");
  ASSERT_NE(marker, std::string::npos);
  EXPECT_EQ(marker % 2, 0u);
  EXPECT_NE(static_cast<unsigned char>(cut[cut.size() - 2]) & 0xc0, 0x80);
}

}  // namespace
}  // namespace planarvo::capi
