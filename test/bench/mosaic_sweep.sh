#!/usr/bin/env bash
# The floor mosaic's match with the ground over other textures, camera poses and motions: per case
# a simulated drive, tracked with the true extrinsics, its 1 mm mosaic from the tracked trajectory,
# and bench_mosaic's NCC against the texture where the YAML places it (and its time, cold kernel
# cache first). Prints one table row per case.
#   bash test/bench/mosaic_sweep.sh [BUILD_DIR=build] [SECONDS=8] [TEXTURES_DIR=../shared/data/textures]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
seconds="${2:-8}"
textures="${3:-$root/../shared/data/textures}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# name | texture | extrinsics (x,y,z m, roll,pitch,yaw deg) | motion
cases=(
  "default camera, mixed|$root/data/textures/asphalt_01.png|0.2441,-0.0185,0.1787,12.4,17.6,-9.2|mixed"
  "straight down, mixed|$textures/brick_floor.png|0.2,0,0.2,0,0,0|mixed"
  "low and tilted (8 cm, pitch 35), car|$textures/blue_floor_tiles_01.png|0.15,0.02,0.08,5,35,3|car"
  "high (40 cm), spin|$textures/skimage_grass.png|0.1,0,0.4,-8,10,90|spin"
  "tilted 30 roll, mixed|$textures/anti_slip_concrete.png|0.25,0.05,0.15,30,5,-20|mixed"
)
echo "| case | texture | frames used | image px | build s (warm) | NCC |"
echo "|---|---|---|---|---|---|"
for c in "${cases[@]}"; do
  IFS='|' read -r name tex ext motion <<< "$c"
  d="$work/drive"
  rm -rf "$d"
  "$build/planarvo" simulate --out "$d" --seconds "$seconds" --seed 5 --texture "$tex" --extrinsics "$ext" \
      --motion "$motion" --quiet > /dev/null
  "$build/planarvo" track "$d" --extrinsics "$d/extrinsics_gt.yaml" -o "$work/traj.txt" --quiet > /dev/null || true
  row="$("$build/test/bench_mosaic" "$d" "$work/traj.txt" "$d/extrinsics_gt.yaml" rounds=1 variants=1 \
         out="$work/bm" | grep '^| 1 mm, auto spacing |')"
  IFS='|' read -r _ _ used px _ _ _ build_s _ ncc _ <<< "$row"
  echo "| $name | $(basename "$tex") | $used | $px | $build_s | $ncc |"
done
