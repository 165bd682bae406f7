#!/usr/bin/env bash
# The whole calibration on rigs and floors the other benchmarks do not use (issue 25's closing
# sweep): a camera 8 cm high behind the axle looking backwards under its own lamp and reflection
# (with a rolling shutter and blur, and without), a tilted camera under lamp and shadow, and a car
# at 15 fps with its camera pitched 35 deg. Each drive is simulated, calibrated with `planarvo
# calibrate` (the tool as a user runs it) and tracked with the true extrinsics; one markdown row per
# drive with the calibration's errors (estimate - truth) or its refusal, and tracking's counts.
#   bash test/bench/calibration_rig_sweep.sh [BUILD_DIR=build] [SECONDS=10] [OUT_DIR=a new temp dir]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
seconds="${2:-10}"
out="${3:-$(mktemp -d)}"
cli="$build/planarvo"
textures="$root/../shared/data/textures"
[ -d "$textures" ] || textures="$root/data/textures"
row() {  # name, texture, extrinsics (m, deg), simulate options...
  local name="$1" tex="$2" ext="$3"
  shift 3
  local d="$out/$name-${tex%.png}"
  rm -rf "$d"
  "$cli" simulate --quiet --out "$d" --texture "$textures/$tex" --extrinsics "$ext" --seconds "$seconds" "$@" >/dev/null
  local rc=0
  "$cli" calibrate "$d" --quiet -o "$d/cal.yaml" >"$d/cal.txt" 2>&1 || rc=$?
  "$cli" track "$d" --quiet --extrinsics "$d/extrinsics_gt.yaml" >"$d/track.txt" 2>&1 || true
  /usr/bin/python3 - "$d" "$rc" "$name" "$tex" <<'PY'
import math, re, sys
d, rc, name, tex = sys.argv[1:]
def values(path):
    text = open(path).read()
    return [float(re.search(r"^%s: (\S+)" % k, text, re.M).group(1)) for k in ("x", "y", "z", "roll", "pitch", "yaw")]
track = re.search(r"(\d+) ok, (\d+) degraded, (\d+) lost", open(d + "/track.txt").read())
counts = "/".join(track.groups()) if track else "?"
if rc != "0":
    lines = [l for l in open(d + "/cal.txt").read().splitlines() if l.startswith("planarvo calibrate: ")]
    print("| %s | %s | refused (exit %s): %s | | %s |" % (name, tex, rc, lines[0][20:160] if lines else "?", counts))
else:
    t, c = values(d + "/extrinsics_gt.yaml"), values(d + "/cal.yaml")
    mm = " / ".join("%.2f" % ((c[i] - t[i]) * 1e3) for i in range(3))
    deg = " / ".join("%.3f" % math.degrees(math.remainder(c[i] - t[i], 2 * math.pi)) for i in range(3, 6))
    print("| %s | %s | %s | %s | %s |" % (name, tex, mm, deg, counts))
PY
}
low="-0.15,0.05,0.08,-5,30,170"
echo "| rig | texture | x / y / z mm (or the refusal) | roll / pitch / yaw deg | tracked ok / degraded / lost |"
echo "|---|---|---|---|---|"
for tex in black_painted_planks.png blue_floor_tiles_01.png brushed_concrete.png skimage_grass.png anti_slip_concrete.png brown_mud_rocks_01.png; do
  row low-all "$tex" "$low" --lamp 0.6 --reflection 40 --readout-time 0.02 --exposure 0.004
done
row low-light black_painted_planks.png "$low" --lamp 0.6 --reflection 40
row low-reflection black_painted_planks.png "$low" --reflection 40
for tex in asphalt_02.png skimage_gravel.png anti_skid_tiles.png aerial_asphalt_01.png; do
  row tilted "$tex" 0.1,-0.2,0.3,25,-25,90 --shadow 0.5 --lamp 0.4
  row car15 "$tex" 0.3,0.0,0.25,0,35,0 --motion car --min-turn-radius 1.0 --fps 15 --readout-time 0.03
done
