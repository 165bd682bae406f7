#!/usr/bin/env bash
# The whole check (README, Quick start; .ci/run runs it): installs what is missing, builds and
# runs the test suite, then builds and runs it again under AddressSanitizer and
# UndefinedBehaviorSanitizer, then runs the threaded tests (several trackers in threads, one per
# camera) under ThreadSanitizer, then builds the fuzz targets and runs each for 10 s. Stops at the
# first failure; prints each stage's time.
#   PLANARVO_SANITIZERS=0 bash scripts/test.sh   the plain suite only
set -euo pipefail
cd "$(dirname "$0")/.."

started=$SECONDS
stage() {
  echo
  echo "== $1 ($(( (SECONDS - started) / 60 )) min $(( (SECONDS - started) % 60 )) s so far)"
}

stage "dependencies"
bash scripts/install-deps.sh

stage "build"
cmake -S . -B build -G Ninja -DPLANARVO_WERROR=ON
cmake --build build
stage "test suite"
ctest --test-dir build --output-on-failure -j2

if [ "${PLANARVO_SANITIZERS:-1}" != 0 ]; then
  # The sanitizer builds leave out the benchmarks (test/bench), which the suite does not run.
  stage "build with AddressSanitizer + UndefinedBehaviorSanitizer"
  cmake -S . -B build-asan -G Ninja -DPLANARVO_WERROR=ON -DPLANARVO_SANITIZE=ON -DPLANARVO_BUILD_BENCHMARKS=OFF
  cmake --build build-asan
  stage "test suite under AddressSanitizer + UndefinedBehaviorSanitizer"
  ctest --test-dir build-asan --output-on-failure -j2

  stage "build with ThreadSanitizer (the end-to-end tests)"
  cmake -S . -B build-tsan -G Ninja -DPLANARVO_WERROR=ON -DPLANARVO_TSAN=ON -DPLANARVO_BUILD_BENCHMARKS=OFF
  cmake --build build-tsan --target planarvo_test_threads
  stage "threaded tests under ThreadSanitizer"
  # Trackers in threads, and the mosaic's decoding thread (BadInput builds small mosaics).
  ctest --test-dir build-tsan --output-on-failure -R 'TrackerThreads\.|Mosaic\.BadInput'

  # The fuzz targets (fuzz/README.md) built with clang, ASan and UBSan, and each run briefly on its
  # seed corpus: they cannot rot, and a seed that crashes fails the run. The 10-minute runs are
  # scripts/fuzz.sh -t 600 -j 2.
  stage "fuzz targets: build (clang, AddressSanitizer + UndefinedBehaviorSanitizer) and 10 s each"
  bash scripts/fuzz.sh -t 10 -j 2
fi
stage "done"
