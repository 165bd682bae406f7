#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang + ASan + UBSan) in build-fuzz/ and runs each one, or
# the ones named, for a given time, starting from a copy of its seed corpus (fuzz/seeds/TARGET).
# Prints a table: executions, corpus size and findings (crash, hang, out-of-memory and leak
# artifacts, and sanitizer reports in the log). Exit status 1 when anything was found, or when a
# target was not built or executed nothing (it did not start).
#
#   scripts/fuzz.sh [-t SECONDS] [-j JOBS] [-b BUILD_DIR] [--no-build] [--report] [TARGET...]
#
#   -t SECONDS   time per target (libFuzzer -max_total_time; default 60)
#   -j JOBS      targets run at once (default 1)
#   -b DIR       build directory (default build-fuzz)
#   --no-build   use the targets already built
#   --report     run nothing: print the table of the last runs in BUILD_DIR/fuzz-runs
#   TARGET       camera_yaml extrinsics_yaml frames tum direction motion_pairs g2o capi mcap rosbag1
#                image manifest
#                (default all)
#
# Each run's log, working corpus and artifacts are in BUILD_DIR/fuzz-runs/TARGET/. Needs only
# Debian packages: clang, libclang-rt-dev (libFuzzer), cmake, ninja-build, and the library's own
# dependencies (scripts/install-deps.sh). Runs at nice 19; set FUZZ_NICE to change that.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
all_targets=(camera_yaml extrinsics_yaml frames tum direction motion_pairs g2o capi mcap rosbag1 image manifest)
seconds=60
jobs=1
build="$root/build-fuzz"
do_build=1
do_run=1
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    -t) seconds=$2; shift 2 ;;
    -j) jobs=$2; shift 2 ;;
    -b) build=$(realpath -m "$2"); shift 2 ;;
    --no-build) do_build=0; shift ;;
    --report) do_build=0; do_run=0; shift ;;
    -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) targets+=("${1#fuzz_}"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
for t in "${targets[@]}"; do
  [[ " ${all_targets[*]} " == *" $t "* ]] || { echo "fuzz.sh: no target '$t' (${all_targets[*]})" >&2; exit 2; }
done
[[ "$seconds" =~ ^[0-9]+$ && "$seconds" -gt 0 ]] || { echo "fuzz.sh: -t needs a positive number of seconds" >&2; exit 2; }
[[ "$jobs" =~ ^[0-9]+$ && "$jobs" -gt 0 ]] || { echo "fuzz.sh: -j needs a positive number" >&2; exit 2; }

if [ "$do_build" = 1 ]; then
  cc=$(command -v clang || command -v clang-14 || true)
  cxx=$(command -v clang++ || command -v clang++-14 || true)
  [ -n "$cc" ] && [ -n "$cxx" ] || { echo "fuzz.sh: clang not found (apt-get install clang libclang-rt-dev)" >&2; exit 2; }
  launcher=()
  if command -v ccache >/dev/null; then
    launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  fi
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" "${launcher[@]}" \
    -DPLANARVO_FUZZ=ON -DPLANARVO_WERROR=ON -DPLANARVO_BUILD_TESTS=OFF -DPLANARVO_BUILD_BENCHMARKS=OFF >/dev/null
  nice -n 10 cmake --build "$build" --target planarvo_fuzz -j "$(nproc)"
fi

dict_for() {
  case "$1" in
    camera_yaml|extrinsics_yaml) echo "$root/fuzz/dict/yaml.dict" ;;
    capi) echo "" ;;
    mcap) echo "$root/fuzz/dict/mcap.dict" ;;
    rosbag1) echo "$root/fuzz/dict/rosbag1.dict" ;;
    image) echo "$root/fuzz/dict/image.dict" ;;
    *) echo "$root/fuzz/dict/text.dict" ;;
  esac
}

run_one() {
  local t=$1 dir="$build/fuzz-runs/$1"
  rm -rf "$dir"
  if [ ! -x "$build/fuzz/fuzz_$t" ]; then
    mkdir -p "$dir"
    echo "not built: $build/fuzz/fuzz_$t" >"$dir/missing"
    return
  fi
  mkdir -p "$dir/corpus" "$dir/artifacts" "$dir/tmp"
  cp "$root/fuzz/seeds/$t/"* "$dir/corpus/"
  local dict args=()
  dict=$(dict_for "$t")
  [ -n "$dict" ] && args+=("-dict=$dict")
  local start end
  start=$(date +%s)
  # -timeout: an input running over 10 s is a hang; -rss_limit_mb: over 2 GB is a finding.
  # TMPDIR: where the targets write the inputs of readers that take a path.
  TMPDIR="$dir/tmp" PLANARVO_CACHE_DIR="$build/fuzz-kernel-cache" \
    nice -n "${FUZZ_NICE:-19}" "$build/fuzz/fuzz_$t" "${args[@]}" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$dir/artifacts/" "$dir/corpus" >"$dir/log.txt" 2>&1 || true
  end=$(date +%s)
  echo $((end - start)) >"$dir/seconds"
}

running=0
for t in "${targets[@]}"; do
  [ "$do_run" = 1 ] || break
  echo "fuzz.sh: fuzz_$t for ${seconds} s" >&2
  run_one "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait

found=0
printf '%-16s %8s %12s %9s %7s %7s %6s %5s %5s %10s\n' \
  target seconds executions exec/s corpus crashes hangs ooms leaks sanitizer
for t in "${targets[@]}"; do
  dir="$build/fuzz-runs/$t"
  if [ -f "$dir/missing" ]; then
    printf '%-16s NOT BUILT (%s)\n' "$t" "$build/fuzz/fuzz_$t"
    found=1
    continue
  fi
  [ -f "$dir/seconds" ] || { printf '%-16s (not run)\n' "$t"; found=1; continue; }
  secs=$(cat "$dir/seconds")
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/log.txt" | tail -1)
  # A run that died without libFuzzer's final statistics: its last status line "#N ...".
  [ -n "$execs" ] || execs=$(sed -n 's/^#\([0-9][0-9]*\)[[:space:]].*/\1/p' "$dir/log.txt" | tail -1)
  execs=${execs:-0}
  rate=$(( secs > 0 ? execs / secs : 0 ))
  corpus=$(find "$dir/corpus" -type f | wc -l)
  crashes=$(find "$dir/artifacts" -name 'crash-*' -o -name 'deadly-*' | wc -l)
  hangs=$(find "$dir/artifacts" -name 'timeout-*' | wc -l)
  ooms=$(find "$dir/artifacts" -name 'oom-*' | wc -l)
  leaks=$(find "$dir/artifacts" -name 'leak-*' | wc -l)
  reports=$(grep -c -E 'ERROR: (Address|Leak|Undefined)Sanitizer|runtime error:|broken promise' "$dir/log.txt" || true)
  printf '%-16s %8s %12s %9s %7s %7s %6s %5s %5s %10s\n' \
    "$t" "$secs" "$execs" "$rate" "$corpus" "$crashes" "$hangs" "$ooms" "$leaks" "$reports"
  # A target that ran nothing (it did not start, or died before its first input) found nothing
  # only because it never looked.
  if [ "$execs" -eq 0 ]; then
    found=1
    echo "  -> $t executed nothing: $dir/log.txt" >&2
  elif [ $((crashes + hangs + ooms + leaks + reports)) -gt 0 ]; then
    found=1
    echo "  -> $dir/log.txt, $dir/artifacts/" >&2
  fi
done
exit $found
