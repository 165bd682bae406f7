// The C API's contract: statuses and messages instead of exceptions, NULL safety, struct_size
// checks, thread-local error messages, buffer sizing.
#include <cstring>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "planarvo/planarvo.h"
#include "common/test_util.h"

namespace {

TEST(CApi, VersionMatchesHeader) {
  EXPECT_EQ(planarvo_version_number(), PLANARVO_VERSION_NUMBER);
  EXPECT_STREQ(planarvo_version_string(), "0.1.0");
}

TEST(CApi, NullArgumentsAreStatusesNotCrashes) {
  EXPECT_EQ(planarvo_context_create(nullptr, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("context"), std::string::npos);
  EXPECT_EQ(planarvo_list_devices(nullptr, 0, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_camera_load(nullptr, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_extrinsics_matrix(nullptr, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_context_destroy(nullptr);
  planarvo_dataset_destroy(nullptr);
}

TEST(CApi, StructSizeIsChecked) {
  planarvo_context_options o;
  planarvo_context_options_init(&o);
  EXPECT_EQ(o.struct_size, sizeof o);
  o.struct_size = 4;
  planarvo_context* c = nullptr;
  EXPECT_EQ(planarvo_context_create(&o, &c), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(c, nullptr);
  EXPECT_NE(std::string(planarvo_last_error()).find("struct_size"), std::string::npos);
}

TEST(CApi, ListDevicesSizesItsBuffer) {
  size_t n = 0;
  ASSERT_EQ(planarvo_list_devices(nullptr, 0, &n), PLANARVO_OK);
  ASSERT_GE(n, 1u) << "the test machine has PoCL";
  planarvo_device_info one{};
  one.struct_size = sizeof one;
  size_t m = 0;
  if (n > 1) {
    EXPECT_EQ(planarvo_list_devices(&one, 1, &m), PLANARVO_ERROR_BUFFER_TOO_SMALL);
  }
  std::vector<planarvo_device_info> all(n);
  for (auto& d : all) d.struct_size = sizeof d;
  ASSERT_EQ(planarvo_list_devices(all.data(), n, &m), PLANARVO_OK);
  EXPECT_EQ(m, n);
  EXPECT_GT(std::strlen(all[0].device_name), 0u);
  EXPECT_GT(all[0].max_work_group_size, 0u);
  EXPECT_EQ(all[0].index, 0);
}

TEST(CApi, UnknownDeviceIsNoDevice) {
  planarvo_context_options o;
  planarvo_context_options_init(&o);
  o.device = "no-such-device-xyz";
  planarvo_context* c = nullptr;
  EXPECT_EQ(planarvo_context_create(&o, &c), PLANARVO_ERROR_NO_DEVICE);
  EXPECT_EQ(c, nullptr);
  EXPECT_NE(std::string(planarvo_last_error()).find("no-such-device-xyz"), std::string::npos);
}

TEST(CApi, ContextOnDefaultDevice) {
  planarvo_context* c = nullptr;
  ASSERT_EQ(planarvo_context_create(nullptr, &c), PLANARVO_OK) << planarvo_last_error();
  planarvo_device_info info{};
  info.struct_size = sizeof info;
  EXPECT_EQ(planarvo_context_device(c, &info), PLANARVO_OK);
  EXPECT_GT(std::strlen(info.device_name), 0u);
  planarvo_context_destroy(c);
}

TEST(CApi, LastErrorIsPerThread) {
  EXPECT_EQ(planarvo_context_create(nullptr, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  const std::string here = planarvo_last_error();
  std::string there = "unset";
  std::thread t([&] {
    there = planarvo_last_error();  // nothing failed on this thread yet
    EXPECT_EQ(planarvo_camera_load("/nonexistent/camera.yaml", nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  });
  t.join();
  EXPECT_EQ(there, "");
  EXPECT_EQ(std::string(planarvo_last_error()), here);
}

TEST(CApi, StatusNamesAreDistinct) {
  EXPECT_STREQ(planarvo_status_name(PLANARVO_OK), "PLANARVO_OK");
  EXPECT_STREQ(planarvo_status_name(PLANARVO_ERROR_NO_DEVICE), "PLANARVO_ERROR_NO_DEVICE");
  EXPECT_STREQ(planarvo_status_name(static_cast<planarvo_status>(999)), "PLANARVO_ERROR_UNKNOWN");
}

TEST(CApi, ExtrinsicsMatrixFollowsConventions) {
  const planarvo_extrinsics e{0.1, -0.2, 0.3, 0, 0, 0};
  double m[16];
  ASSERT_EQ(planarvo_extrinsics_matrix(&e, m), PLANARVO_OK);
  // Straight down, image top forward: camera z -> robot -z, camera y (image down) -> robot -x.
  EXPECT_DOUBLE_EQ(m[2 * 4 + 2], -1.0);
  EXPECT_DOUBLE_EQ(m[0 * 4 + 1], -1.0);
  EXPECT_DOUBLE_EQ(m[0 * 4 + 3], 0.1);
  EXPECT_DOUBLE_EQ(m[2 * 4 + 3], 0.3);
  EXPECT_DOUBLE_EQ(m[15], 1.0);
}

}  // namespace
