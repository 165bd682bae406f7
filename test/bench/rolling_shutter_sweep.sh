#!/usr/bin/env bash
# Rolling shutters and motion blur (issue 23) over textures, camera poses and motions:
# bench_track accuracy on drives rendered row by row (readout) and integrated over an exposure,
# the tracker told the camera's readout and exposure (the default: each frame undistorted to the
# instantaneous global shutter's image at its stamp) and, for comparison, not told them (unroll=0,
# told_exposure=0: what it did before).
# One table row per drive.
#   bash test/bench/rolling_shutter_sweep.sh [BUILD_DIR=build] [SECONDS=10]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
seconds="${2:-10}"
bench="$build/test/bench_track"
# name | scene keys | textures
scenes=(
  "configuration 1|config=1|asphalt_01.png,brick_floor.png,anti_skid_tiles.png"
  "configuration 2|config=2|asphalt_01.png,brick_floor.png"
  "configuration 3|config=3|asphalt_01.png,brick_floor.png"
  "low rolled, spin|ext=0.25,0.05,0.12,-27,8,0 motion=spin turn=1.0|asphalt_01.png,brick_floor.png"
  "rear 40 deg, car at 3 m/s|ext=-1.0,0,0.9,0,40,180 fov=60 motion=car speed=3 radius=6|asphalt_01.png,brick_floor.png"
)
# name | effect keys | tracker keys
effects=(
  "global shutter||"
  "readout 25 ms, not told|readout=0.025|unroll=0"
  "readout 25 ms|readout=0.025|"
  "exposure 4 ms, not told|exposure=0.004|told_exposure=0"
  "exposure 4 ms|exposure=0.004|"
  "readout 25 ms + exposure 4 ms, exposure not told|readout=0.025 exposure=0.004|told_exposure=0"
  "readout 25 ms + exposure 4 ms|readout=0.025 exposure=0.004|"
)
echo "| scene | effect | texture | ok / deg / lost | slope v | slope w | RMS / max mm | drift % | ms/frame | passes (coarse to fine) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for s in "${scenes[@]}"; do
  IFS='|' read -r sname skeys tex <<< "$s"
  for e in "${effects[@]}"; do
    IFS='|' read -r ename ekeys tkeys <<< "$e"
    # shellcheck disable=SC2086
    "$bench" accuracy seconds="$seconds" textures="$tex" $skeys $ekeys $tkeys 2>&1 |
      awk -v s="$sname" -v l="$ename" '$1 ~ /\.png$/ {
        printf "| %s | %s | %s | %s / %s / %s | %s | %s | %s / %s | %s | %s | %s %s %s %s |\n",
               s, l, $1, $4, $5, $6, $10, $11, $12, $13, $16, $17, $24, $25, $26, $27 }'
  done
done
