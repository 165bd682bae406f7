#!/usr/bin/env bash
# Tracking that starts at speed (issue 23; src/track/README.md, "Acquisition"): 3-s drives over
# several textures, camera poses, a rear camera on a car, a rolling shutter with motion blur and
# a robot spinning in place; the tracker is given only the FRAMES frames from the drive's
# fastest point after its first second, so it starts there with no motion to predict from. One
# markdown row per drive: the speed there, ok/degraded/lost, the worst motion error, the worst
# among the ok ones and the first motion's against the simulator's truth, and the time of the
# first aligned frame (the one that searches) beside the median of the others.
#   bash test/bench/acquisition_sweep.sh [BUILD_DIR=build] [FRAMES=16] [SCRATCH=mktemp]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
frames="${2:-16}"
scratch="${3:-$(mktemp -d)}"
tool="$build/planarvo"
textures="$root/data/textures"
[ -f "$textures/brick_floor.png" ] || textures="$root/../shared/data/textures"
config2="0.1917,-0.1078,0.2164,29.8,-4.6,75.8"
config3="0.2226,0.0806,0.1469,-26.6,4.7,-18.6"
rear="--extrinsics -1.0,0,0.9,0,40,180 --fov 60 --motion car --max-speed 3 --min-turn-radius 6"
# name | simulate keys
drives=()
for tex in brick_floor asphalt_01 blue_floor_tiles_01 brushed_concrete skimage_grass anti_skid_tiles; do
  for seed in 1 2; do drives+=("$tex, configuration 1, seed $seed|--texture $textures/$tex.png --seed $seed --max-speed 1.2"); done
done
for seed in 3 4; do
  drives+=("asphalt_02, configuration 2, seed $seed|--texture $textures/asphalt_02.png --seed $seed --max-speed 1.2 --extrinsics $config2")
  drives+=("asphalt_02, configuration 3 (low, rolled), seed $seed|--texture $textures/asphalt_02.png --seed $seed --max-speed 1.2 --extrinsics $config3")
done
drives+=(
  "rear camera 40 deg, car, asphalt_02|--texture $textures/asphalt_02.png $rear --seed 6"
  "rear camera 40 deg, car, asphalt_01|--texture $textures/asphalt_01.png $rear --seed 7"
  "brick_floor, 25 ms rolling shutter|--texture $textures/brick_floor.png --seed 5 --max-speed 1.2 --readout-time 0.025"
  "asphalt_01, 25 ms rolling shutter, 4 ms exposure|--texture $textures/asphalt_01.png --seed 6 --max-speed 1.2 --readout-time 0.025 --exposure 0.004"
  "brushed_concrete, spinning at 3 rad/s|--texture $textures/brushed_concrete.png --seed 2 --motion spin --max-turn-rate 3"
)
echo "| drive | m/s at start | ok / degraded / lost | worst error mm | worst ok error mm | first motion's error mm | first aligned frame ms | median ms of the rest |"
echo "|---|---|---|---|---|---|---|---|"
for d in "${drives[@]}"; do
  IFS='|' read -r name keys <<<"$d"
  dir="$scratch/$(echo "$name" | tr -c 'a-z0-9' '_')"
  [ -f "$dir/frames.txt" ] || "$tool" simulate --quiet --out "$dir" --seconds 3 --supersampling 2 $keys >/dev/null
  python3 - "$dir" "$frames" <<'PY'
import math, os, sys
d, n = sys.argv[1], int(sys.argv[2])
gt = [l.split() for l in open(d + "/groundtruth.txt") if not l.startswith("#")]
t = [float(r[0]) for r in gt]; x = [float(r[1]) for r in gt]; y = [float(r[2]) for r in gt]
fps = 1.0 / (t[1] - t[0])
best, first = -1.0, 0
for k in range(int(round(fps)), len(t) - n):
    v = math.hypot(x[k + 1] - x[k], y[k + 1] - y[k])
    if v > best: best, first = v, k
lines = [l for l in open(d + "/frames.txt") if not l.startswith("#")]
cut = d + "/start"
os.makedirs(cut, exist_ok=True)
for f in ["camera.yaml", "groundtruth.txt"]:
    open(cut + "/" + f, "w").write(open(d + "/" + f).read())
if not os.path.exists(cut + "/images"): os.symlink(d + "/images", cut + "/images")
open(cut + "/frames.txt", "w").write("".join(lines[first:first + n]))
open(cut + "/speed", "w").write("%.2f" % (best * fps))
PY
  "$tool" track --quiet "$dir/start" --extrinsics "$dir/extrinsics_gt.yaml" -o "$dir/start/trajectory.txt" \
      --stats "$dir/start/stats.csv" --max-lost 100 >/dev/null
  python3 - "$dir/start" "$name" <<'PY'
import csv, math, statistics, sys
d, name = sys.argv[1], sys.argv[2]
def poses(path):
    out = {}
    for l in open(path):
        if l.startswith("#") or not l.strip(): continue
        r = [float(v) for v in l.split()]
        out[round(r[0], 6)] = (r[1], r[2], 2 * math.atan2(r[6], r[7]))
    return out
def rel(a, b):
    dx, dy = b[0] - a[0], b[1] - a[1]
    c, s = math.cos(a[2]), math.sin(a[2])
    return (c * dx + s * dy, -s * dx + c * dy)
est, gt = poses(d + "/trajectory.txt"), poses(d + "/groundtruth.txt")
ts = sorted(est)
err = []
for a, b in zip(ts, ts[1:]):
    e, g = rel(est[a], est[b]), rel(gt[a], gt[b])
    err.append(1e3 * math.hypot(e[0] - g[0], e[1] - g[1]))
rows = list(csv.DictReader(open(d + "/stats.csv")))
count = {s: sum(1 for r in rows[1:] if r["status"] == s) for s in ("ok", "degraded", "lost")}
ms = [float(r["ms"]) for r in rows[1:]]
ok_err = [e for e, r in zip(err, rows[1:]) if r["status"] == "ok"]
print("| %s | %s | %d / %d / %d | %.4f | %.4f | %.4f | %.1f | %.1f |" % (
    name, open(d + "/speed").read(), count["ok"], count["degraded"], count["lost"], max(err),
    max(ok_err) if ok_err else 0.0, err[0], ms[0], statistics.median(ms[1:])))
PY
done
