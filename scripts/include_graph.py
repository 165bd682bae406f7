#!/usr/bin/env python3
"""The include graph between the parts of src/ (core, io, image, ocl, track, graph, calib, sim,
mosaic, capi, cli) at a git revision, from the `#include "part/..."` lines, or how it changed
between two revisions. Edges into core (which every part uses) are left out.

    scripts/include_graph.py [REV]          # the edges at REV (default HEAD)
    scripts/include_graph.py OLD NEW        # the edges whose headers differ, with both counts
"""
import collections
import re
import subprocess
import sys

PARTS = ("core", "io", "image", "ocl", "track", "graph", "calib", "sim", "mosaic", "capi", "cli")


def git(*args):
    return subprocess.run(("git",) + args, capture_output=True, text=True, check=True).stdout


def graph(rev):
    edges = collections.defaultdict(set)
    for path in git("ls-tree", "-r", "--name-only", rev, "src").split():
        if not path.endswith((".cpp", ".h")):
            continue
        part = path.split("/")[1]
        for m in re.finditer(r'#include "([a-z_]+)/([^"]+)"', git("show", "%s:%s" % (rev, path))):
            if m.group(1) != part and m.group(1) in PARTS and m.group(1) != "core":
                edges[(part, m.group(1))].add(m.group(1) + "/" + m.group(2))
    return edges


def main(argv):
    if len(argv) <= 2:
        for (a, b), headers in sorted(graph(argv[1] if len(argv) == 2 else "HEAD").items()):
            print("%-7s -> %-7s %2d headers" % (a, b, len(headers)))
        return 0
    old, new = graph(argv[1]), graph(argv[2])
    for key in sorted(set(old) | set(new)):
        if old.get(key) == new.get(key):
            continue
        before, after = sorted(old.get(key, ())), sorted(new.get(key, ()))
        change = "gone" if not after else "new" if not before else ""
        print("%-7s -> %-7s before %2d  after %2d  %-4s %s" % (key[0], key[1], len(before), len(after), change,
                                                           ", ".join(sorted(set(before) ^ set(after)))))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
