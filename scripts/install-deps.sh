#!/usr/bin/env bash
# Installs planarvo's build and test dependencies from Debian 12 packages.
# Idempotent: packages already present are skipped; apt-get runs only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers clinfo
  libeigen3-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-videoio-dev
  libopencv-calib3d-dev libopencv-video-dev
  libsuitesparse-dev
  libzstd-dev liblz4-dev libbz2-dev
  libgtest-dev libgmock-dev
  # The fuzz targets (fuzz/, scripts/fuzz.sh), which the test command builds and runs briefly:
  # clang with libFuzzer and the sanitizers' runtimes.
  clang libclang-rt-dev
  python3 python3-numpy python3-pytest
  # python/tests/test_typing.py: mypy --strict over the examples and the package (issue 25).
  python3-mypy
  # planarvo plot (python/planarvo/plot): the figures and the calibration report.
  python3-matplotlib
  # ROS 1 bag tests: the official writer (brings python3-roslz4) and the message modules
  # (python3-sensor-msgs brings python3-geometry-msgs and python3-std-msgs).
  python3-rosbag python3-sensor-msgs python3-nav-msgs
)
# Benchmark-only peer (issue 3): Ceres Solver. Installed when PLANARVO_BENCH_DEPS=1.
if [ "${PLANARVO_BENCH_DEPS:-0}" = 1 ]; then packages+=(libceres-dev); fi
# planarvo_node (ros/): roscpp and the messages it uses (ROS 1 as Debian packages it); and its
# end-to-end test (test/ros): roscore (python3-roslaunch brings rosmaster and rosout), rosbag play
# and the bag writer, rospy with the message modules the test reads.
packages+=(
  libroscpp-dev libstd-msgs-dev libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libtf2-msgs-dev
  libdiagnostic-msgs-dev python3-diagnostic-msgs
  python3-roslaunch python3-rosbag python3-rospy python3-yaml python3-sensor-msgs python3-nav-msgs python3-tf2-msgs
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi
export DEBIAN_FRONTEND=noninteractive
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
else
  echo "install-deps: installing ${missing[*]}"
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The writer of the MCAP reader's test files (test/tools/mcap: the official @mcap/core writer and
# @foxglove/cdr, pinned in its package-lock.json): `npm ci` when node_modules is missing or older
# than the lock file, with the machine's node and npm; Debian's npm (it brings nodejs) only when
# there is no npm at all. Without them the MCAP file tests skip.
mcap_tools="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/test/tools/mcap"
if ! command -v npm >/dev/null 2>&1; then
  echo "install-deps: installing npm (Debian) for test/tools/mcap"
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends npm
fi
if [ ! -d "$mcap_tools/node_modules" ] || [ "$mcap_tools/package-lock.json" -nt "$mcap_tools/node_modules" ]; then
  echo "install-deps: npm ci in test/tools/mcap"
  (cd "$mcap_tools" && npm ci --no-audit --no-fund --loglevel=error)
  touch "$mcap_tools/node_modules"
else
  echo "install-deps: test/tools/mcap/node_modules up to date"
fi
