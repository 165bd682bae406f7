#!/usr/bin/env bash
# The rolling shutter's readout time estimated from the drive (issue 23): `planarvo calibrate
# --readout-time estimate` on simulated drives over several textures, camera poses and readouts
# (a global shutter among them), against the readout the simulator rendered. One table row per
# drive: the estimate with its sigma, the error in ms and in sigmas, roll/pitch/z errors after
# the calibration, and the estimate's time.
#   bash test/bench/readout_estimate_sweep.sh [BUILD_DIR=build] [SECONDS=20] [SCRATCH=mktemp]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
seconds="${2:-20}"
scratch="${3:-$(mktemp -d)}"
tool="$build/planarvo"
textures="$root/data/textures"
[ -f "$textures/brick_floor.png" ] || textures="$root/../shared/data/textures"
# name | readout s | simulate keys
drives=(
  "asphalt_01, default camera|0.025|--texture $textures/asphalt_01.png --seed 1"
  "brick_floor, z 0.3 m, roll 5, pitch 20|0.015|--texture $textures/brick_floor.png --extrinsics 0.15,0.03,0.3,5,20,0 --seed 2"
  "anti_skid_tiles, default camera|0.030|--texture $textures/anti_skid_tiles.png --seed 3"
  "brushed_concrete, global shutter|0|--texture $textures/brushed_concrete.png --seed 4"
  "low rolled camera z 0.12 m, roll -27, blue tiles|0.010|--texture $textures/blue_floor_tiles_01.png --extrinsics 0.25,0.05,0.12,-27,8,0 --seed 5"
  "rear camera 40 deg, car at 3 m/s, asphalt_02|0.020|--texture $textures/asphalt_02.png --extrinsics -1.0,0,0.9,0,40,180 --fov 60 --motion car --max-speed 3 --min-turn-radius 6 --seed 6"
)
echo "| drive | true ms | estimate ms | sigma ms | error ms | error/sigma | roll err deg | pitch err deg | z err mm | estimate s |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for d in "${drives[@]}"; do
  IFS='|' read -r name readout keys <<<"$d"
  dir="$scratch/$(echo "$name" | tr -c 'a-z0-9' '_')"
  [ -f "$dir/frames.txt" ] || "$tool" simulate --quiet --out "$dir" --seconds "$seconds" --readout-time "$readout" $keys >/dev/null
  out="$("$tool" calibrate "$dir" --quiet --readout-time estimate -o "$dir/estimated.yaml")"
  line="$(grep '^rolling shutter' <<<"$out")"
  python3 - "$dir" "$readout" "$name" "$line" <<'PY'
import math, re, sys
d, truth, name, line = sys.argv[1], float(sys.argv[2]), sys.argv[3], sys.argv[4]
def yaml(path):
    v = {}
    for l in open(path):
        m = re.match(r"^(x|y|z|roll|pitch|yaw):\s*([-0-9.eE+]+)", l)
        if m: v[m.group(1)] = float(m.group(2))
    return v
gt, est = yaml(d + "/extrinsics_gt.yaml"), yaml(d + "/estimated.yaml")
m = re.search(r"readout ([-0-9.]+) ms \+- ([0-9.]+) .*?, ([0-9.]+) s;", line)
r, s, secs = float(m.group(1)), float(m.group(2)), float(m.group(3))
err = r - truth * 1e3
print("| %s | %.1f | %.2f | %.2f | %+.2f | %+.1f | %+.3f | %+.3f | %+.2f | %.1f |" % (
    name, truth * 1e3, r, s, err, err / s if s > 0 else 0.0, math.degrees(est["roll"] - gt["roll"]),
    math.degrees(est["pitch"] - gt["pitch"]), (est["z"] - gt["z"]) * 1e3, secs))
PY
done
