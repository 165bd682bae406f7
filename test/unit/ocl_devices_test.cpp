// Device enumeration and selection (src/ocl/runtime.h). Needs one OpenCL device, which CI has
// through PoCL; no GPU.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>

#include "core/error.h"
#include "ocl/runtime.h"
#include "unit/ocl_test_helpers.h"

namespace planarvo {
namespace {

using ::testing::HasSubstr;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

TEST(OclDevices, ListsAtLeastOneDeviceWithSensibleFields) {
  const std::vector<ocl::DeviceInfo> devices = ocl::list_devices();
  ASSERT_FALSE(devices.empty()) << "no OpenCL device; CI expects PoCL's CPU device";
  for (size_t i = 0; i < devices.size(); ++i) {
    const ocl::DeviceInfo& d = devices[i];
    SCOPED_TRACE(d.device_name);
    EXPECT_EQ(d.global_index, static_cast<int>(i));
    EXPECT_FALSE(d.platform_name.empty());
    EXPECT_FALSE(d.device_name.empty());
    EXPECT_THAT(d.platform_version, HasSubstr("OpenCL"));
    EXPECT_THAT(d.device_version, HasSubstr("OpenCL"));
    EXPECT_THAT(d.opencl_c_version, HasSubstr("OpenCL C"));
    EXPECT_FALSE(d.driver_version.empty());
    EXPECT_THAT((std::vector<std::string>{"GPU", "CPU", "ACCELERATOR", "OTHER"}),
                ::testing::Contains(d.type));
    EXPECT_GT(d.max_work_group_size, 0u);
    EXPECT_GT(d.compute_units, 0u);
    EXPECT_GT(d.global_mem_size, 0u);
    EXPECT_GT(d.local_mem_size, 0u);
    // Names are trimmed: drivers pad them with spaces and NULs.
    EXPECT_NE(d.device_name.back(), ' ');
    EXPECT_NE(d.device_name.back(), '\0');
  }
}

TEST(OclDevices, ListingTwiceGivesTheSameOrder) {
  const auto a = ocl::list_devices(), b = ocl::list_devices();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].device_name, b[i].device_name);
}

TEST(OclDevices, SelectsByIndex) {
  test::ScopedEnv env("PLANARVO_DEVICE", nullptr);
  const auto devices = ocl::list_devices();
  ASSERT_FALSE(devices.empty());
  const size_t last = devices.size() - 1;
  ocl::Runtime rt(test::on_device(std::to_string(last)));
  EXPECT_EQ(rt.device_info().global_index, static_cast<int>(last));
  EXPECT_EQ(rt.device_info().device_name, devices[last].device_name);
  ocl::Runtime first(test::on_device("0"));
  EXPECT_EQ(first.device_info().global_index, 0);
}

TEST(OclDevices, SelectsByCaseInsensitiveSubstringOfTheDeviceName) {
  test::ScopedEnv env("PLANARVO_DEVICE", nullptr);
  const auto devices = ocl::list_devices();
  ASSERT_FALSE(devices.empty());
  const ocl::DeviceInfo& want = devices.back();
  // A middle part of the name, in the other case, must find a device with that name.
  const std::string& name = want.device_name;
  const std::string part = name.substr(name.size() / 4, std::max<size_t>(name.size() / 2, 1));
  std::string flipped = part;
  for (char& c : flipped)
    c = std::isupper(static_cast<unsigned char>(c)) ? static_cast<char>(std::tolower(c))
                                                     : static_cast<char>(std::toupper(c));
  ocl::Runtime rt(test::on_device(flipped));
  EXPECT_THAT(lower(rt.device_info().device_name), HasSubstr(lower(part)));
}

TEST(OclDevices, SelectsPoclByPlatformName) {
  test::ScopedEnv env("PLANARVO_DEVICE", nullptr);
  const auto devices = ocl::list_devices();
  const auto pocl = std::find_if(devices.begin(), devices.end(), [](const ocl::DeviceInfo& d) {
    return lower(d.platform_version).find("pocl") != std::string::npos;
  });
  if (pocl == devices.end()) GTEST_SKIP() << "no PoCL platform on this machine";
  ocl::Runtime rt(test::on_device("PoCL"));
  EXPECT_EQ(rt.device_info().global_index, pocl->global_index);
  ocl::Runtime by_platform(test::on_device(lower(pocl->platform_name)));
  EXPECT_EQ(by_platform.device_info().platform_name, pocl->platform_name);
}

TEST(OclDevices, SelectsByType) {
  test::ScopedEnv env("PLANARVO_DEVICE", nullptr);
  const auto devices = ocl::list_devices();
  ASSERT_FALSE(devices.empty());
  const ocl::DeviceInfo& d = devices.back();
  if (d.type == "OTHER") GTEST_SKIP();
  ocl::Runtime rt(test::on_device(lower(d.type)));
  EXPECT_EQ(rt.device_info().type, d.type);
}

TEST(OclDevices, DefaultPrefersGpuOrAccelerator) {
  test::ScopedEnv env("PLANARVO_DEVICE", nullptr);
  const auto devices = ocl::list_devices();
  ASSERT_FALSE(devices.empty());
  int expected = 0;
  for (const auto& d : devices)
    if (d.type == "GPU" || d.type == "ACCELERATOR") { expected = d.global_index; break; }
  ocl::Runtime rt;
  EXPECT_EQ(rt.device_info().global_index, expected);
}

TEST(OclDevices, SelectsFromTheEnvironment) {
  const auto devices = ocl::list_devices();
  ASSERT_FALSE(devices.empty());
  const std::string last = std::to_string(devices.size() - 1);
  {
    test::ScopedEnv env("PLANARVO_DEVICE", last.c_str());
    ocl::Runtime rt;
    EXPECT_EQ(rt.device_info().global_index, static_cast<int>(devices.size() - 1));
  }
  {
    test::ScopedEnv env("PLANARVO_DEVICE", "no such device anywhere");
    const std::string msg = test::error_message([] { ocl::Runtime rt; }, ErrorCode::NoDevice);
    EXPECT_THAT(msg, HasSubstr("no such device anywhere"));
    EXPECT_THAT(msg, HasSubstr("PLANARVO_DEVICE"));
    // The option wins over the environment.
    ocl::Runtime rt(test::on_device("0"));
    EXPECT_EQ(rt.device_info().global_index, 0);
  }
}

TEST(OclDevices, OutOfRangeIndexIsNoDeviceNamingTheIndex) {
  test::ScopedEnv env("PLANARVO_DEVICE", nullptr);
  const std::string index = std::to_string(ocl::list_devices().size() + 7);
  const std::string msg =
      test::error_message([&] { ocl::Runtime rt(test::on_device(index)); }, ErrorCode::NoDevice);
  EXPECT_THAT(msg, HasSubstr("device index " + index));
}

TEST(OclDevices, NonMatchingNameIsNoDeviceNamingTheSelector) {
  test::ScopedEnv env("PLANARVO_DEVICE", nullptr);
  const std::string msg = test::error_message(
      [] { ocl::Runtime rt(test::on_device("Imaginary Accelerator 9000")); }, ErrorCode::NoDevice);
  EXPECT_THAT(msg, HasSubstr("\"Imaginary Accelerator 9000\""));
}

}  // namespace
}  // namespace planarvo
