// Building programs from the embedded sources: options, the common prelude, build logs,
// memoisation (src/ocl/runtime.h).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <thread>

#include "core/error.h"
#include "ocl/embedded.h"
#include "ocl/runtime.h"
#include "unit/ocl_test_helpers.h"

namespace planarvo {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

ocl::RuntimeOptions no_cache() {
  ocl::RuntimeOptions o;
  o.use_cache = false;
  return o;
}

bool embeds(const std::string& name) {
  for (const ocl::EmbeddedSource* s = ocl::embedded_sources(); s->name; ++s)
    if (name == s->name) return true;
  return false;
}

// The build log of source, built on rt's device; "" when it builds.
std::string build_log(ocl::Runtime& rt, const std::string& source) {
  cl::Program p(rt.context(), source);
  try {
    p.build(std::vector<cl::Device>{rt.device()}, "");
  } catch (const cl::Error&) {
    return p.getBuildInfo<CL_PROGRAM_BUILD_LOG>(rt.device()) + " ";
  }
  return {};
}

TEST(OclBuild, FailedBuildCarriesTheLogProgramDeviceAndOptions) {
  ocl::Runtime rt(no_cache());
  const std::string msg = test::error_message(
      [&] { rt.program("fill", "-D PLANARVO_TEST_BUILD_ERROR"); }, ErrorCode::OpenCL);
  EXPECT_THAT(msg, HasSubstr("planarvo test: requested build failure"));  // the build log
  EXPECT_THAT(msg, HasSubstr("fill.cl:"));  // which points into the kernel's own file
  EXPECT_THAT(msg, HasSubstr("\"fill\""));
  EXPECT_THAT(msg, HasSubstr(rt.device_info().device_name));
  EXPECT_THAT(msg, HasSubstr("-D PLANARVO_TEST_BUILD_ERROR"));
  // A failure is not memoised: the good variant still builds.
  EXPECT_NO_THROW(rt.program("fill"));
}

TEST(OclBuild, AddsClStd12WhereTheDeviceSpeaksIt) {
  ocl::Runtime rt(no_cache());
  const std::string& c = rt.device_info().opencl_c_version;
  const bool at_least_12 = c.find("OpenCL C 1.0") == std::string::npos &&
                           c.find("OpenCL C 1.1") == std::string::npos;
  if (at_least_12) {
    EXPECT_EQ(rt.effective_build_options(""), "-cl-std=CL1.2");
    EXPECT_EQ(rt.effective_build_options(" -D A=1 "), "-cl-std=CL1.2 -D A=1");
    // It reaches the compiler: the failed build reports what it was built with.
    const std::string msg = test::error_message(
        [&] { rt.program("fill", "-D PLANARVO_TEST_BUILD_ERROR"); }, ErrorCode::OpenCL);
    EXPECT_THAT(msg, HasSubstr("-cl-std=CL1.2"));
  } else {
    EXPECT_EQ(rt.effective_build_options(""), "");
  }
  // A caller's own -cl-std is left alone.
  EXPECT_EQ(rt.effective_build_options("-cl-std=CL1.1"), "-cl-std=CL1.1");
}

TEST(OclBuild, NormalisesOptions) {
  EXPECT_EQ(ocl::normalize_build_options(""), "");
  EXPECT_EQ(ocl::normalize_build_options(" \t\n "), "");
  EXPECT_EQ(ocl::normalize_build_options("  -D A=1 \t  -D   B=2\n"), "-D A=1 -D B=2");
  // Inside double quotes whitespace is part of the value.
  EXPECT_EQ(ocl::normalize_build_options("-D S=\"a   b\"   -w"), "-D S=\"a   b\" -w");
  EXPECT_EQ(ocl::normalize_build_options("-D Q=\\\"  x"), "-D Q=\\\" x");
}

TEST(OclBuild, MemoisesPerProgramAndNormalisedOptions) {
  ocl::Runtime rt(no_cache());
  cl::Program& a = rt.program("fill");
  cl::Program& b = rt.program("fill", "   ");
  EXPECT_EQ(&a, &b);
  EXPECT_EQ(a(), b());
  cl::Program& c = rt.program("fill", "-D VARIANT=1");
  EXPECT_NE(a(), c());
  EXPECT_EQ(&c, &rt.program("fill", " -D  VARIANT=1"));
  EXPECT_EQ(rt.stats().built_from_source, 2);
  test::expect_fill_works(rt, a);
  test::expect_fill_works(rt, c);
}

TEST(OclBuild, ProgramIsSafeToCallFromSeveralThreads) {
  ocl::Runtime rt(no_cache());
  std::vector<cl_program> got(8, nullptr);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < got.size(); ++t)
    threads.emplace_back(
        [&, t] { got[t] = rt.program("fill", "-D T=" + std::to_string(t % 2))(); });
  for (auto& t : threads) t.join();
  for (size_t t = 0; t < got.size(); ++t) {
    EXPECT_NE(got[t], nullptr);
    EXPECT_EQ(got[t], got[t % 2]);
  }
  EXPECT_EQ(rt.stats().built_from_source, 2);
}

TEST(OclBuild, UnknownProgramIsAnErrorNamingIt) {
  ocl::Runtime rt(no_cache());
  const std::string msg =
      test::error_message([&] { rt.program("no_such_program"); }, ErrorCode::Internal);
  EXPECT_THAT(msg, HasSubstr("no_such_program"));
}

TEST(OclBuild, ThePreludeIsNotAProgram) {
  ocl::Runtime rt(no_cache());
  const std::string msg = test::error_message([&] { rt.program("common"); },
                                              ErrorCode::InvalidArgument);
  EXPECT_THAT(msg, HasSubstr("prelude"));
}

TEST(OclBuild, ProgramSourceStartsWithThePreludeWhenThereIsOne) {
  const std::string fill = ocl::program_source("fill");
  EXPECT_THAT(fill, HasSubstr("__kernel void fill_float"));
  if (embeds("common")) {
    EXPECT_THAT(fill, StartsWith("#line 1 \"common.cl\"\n"));
    EXPECT_THAT(fill, HasSubstr("\n#line 1 \"fill.cl\"\n"));
  } else {
    EXPECT_THAT(fill, StartsWith("#line 1 \"fill.cl\"\n// Fills a buffer"));
  }
}

TEST(OclBuild, ComposedSourceBuildsAndPointsMessagesAtTheRightFileAndLine) {
  ocl::Runtime rt(no_cache());
  const std::string prelude = "// helpers\ninline float twice(float x) { return 2.0f * x; }";
  const std::string uses =
      "__kernel void k(__global float* p) { p[get_global_id(0)] = twice(1.0f); }\n";
  EXPECT_EQ(build_log(rt, ocl::compose_program_source(prelude, "stage", uses)), "");
  // Without the prelude the helper is unknown: composition is what makes it visible.
  EXPECT_NE(build_log(rt, ocl::compose_program_source("", "stage", uses)), "");

  const std::string bad_stage = "// one\n// two\n#error \"stage line three\"\n";
  EXPECT_THAT(build_log(rt, ocl::compose_program_source(prelude, "stage", bad_stage)),
              HasSubstr("stage.cl:3"));
  const std::string bad_prelude = "// one\n#error \"prelude line two\"\n";
  EXPECT_THAT(build_log(rt, ocl::compose_program_source(bad_prelude, "stage", uses)),
              HasSubstr("common.cl:2"));
}

TEST(OclBuild, RegistryKeepsEachNormalisedOptionSetOnce) {
  ocl::Runtime::register_build_options("registry_test_program", "-D A=1");
  ocl::Runtime::register_build_options("registry_test_program", "  -D   A=1 ");
  ocl::Runtime::register_build_options("registry_test_program", "");
  EXPECT_EQ(ocl::Runtime::registered_build_options("registry_test_program"),
            (std::vector<std::string>{"", "-D A=1"}));
  EXPECT_TRUE(ocl::Runtime::registered_build_options("never_registered").empty());
}

}  // namespace
}  // namespace planarvo
