// kernels/ocl/fill.cl against its C++ reference: every element of [0, n) written with the value,
// nothing beyond n touched, for sizes that are not multiples of the work-group size.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "ocl/runtime.h"

namespace planarvo {
namespace {

// The C++ reference of fill_float.
std::vector<float> fill_reference(float value, int n) {
  return std::vector<float>(static_cast<size_t>(n), value);
}

uint32_t bits_of(float v) {
  uint32_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// A NaN whose payload the kernel cannot produce: an element still holding it was not written.
float poison() {
  const uint32_t b = 0x7fc0dead;
  float v;
  std::memcpy(&v, &b, sizeof v);
  return v;
}

class FillKernel : public ::testing::Test {
 protected:
  // Runs fill_float on n elements of a poisoned buffer with `guard` extra elements after them.
  std::vector<float> run(float value, int n, size_t work_group, int guard = 37) {
    std::vector<float> host(static_cast<size_t>(n + guard), poison());
    cl::Buffer buf(rt_.context(), CL_MEM_READ_WRITE, host.size() * sizeof(float));
    rt_.queue().enqueueWriteBuffer(buf, CL_TRUE, 0, host.size() * sizeof(float), host.data());
    cl::Kernel k(rt_.program("fill"), "fill_float");
    k.setArg(0, buf);
    k.setArg(1, value);
    k.setArg(2, n);
    const size_t wg = std::min(
        work_group, k.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(rt_.device()));
    const size_t global = (static_cast<size_t>(n) + wg - 1) / wg * wg;  // round up
    rt_.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global), cl::NDRange(wg));
    rt_.queue().enqueueReadBuffer(buf, CL_TRUE, 0, host.size() * sizeof(float), host.data());
    return host;
  }

  ocl::Runtime rt_;
};

TEST_F(FillKernel, MatchesReferenceAndWritesNothingBeyondN) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<float> values(-1e6f, 1e6f);
  for (const int n : {1, 63, 64, 65, 1000, 4099}) {
    for (const size_t wg : {size_t{1}, size_t{16}, size_t{64}}) {
      SCOPED_TRACE("n = " + std::to_string(n) + ", work-group " + std::to_string(wg));
      const float value = values(rng);
      const std::vector<float> out = run(value, n, wg);
      const std::vector<float> ref = fill_reference(value, n);
      int mismatches = 0;
      for (int i = 0; i < n; ++i)
        mismatches += bits_of(out[static_cast<size_t>(i)]) != bits_of(ref[static_cast<size_t>(i)]);
      EXPECT_EQ(mismatches, 0);
      int touched = 0;
      for (size_t i = static_cast<size_t>(n); i < out.size(); ++i)
        touched += bits_of(out[i]) != bits_of(poison());
      EXPECT_EQ(touched, 0) << "elements beyond n were written";
    }
  }
}

TEST_F(FillKernel, SpecialValuesArePreservedBitForBit) {
  for (const float value : {0.0f, -0.0f, 1e-40f /* denormal */, -3.5f}) {
    const std::vector<float> out = run(value, 100, 32);
    for (int i = 0; i < 100; ++i)
      ASSERT_EQ(bits_of(out[static_cast<size_t>(i)]), bits_of(value)) << "element " << i;
  }
}

}  // namespace
}  // namespace planarvo
