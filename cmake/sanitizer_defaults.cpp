// The sanitizers' settings, compiled into the test executables and, in sanitizer builds, into the
// planarvo tool (the sanitizer runtimes call these hooks at start-up), so that they hold however
// a program is started: ctest, a test running the tool, a debugger, by hand. The runtimes look
// them up as dynamic symbols (hence default visibility); in a build without sanitizers nothing
// calls them.

// AddressSanitizer keeps its defaults but one: intercept_tls_get_addr=0. GCC 12's runtime (up to
// GCC 13 and LLVM 16) takes a dynamic TLS block that a malloc happens to place at a certain page
// offset for a pre-2.25 glibc header and reads garbage from it, and LeakSanitizer's tracer then
// dies at exit ("Tracer caught signal 11 ... LeakSanitizer has encountered a fatal error",
// google/sanitizers#1322): exit 1 with no leak, at random. It hit the tool run by
// KernelBinaries.TrackAndCalibrateWithoutCompilingMatchRunTimeCompiledKernels in a clean-clone
// CI run. Leak checking itself is unchanged.
extern "C" const char* __asan_default_options();
extern "C" __attribute__((visibility("default"))) const char* __asan_default_options() {
  return "intercept_tls_get_addr=0";
}

// LeakSanitizer keeps its defaults, with one suppression: PoCL keeps
// the LLVM objects with which it compiled kernels (a device's compiler state) to the end of the
// process and never frees them. Only allocations made inside libpocl and libLLVM are suppressed.
extern "C" const char* __lsan_default_suppressions();
extern "C" __attribute__((visibility("default"))) const char* __lsan_default_suppressions() {
  return "leak:libpocl.so\nleak:libLLVM\n";
}

extern "C" const char* __tsan_default_options();
extern "C" __attribute__((visibility("default"))) const char* __tsan_default_options() { return "second_deadlock_stack=1"; }

// ThreadSanitizer suppressions (scripts/test.sh runs the threaded tests under it). Only code
// that ThreadSanitizer cannot see is suppressed, never planarvo's own:
// - GDAL, loaded by OpenCV's imgcodecs when a test reads its textures with cv::imread, takes
//   its own two internal mutexes in both orders on the reading thread while it registers its
//   drivers (CPLAcquireMutex / CPLCreateOrAcquireMutexEx). GDAL is not instrumented and
//   planarvo holds no lock across the call: this lock-order report, only inside libgdal.
extern "C" const char* __tsan_default_suppressions();
extern "C" __attribute__((visibility("default"))) const char* __tsan_default_suppressions() { return "deadlock:libgdal.so\n"; }
