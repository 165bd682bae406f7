#!/usr/bin/env bash
# The whole check (README, Quick start; .ci/run runs it): installs what is missing, builds and
# runs the test suite, then builds it again with clang under AddressSanitizer and
# UndefinedBehaviorSanitizer, with the fuzz targets, and runs it, then runs the threaded tests
# (several trackers in threads, one per camera) under ThreadSanitizer, then runs each fuzz
# target for 10 s. Stops at the first failure; prints each stage's time.
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
  # The sanitizer build is clang's (a second compiler's warnings, too), and it also builds the
  # fuzz targets (PLANARVO_FUZZ: the library's objects instrumented for libFuzzer's coverage as
  # well), so one build serves both stages. It leaves out the benchmarks (test/bench), which
  # the suite does not run.
  stage "build with AddressSanitizer + UndefinedBehaviorSanitizer (clang), and the fuzz targets"
  cmake -S . -B build-asan -G Ninja -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DPLANARVO_WERROR=ON -DPLANARVO_SANITIZE=ON -DPLANARVO_FUZZ=ON -DPLANARVO_BUILD_BENCHMARKS=OFF
  cmake --build build-asan
  stage "test suite under AddressSanitizer + UndefinedBehaviorSanitizer"
  ctest --test-dir build-asan --output-on-failure -j2

  stage "build with ThreadSanitizer (the end-to-end tests)"
  cmake -S . -B build-tsan -G Ninja -DPLANARVO_WERROR=ON -DPLANARVO_TSAN=ON -DPLANARVO_BUILD_BENCHMARKS=OFF
  cmake --build build-tsan --target planarvo_test_threads
  stage "threaded tests under ThreadSanitizer"
  # Trackers in threads, and the mosaic's decoding thread (BadInput builds small mosaics).
  ctest --test-dir build-tsan --output-on-failure -R 'TrackerThreads\.|Mosaic\.BadInput'

  # The fuzz targets (fuzz/README.md), each run briefly on its seed corpus: they cannot rot, and
  # a seed that crashes fails the run. The 10-minute runs are scripts/fuzz.sh -t 600 -j 2.
  stage "fuzz targets: 10 s each"
  bash scripts/fuzz.sh -t 10 -j 2 -b build-asan --no-build
fi
stage "done"
