#!/usr/bin/env bash
# The local plane (issue 24, the paper's section 6.4) over rear cameras, textures and bumps:
# bench_track accuracy on a car at up to 3 m/s whose body rolls -0.07 deg per deg/s of yaw rate and
# pitches over a bump every 10 m, tracked with the mounting held fixed (plane=0) and with the local
# plane (plane=1); then the rigid robot cameras (configurations 1-3) both ways. One row per drive.
#   bash test/bench/local_plane_sweep.sh [BUILD_DIR=build] [SECONDS=20] [PART=all|rear1|rear2|rear3|rigid]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
seconds="${2:-20}"
part="${3:-all}"
bench="$build/test/bench_track"
textures="asphalt_01.png brick_floor.png anti_skid_tiles.png"
row() {  # name, tracker, keys...
  local name="$1" mode="$2"
  shift 2
  "$bench" accuracy seconds="$seconds" "$@" 2>&1 | awk -v s="$name" -v m="$mode" '
    $1 ~ /\.png$/ { printf "| %s | %s | %s | %s / %s / %s | %s | %s | %s / %s | %s | %s |", s, m, $1, $4, $5, $6, $10, $11, $12, $13, $16, $17; row = 1 }
    /local plane:/ { printf " %s / %s | %s / %s | %s %s |\n", $6, $8, $13, $15, $19, $20; row = 0 }
    END { if (row) printf " | | |\n" }'
}
echo "| scene | tracker | texture | ok / deg / lost | slope v | slope w | RMS / max mm | drift % | ms/frame | roll err RMS / max deg | pitch err RMS / max deg | RMS err/sigma roll, pitch |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
poses=("-1.0,0,0.9,0,40,180" "-1.2,0,1.1,0,55,180" "-0.8,0,0.8,0,35,180")
for i in 0 1 2; do
  pose="${poses[$i]}"
  [ "$part" = all ] || [ "$part" = "rear$((i + 1))" ] || continue
  for bumps in 3 10; do
    for tex in $textures; do
      for plane in 0 1; do
        row "rear $pose, bumps $bumps" "$([ $plane = 1 ] && echo local plane || echo fixed)" \
          ext="$pose" fov=60 motion=car speed=3 radius=6 lean=-0.07 bumps=$bumps textures=$tex plane=$plane
      done
    done
  done
done
[ "$part" = all ] || [ "$part" = rigid ] || exit 0
for config in 1 2 3; do
  for tex in $textures; do
    for plane in 0 1; do
      row "configuration $config (rigid)" "$([ $plane = 1 ] && echo local plane || echo fixed)" config=$config textures=$tex plane=$plane
    done
  done
done
