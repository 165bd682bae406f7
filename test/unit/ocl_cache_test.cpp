// The on-disk program cache (src/ocl/program_cache.h): hits, misses, corrupt and stale entries,
// unwritable directories, and where it lives by default (src/ocl/cache_dirs.h). Each test names its own cache directory instead of the
// PLANARVO_CACHE_DIR that CTest sets.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include <unistd.h>

#include "core/error.h"
#include "ocl/cache_dirs.h"
#include "ocl/program_cache.h"
#include "ocl/runtime.h"
#include "common/test_util.h"
#include "unit/ocl_test_helpers.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

ocl::RuntimeOptions cached_in(const fs::path& dir) {
  ocl::RuntimeOptions o;
  o.cache_dir = dir.string();
  return o;
}

std::set<fs::path> entries(const fs::path& dir) {
  std::set<fs::path> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".clbin") out.insert(e.path());
  return out;
}

std::vector<char> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& p, const std::vector<char>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Builds fill in a fresh Runtime on dir, checks that it runs, and returns where it came from.
ocl::ProgramStats fill_once(const fs::path& dir, const std::string& options = "") {
  ocl::Runtime rt(cached_in(dir));
  test::expect_fill_works(rt, rt.program("fill", options));
  return rt.stats();
}

// A cache with one entry for fill; returns the entry.
fs::path prime(const fs::path& dir) {
  const ocl::ProgramStats first = fill_once(dir);
  EXPECT_EQ(first.built_from_source, 1);
  EXPECT_EQ(first.loaded_from_cache, 0);
  EXPECT_EQ(first.cache_write_failures, 0);
  const auto files = entries(dir);
  EXPECT_EQ(files.size(), 1u);
  return files.empty() ? fs::path() : *files.begin();
}

TEST(OclCache, SecondRuntimeLoadsFromTheCache) {
  test::ScratchDir scratch;
  const fs::path dir = scratch / "cache";
  prime(dir);
  const ocl::ProgramStats second = fill_once(dir);
  EXPECT_EQ(second.loaded_from_cache, 1);
  EXPECT_EQ(second.built_from_source, 0);
  EXPECT_EQ(second.cache_rejected, 0);
  // Nothing left behind by the atomic write.
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(e.path().extension(), ".clbin") << e.path();
  }
  EXPECT_EQ(files, 1u);
}

TEST(OclCache, TruncatedEntryIsAMissAndIsRewritten) {
  test::ScratchDir scratch;
  const fs::path dir = scratch / "cache";
  const fs::path entry = prime(dir);
  std::vector<char> bytes = read_bytes(entry);
  const size_t full = bytes.size();
  bytes.resize(full * 2 / 3);
  write_bytes(entry, bytes);

  const ocl::ProgramStats s = fill_once(dir);
  EXPECT_EQ(s.cache_rejected, 1);
  EXPECT_EQ(s.built_from_source, 1);
  EXPECT_EQ(s.loaded_from_cache, 0);
  EXPECT_EQ(read_bytes(entry).size(), full);  // overwritten with a good entry
  EXPECT_EQ(fill_once(dir).loaded_from_cache, 1);
}

TEST(OclCache, OverwrittenBinaryBytesAreAMiss) {
  test::ScratchDir scratch;
  const fs::path dir = scratch / "cache";
  const fs::path entry = prime(dir);
  std::vector<char> bytes = read_bytes(entry);
  ASSERT_GT(bytes.size(), 600u);
  for (size_t i = bytes.size() - 512; i < bytes.size() - 256; ++i) bytes[i] = '\x5a';
  write_bytes(entry, bytes);

  const ocl::ProgramStats s = fill_once(dir);
  EXPECT_EQ(s.cache_rejected, 1);
  EXPECT_EQ(s.built_from_source, 1);
  EXPECT_EQ(fill_once(dir).loaded_from_cache, 1);
}

TEST(OclCache, GarbageAndEmptyEntriesAreMisses) {
  test::ScratchDir scratch;
  const fs::path dir = scratch / "cache";
  const fs::path entry = prime(dir);
  write_bytes(entry, std::vector<char>(4096, '\x7f'));
  EXPECT_EQ(fill_once(dir).cache_rejected, 1);
  write_bytes(entry, {});
  EXPECT_EQ(fill_once(dir).cache_rejected, 1);
  EXPECT_EQ(fill_once(dir).loaded_from_cache, 1);
}

TEST(OclCache, DifferentOptionsHaveDifferentEntries) {
  test::ScratchDir scratch;
  const fs::path dir = scratch / "cache";
  EXPECT_EQ(fill_once(dir, "-D VARIANT=1").built_from_source, 1);
  EXPECT_EQ(fill_once(dir, "-D VARIANT=2").built_from_source, 1);
  EXPECT_EQ(entries(dir).size(), 2u);
  ocl::Runtime rt(cached_in(dir));
  rt.program("fill", "-D VARIANT=1");
  rt.program("fill", "-D  VARIANT=2 ");  // the same options, spelt differently
  EXPECT_EQ(rt.stats().loaded_from_cache, 2);
  EXPECT_EQ(rt.stats().built_from_source, 0);
}

TEST(OclCache, AnEntryUnderAnotherKeyIsAMiss) {
  // The entry of one option set copied over another's: the header's key gives it away.
  test::ScratchDir scratch;
  const fs::path dir = scratch / "cache";
  fill_once(dir, "-D VARIANT=1");
  const auto one = entries(dir);
  fill_once(dir, "-D VARIANT=2");
  auto two = entries(dir);
  ASSERT_EQ(one.size(), 1u);
  ASSERT_EQ(two.size(), 2u);
  two.erase(*one.begin());
  fs::copy_file(*one.begin(), *two.begin(), fs::copy_options::overwrite_existing);

  const ocl::ProgramStats s = fill_once(dir, "-D VARIANT=2");
  EXPECT_EQ(s.cache_rejected, 1);
  EXPECT_EQ(s.built_from_source, 1);
  EXPECT_EQ(fill_once(dir, "-D VARIANT=1").loaded_from_cache, 1);
}

TEST(OclCache, UncreatableDirectoryStillBuilds) {
  test::ScratchDir scratch;
  const fs::path file = scratch / "a-regular-file";
  write_bytes(file, {'x'});
  const fs::path dir = file / "cache";  // a directory under a regular file cannot exist
  for (int i = 0; i < 2; ++i) {
    const ocl::ProgramStats s = fill_once(dir);
    EXPECT_EQ(s.built_from_source, 1);
    EXPECT_EQ(s.cache_write_failures, 1);
  }
}

TEST(OclCache, DisabledCacheWritesNothing) {
  test::ScratchDir scratch;
  ocl::RuntimeOptions o = cached_in(scratch / "cache");
  o.use_cache = false;
  ocl::Runtime rt(o);
  EXPECT_EQ(rt.cache_dir(), "");
  test::expect_fill_works(rt, rt.program("fill"));
  EXPECT_EQ(rt.stats().built_from_source, 1);
  EXPECT_FALSE(fs::exists(scratch / "cache"));
}

TEST(OclCache, DirectoryComesFromOptionsThenEnvironment) {
  test::ScratchDir scratch;
  const std::string from_env = (scratch / "env").string();
  test::ScopedEnv env("PLANARVO_CACHE_DIR", from_env.c_str());
  EXPECT_EQ(ocl::Runtime().cache_dir(), from_env);
  EXPECT_EQ(ocl::Runtime(cached_in(scratch / "opt")).cache_dir(), (scratch / "opt").string());
  {
    // Nothing chosen: none on a driver that caches compiled kernels itself (PoCL), else the
    // user's cache directory.
    test::ScopedEnv no_env("PLANARVO_CACHE_DIR", nullptr);
    test::ScopedEnv xdg("XDG_CACHE_HOME", (scratch / "xdg").string().c_str());
    const bool own = ocl::detail::driver_caches_kernels(ocl::Runtime().device_info().platform_name);
    EXPECT_EQ(ocl::Runtime().cache_dir(), own ? "" : (scratch / "xdg" / "planarvo").string());
    test::ScopedEnv no_xdg("XDG_CACHE_HOME", nullptr);
    test::ScopedEnv home("HOME", (scratch / "home").string().c_str());
    EXPECT_EQ(ocl::Runtime().cache_dir(), own ? "" : (scratch / "home" / ".cache" / "planarvo").string());
    // A chosen directory is used whatever the driver.
    EXPECT_EQ(ocl::Runtime(cached_in(scratch / "opt")).cache_dir(), (scratch / "opt").string());
  }
}

// Which drivers cache compiled kernels themselves: PoCL, unless POCL_KERNEL_CACHE=0 turns its
// cache off (then the engine's is the only one).
TEST(OclCache, PoclKeepsItsOwnKernelCache) {
  ocl::Runtime first;  // the driver initialised before POCL_KERNEL_CACHE changes (PoCL reads it then)
  test::ScopedEnv on("POCL_KERNEL_CACHE", nullptr);
  EXPECT_TRUE(ocl::detail::driver_caches_kernels("Portable Computing Language"));
  EXPECT_FALSE(ocl::detail::driver_caches_kernels("NVIDIA CUDA"));
  EXPECT_FALSE(ocl::detail::driver_caches_kernels("Intel(R) OpenCL"));
  test::ScopedEnv off("POCL_KERNEL_CACHE", "0");
  EXPECT_FALSE(ocl::detail::driver_caches_kernels("Portable Computing Language"));
  test::ScopedEnv no_env("PLANARVO_CACHE_DIR", nullptr);
  test::ScratchDir scratch;
  test::ScopedEnv xdg("XDG_CACHE_HOME", scratch.path().string().c_str());
  EXPECT_EQ(ocl::Runtime().cache_dir(), (scratch / "planarvo").string());
}

TEST(OclCache, CacheDirUsableWhenItIsOrCanBeAWritableDirectory) {
  test::ScratchDir scratch;
  std::ofstream(scratch / "file") << "x";
  EXPECT_TRUE(ocl::detail::cache_dir_usable(scratch.path()));
  EXPECT_TRUE(ocl::detail::cache_dir_usable(scratch / "missing" / "deeper"));
  EXPECT_FALSE(ocl::detail::cache_dir_usable(scratch / "file"));
  EXPECT_FALSE(ocl::detail::cache_dir_usable(scratch / "file" / ".cache" / "planarvo"));
  EXPECT_FALSE(ocl::detail::cache_dir_usable(""));
  EXPECT_FALSE(fs::exists(scratch / "missing"));  // asking creates nothing
}

// A service user with no home, or a home it cannot write, caches in <temp>/planarvo-<uid>, a
// directory only it can enter; with no usable temp directory either, nothing is cached.
TEST(OclCache, DefaultWithoutAHomeIsAPrivateTempDirectory) {
  test::ScratchDir scratch;
  fs::create_directories(scratch / "tmp");
  std::ofstream(scratch / "file") << "x";
  test::ScopedEnv no_env("PLANARVO_CACHE_DIR", nullptr);
  test::ScopedEnv no_xdg("XDG_CACHE_HOME", nullptr);
  test::ScopedEnv tmp("TMPDIR", (scratch / "tmp").c_str());
  const fs::path private_dir = scratch / "tmp" / ("planarvo-" + std::to_string(::geteuid()));
  const std::string in_temp = (private_dir / "programs").string();
  {
    test::ScopedEnv no_home("HOME", nullptr);
    EXPECT_EQ(ocl::detail::resolve_cache_dir({}), in_temp);
    EXPECT_EQ(fs::symlink_status(private_dir).permissions(), fs::perms::owner_all);
    ocl::RuntimeOptions off;
    off.use_cache = false;
    EXPECT_EQ(ocl::detail::resolve_cache_dir(off), "");
  }
  {
    test::ScopedEnv home("HOME", (scratch / "file").c_str());  // cannot hold a .cache
    EXPECT_EQ(ocl::detail::resolve_cache_dir({}), in_temp);
  }
  {
    test::ScopedEnv xdg("XDG_CACHE_HOME", (scratch / "file").c_str());
    EXPECT_EQ(ocl::detail::resolve_cache_dir({}), in_temp);
  }
  {
    test::ScopedEnv home("HOME", (scratch / "home").c_str());  // missing, but can be made
    EXPECT_EQ(ocl::detail::resolve_cache_dir({}), (scratch / "home" / ".cache" / "planarvo").string());
  }
  {
    test::ScopedEnv no_home("HOME", nullptr);
    test::ScopedEnv bad_tmp("TMPDIR", (scratch / "file").c_str());
    EXPECT_EQ(ocl::detail::resolve_cache_dir({}), "");
  }
}

// Another user could plant binaries in a directory it can write: such a directory, or a
// symlink in its place, is refused.
TEST(OclCache, PrivateTempDirectoryIsRefusedWhenOthersCanWriteIt) {
  test::ScratchDir scratch;
  fs::create_directories(scratch / "tmp");
  test::ScopedEnv tmp("TMPDIR", (scratch / "tmp").c_str());
  const fs::path private_dir = scratch / "tmp" / ("planarvo-" + std::to_string(::geteuid()));
  fs::create_directories(private_dir);
  fs::permissions(private_dir, fs::perms::all);
  EXPECT_EQ(ocl::detail::private_temp_dir(), fs::path());
  fs::permissions(private_dir, fs::perms::owner_all | fs::perms::group_read |
                                   fs::perms::group_exec | fs::perms::others_read |
                                   fs::perms::others_exec);
  EXPECT_EQ(ocl::detail::private_temp_dir(), private_dir);
  fs::remove(private_dir);
  fs::create_directories(scratch / "elsewhere");
  fs::permissions(scratch / "elsewhere", fs::perms::owner_all);
  fs::create_directory_symlink(scratch / "elsewhere", private_dir);
  EXPECT_EQ(ocl::detail::private_temp_dir(), fs::path());
}

}  // namespace
}  // namespace planarvo
