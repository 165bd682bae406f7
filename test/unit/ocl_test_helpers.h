// Helpers for the src/ocl tests: scoped environment variables, and a check that a built
// "fill" program really runs.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "ocl/runtime.h"

namespace planarvo::test {

// Sets (or, with nullptr, unsets) an environment variable for its lifetime, then restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = std::string(old);
    if (value)
      setenv(name, value, 1);
    else
      unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_.c_str(), old_->c_str(), 1);
    else
      unsetenv(name_.c_str());
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_;
  std::optional<std::string> old_;
};

// Runs f, which must throw planarvo::Error with the given code; returns the message.
template <class F>
std::string error_message(F&& f, ErrorCode code) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(static_cast<int>(e.code()), static_cast<int>(code)) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "expected planarvo::Error";
  return {};
}

inline ocl::RuntimeOptions on_device(const std::string& device) {
  ocl::RuntimeOptions o;
  o.device = device;
  return o;
}

// A NaN with a payload no kernel produces, so "left untouched" is a bitwise test.
inline constexpr uint32_t kPoisonBits = 0x7fc0dead;

inline bool is_poison(float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits == kPoisonBits;
}

inline float poison() {
  float v;
  std::memcpy(&v, &kPoisonBits, sizeof v);
  return v;
}

// Runs fill_float from program over n elements of a poisoned buffer with `guard` extra
// elements and returns all n + guard of them.
inline std::vector<float> run_fill(ocl::Runtime& rt, cl::Program& program, float value, int n,
                                   int guard = 16, size_t work_group = 64) {
  std::vector<float> host(static_cast<size_t>(n + guard), poison());
  cl::Buffer buf(rt.context(), CL_MEM_READ_WRITE, host.size() * sizeof(float));
  rt.queue().enqueueWriteBuffer(buf, CL_TRUE, 0, host.size() * sizeof(float), host.data());
  cl::Kernel k(program, "fill_float");
  k.setArg(0, buf);
  k.setArg(1, value);
  k.setArg(2, n);
  const size_t wg = std::min(work_group, rt.device_info().max_work_group_size);
  const size_t global = (static_cast<size_t>(n) + wg - 1) / wg * wg;  // no uneven work-groups
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global), cl::NDRange(wg));
  rt.queue().enqueueReadBuffer(buf, CL_TRUE, 0, host.size() * sizeof(float), host.data());
  return host;
}

// fill_float writes value to exactly the first n elements.
inline void expect_fill_works(ocl::Runtime& rt, cl::Program& program) {
  const int n = 1000;  // not a multiple of the work-group size
  const float value = 2.5f;
  const std::vector<float> out = run_fill(rt, program, value, n);
  int wrong = 0;
  for (int i = 0; i < n; ++i) wrong += out[static_cast<size_t>(i)] != value;
  EXPECT_EQ(wrong, 0) << "elements of [0, n) not filled";
  for (size_t i = static_cast<size_t>(n); i < out.size(); ++i)
    EXPECT_TRUE(is_poison(out[i])) << "element " << i << " beyond n was written";
}

}  // namespace planarvo::test
