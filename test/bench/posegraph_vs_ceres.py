#!/usr/bin/env python3
"""`planarvo posegraph IN -o OUT` against Ceres Solver as whole processes.

For every g2o file in the data folder, runs both tools interleaved (planarvo, Ceres, planarvo,
Ceres, ...), times each process from spawn to exit with time.perf_counter (millisecond
resolution), and prints one Markdown row per graph: best and median wall time of each, the
chi^2 each reached (recomputed here from the graph it wrote, g2o's convention), its iterations,
and the ratio planarvo / Ceres of the best times. The issue's target is a ratio of at most 0.5
on every graph (--check makes a miss exit 1).

The Ceres peer is test/bench/ceres/posegraph_ceres (build with -DPLANARVO_BENCH_CERES=ON after
`PLANARVO_BENCH_DEPS=1 scripts/install-deps.sh`): it reads the same file, solves the same
problem with the same tolerances and writes the result, linked against Ceres alone.

  test/bench/posegraph_vs_ceres.py [--planarvo build/planarvo]
      [--ceres build-ceres/test/bench/ceres/posegraph_ceres] [--data ../shared/data/posegraphs]
      [--repeat 5] [--graphs ring,intel] [--check]
"""
import argparse
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
ORDER = ["ring", "intel", "manhattanOlson3500", "ringCity", "city10000", "ais2klinik"]


def g2o_chi2(path):
    """sum e' Omega e, e = t2v(Z^-1 (X_i^-1 X_j)), over the EDGE_SE2 lines of a g2o file."""
    poses, edges = {}, []
    with open(path) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "VERTEX_SE2":
                poses[int(w[1])] = tuple(map(float, w[2:5]))
            elif w[0] == "EDGE_SE2":
                edges.append((int(w[1]), int(w[2]), tuple(map(float, w[3:12]))))
    chi2 = 0.0
    for i, j, m in edges:
        xi, yi, ti = poses[i]
        xj, yj, tj = poses[j]
        zx, zy, zt, a, b, c, d, e, f = m
        ci, si = math.cos(ti), math.sin(ti)
        lx, ly = ci * (xj - xi) + si * (yj - yi), -si * (xj - xi) + ci * (yj - yi)
        cz, sz = math.cos(zt), math.sin(zt)
        ex, ey = cz * (lx - zx) + sz * (ly - zy), -sz * (lx - zx) + cz * (ly - zy)
        et = math.atan2(math.sin(tj - ti - zt), math.cos(tj - ti - zt))
        chi2 += a * ex * ex + d * ey * ey + f * et * et + 2 * (b * ex * ey + c * ex * et + e * ey * et)
    return chi2


def run(cmd):
    """Wall seconds of one process, its exit code and its output."""
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return time.perf_counter() - t0, p.returncode, p.stdout


def iterations(output):
    m = re.search(r"in (\d+) iterations", output)
    return int(m.group(1)) if m else -1


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--planarvo", default=os.path.join(ROOT, "build", "planarvo"))
    ap.add_argument("--ceres", default=os.path.join(ROOT, "build-ceres", "test", "bench", "ceres", "posegraph_ceres"))
    ap.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data", "posegraphs"))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--graphs", default="", help="comma-separated names (default: every .g2o in --data)")
    ap.add_argument("--check", action="store_true", help="exit 1 unless every ratio is at most 0.5")
    a = ap.parse_args()
    for tool in (a.planarvo, a.ceres):
        if not os.access(tool, os.X_OK):
            sys.exit(f"posegraph_vs_ceres: {tool} is not an executable (build it first; see the docstring)")
    names = [n for n in a.graphs.split(",") if n] or sorted(
        (f[:-4] for f in os.listdir(a.data) if f.endswith(".g2o")),
        key=lambda n: (ORDER.index(n) if n in ORDER else len(ORDER), n))

    print(f"# {platform.node()}: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.2f}; best and median of {a.repeat} interleaved runs, wall ms per process")
    print("| graph | planarvo best | median | χ² | iters | Ceres best | median | χ² | iters | planarvo / Ceres |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    missed = []
    with tempfile.TemporaryDirectory(prefix="posegraph-vs-ceres-") as tmp:
        for name in names:
            src = os.path.join(a.data, name + ".g2o")
            outs = {"planarvo": os.path.join(tmp, name + ".planarvo.g2o"),
                    "ceres": os.path.join(tmp, name + ".ceres.g2o")}
            cmds = {"planarvo": [a.planarvo, "posegraph", src, "-o", outs["planarvo"]],
                    "ceres": [a.ceres, src, "-o", outs["ceres"]]}
            times = {"planarvo": [], "ceres": []}
            last = {}
            for _ in range(a.repeat):
                for tool in ("planarvo", "ceres"):
                    t, rc, out = run(cmds[tool])
                    if rc not in (0, 1):
                        sys.exit(f"posegraph_vs_ceres: {' '.join(cmds[tool])} exited {rc}:\n{out}")
                    times[tool].append(t)
                    last[tool] = out
            cells = []
            for tool in ("planarvo", "ceres"):
                cells += [f"{1e3 * min(times[tool]):.0f}", f"{1e3 * statistics.median(times[tool]):.0f}",
                          f"{g2o_chi2(outs[tool]):.4f}", str(iterations(last[tool]))]
            ratio = min(times["planarvo"]) / min(times["ceres"])
            if ratio > 0.5:
                missed.append(name)
            print(f"| {name} | " + " | ".join(cells) + f" | {ratio:.2f} |", flush=True)
    if missed:
        print(f"\nabove the target (planarvo at most half Ceres's time): {', '.join(missed)}")
    return 1 if a.check and missed else 0


if __name__ == "__main__":
    sys.exit(main())
