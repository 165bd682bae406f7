#!/usr/bin/env bash
# Makes the README's pictures (docs/images/) from a 20-second simulated drive over the built-in
# asphalt texture: the floor mosaic with the tracked trajectory, the mosaic with the true and with
# a wrong calibration side by side (zoomed), and two of `planarvo plot track`'s figures.
#   bash scripts/readme_figures.sh [BUILD_DIR=build]   (about a minute on two cores)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
pv="$build/planarvo"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
out="$root/docs/images"
mkdir -p "$out"

"$pv" simulate --out "$work/drive" --seconds 20 --seed 7 --quiet
"$pv" track "$work/drive" --extrinsics "$work/drive/extrinsics_gt.yaml" -o "$work/traj.txt" \
      --stats "$work/stats.csv" --quiet > /dev/null
"$pv" mosaic "$work/drive" --trajectory "$work/traj.txt" --extrinsics "$work/drive/extrinsics_gt.yaml" \
      -o "$work/floor.png" --quiet
# A wrong calibration: yaw 3 degrees and x 15 mm off the true values.
/usr/bin/python3 - "$work/drive/extrinsics_gt.yaml" "$work/wrong.yaml" <<'PY'
import math, re, sys
text = open(sys.argv[1]).read()
v = {k: float(re.search(r"^%s: (\S+)" % k, text, re.M).group(1)) for k in ("x", "y", "z", "roll", "pitch", "yaw")}
v["yaw"] += math.radians(3.0)
v["x"] += 0.015
open(sys.argv[2], "w").write("%YAML:1.0\n---\n" + "".join("%s: %r\n" % kv for kv in v.items()))
PY
"$pv" mosaic "$work/drive" --trajectory "$work/traj.txt" --extrinsics "$work/wrong.yaml" -o "$work/wrong.png" --quiet
"$pv" plot mosaic "$work/floor.png" --trajectory "$work/traj.txt" --title "20-s drive, 1 mm/px, tracked trajectory" \
      --out-dir "$out" --name mosaic
"$pv" plot mosaic "$work/floor.png" "$work/wrong.png" --title "true extrinsics" --title "yaw +3°, x +15 mm" \
      --zoom 0.55,-0.75,0.75,-0.6 --out-dir "$out" --name mosaic_wrong_calibration
"$pv" plot track "$work/drive" --trajectory "$work/traj.txt" --stats "$work/stats.csv" --out-dir "$work/plots"
cp "$work/plots/trajectory.png" "$work/plots/velocity_hist.png" "$out/"
ls -l "$out"
