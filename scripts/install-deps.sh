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
  python3 python3-numpy python3-pytest
)
# Benchmark-only peer (issue 3): Ceres Solver. Installed when PLANARVO_BENCH_DEPS=1.
if [ "${PLANARVO_BENCH_DEPS:-0}" = 1 ]; then packages+=(libceres-dev); fi
# planarvo_node (ros/): roscpp and the messages it uses (ROS 1 as Debian packages it); and its
# end-to-end test (test/ros): roscore (python3-roslaunch brings rosmaster and rosout), rosbag play
# and the bag writer, rospy with the message modules the test reads.
packages+=(
  libroscpp-dev libstd-msgs-dev libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libtf2-msgs-dev
  python3-roslaunch python3-rosbag python3-rospy python3-yaml python3-sensor-msgs python3-nav-msgs python3-tf2-msgs
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
