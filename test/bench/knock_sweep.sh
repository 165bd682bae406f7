#!/usr/bin/env bash
# Online recalibration (issue 24): the mounting watch over rear cameras on a car that leans in
# turns and pitches over bumps. Part "alarms": 20 drives without a knock (three rear cameras, bumps
# of 3 and 10 degrees, three textures, and two slow drives whose bumps last 2.5 s): every change
# found is a false alarm. Part "knocks": drives knocked at KNOCK_T seconds by 2 degrees of roll, 2 of
# pitch, or 1.5 of both: when the change was found, and the mounting as the drive ended against the
# knocked truth. One row per drive (bench_track accuracy's "mounting:" line).
#   bash test/bench/knock_sweep.sh [BUILD_DIR=build] [SECONDS=20] [PART=all|alarms|knocks] [BENCH=BUILD_DIR/test/bench_track]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
seconds="${2:-20}"
part="${3:-all}"
bench="${4:-$build/test/bench_track}"
row() {  # name, keys...
  local name="$1"
  shift
  "$bench" accuracy seconds="$seconds" plane=1 "$@" 2>&1 | awk -v s="$name" '
    $1 ~ /\.png$/ { printf "| %s | %s | %s / %s / %s | %s | %s | %s / %s | %s |", s, $1, $4, $5, $6, $10, $11, $12, $13, $16 }
    /  mounting:/ { sub(/^  mounting: /, ""); printf " %s |\n", $0 }'
}
poses=("-1.0,0,0.9,0,40,180" "-1.2,0,1.1,0,55,180" "-0.8,0,0.8,0,35,180")
textures=(asphalt_01.png brick_floor.png anti_skid_tiles.png)
car="fov=60 motion=car radius=6 lean=-0.07"
echo "| drive | texture | ok / deg / lost | slope v | slope w | RMS / max mm | drift % | mounting watch |"
echo "|---|---|---|---|---|---|---|---|"
if [ "$part" = all ] || [ "$part" = alarms ]; then
  for pose in "${poses[@]}"; do
    for bumps in 3 10; do
      for tex in "${textures[@]}"; do
        row "rear $pose, bumps $bumps, 3 m/s" ext="$pose" $car speed=3 bumps=$bumps textures=$tex
      done
    done
  done
  for tex in asphalt_02.png brushed_concrete.png; do
    row "rear ${poses[0]}, bumps 10, 1 m/s" ext="${poses[0]}" $car speed=1 bumps=10 textures=$tex
  done
fi
if [ "$part" = all ] || [ "$part" = knocks ]; then
  knock_t="${KNOCK_T:-8}"
  i=0
  for pose in "${poses[@]}"; do
    for knock in "2,0,0" "0,2,0" "-1.5,1.5,0" "0,0,0.01"; do
      tex="${textures[$((i % 3))]}"
      i=$((i + 1))
      row "rear $pose, knock $knock_t:$knock" ext="$pose" $car speed=3 bumps=10 textures=$tex knock="$knock_t:$knock"
    done
  done
fi
