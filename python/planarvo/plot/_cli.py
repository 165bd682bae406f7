"""The command line: python3 -m planarvo.plot {track,calibration,outliers,report,mosaic} ... (docs/outputs.md).

Exit status 0 when the figures were written, 2 for bad input or usage (with the reason on
stderr), 1 when something else failed."""
from __future__ import annotations

import argparse
import os
import sys
import time
from typing import List, Optional

from ._errors import InputError
from ._io import add_bag_options, bag_options

PROG = "planarvo plot"


def _formats(text: str) -> List[str]:
    from ._style import parse_formats  # imports matplotlib
    try:
        return parse_formats(text)
    except ValueError as e:
        raise InputError(str(e)) from None


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out-dir", default=".", help="where the figures go (default: the current directory; created)")
    p.add_argument("--format", default="png", help="png, pdf, svg, or several comma-separated (default png)")


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog=PROG, description="Figures (PNG, PDF, SVG) and a calibration report "
                                 "(self-contained HTML) from planarvo's output files.")
    sub = ap.add_subparsers(dest="command", metavar="{track,calibration,outliers,report,mosaic}")
    t = sub.add_parser("track", help="trajectory, velocity, velocity histogram and tracking figures",
                       description="trajectory.FMT, velocity.FMT, velocity_hist.FMT (needs ground truth) and "
                       "tracking.FMT (needs --stats) from a data set and the trajectory that track wrote; with the "
                       "statistics of track --local-plane also body_roll.FMT (the roll against the yaw rate, the "
                       "paper's Figure 18) and body_pitch.FMT (the pitch over time, its Figure 19).")
    t.add_argument("dataset", metavar="DATASET", help="the data set folder, bag or MCAP file that was tracked")
    t.add_argument("--trajectory", required=True, help="the TUM trajectory from planarvo track -o")
    t.add_argument("--stats", help="the per-frame statistics CSV from planarvo track --stats")
    add_bag_options(t)
    _common(t)
    c = sub.add_parser("calibration", help="calibration estimates and residual figures, and an HTML report",
                       description="calibration_estimates.FMT and calibration_residuals.FMT, and with --report "
                       "one self-contained HTML file, from calibrated extrinsics and the motion pairs (given, or "
                       "tracked from the data set as planarvo calibrate does).")
    c.add_argument("dataset", metavar="DATASET", nargs="?", help="the data set that was calibrated")
    c.add_argument("--extrinsics", required=True, help="the extrinsics YAML that planarvo calibrate wrote")
    c.add_argument("--motions", help="a motion-pair CSV instead of DATASET (planarvo calibrate --motions)")
    c.add_argument("--truth", help="true extrinsics YAML (default: DATASET/extrinsics_gt.yaml when present)")
    c.add_argument("--windows", type=int, default=4, help="consecutive sub-trajectories calibrated on their own "
                   "(default 4; 0: none)")
    c.add_argument("--fix-scale", type=float, metavar="SCALE", help="motion pairs of a metric sensor: hold the "
                   "scale at SCALE (1 for a laser) as calibrate --motions --fix-scale does")
    c.add_argument("--report", metavar="HTML", help="also write a self-contained HTML report here")
    add_bag_options(c)
    _common(c)
    o = sub.add_parser("outliers", help="the pixels the tracker's robust norm down-weighted in one frame",
                       description="outliers_N.FMT: tracks frames 0..N with the extrinsics and draws frame N's "
                       "residuals against its keyframe: the down-weighted pixels over the keyframe's image, and "
                       "the residual image (the paper's Figure 20).")
    o.add_argument("dataset", metavar="DATASET", help="the data set folder, bag or MCAP file")
    o.add_argument("--extrinsics", required=True, help="the camera's extrinsics YAML")
    o.add_argument("--frame", required=True, type=int, metavar="N", help="the frame (index from 0; at least 1)")
    o.add_argument("--level", type=int, default=0, metavar="L", help="pyramid level (default 0: full resolution)")
    add_bag_options(o)
    _common(o)
    r = sub.add_parser("report", help="track and calibration figures in one HTML file",
                       description="Everything above for one data set: the track figures (with --trajectory) "
                       "and the calibration figures (with --extrinsics), in one self-contained HTML file.")
    r.add_argument("dataset", metavar="DATASET")
    r.add_argument("--trajectory", help="the TUM trajectory from planarvo track -o")
    r.add_argument("--stats", help="the per-frame statistics CSV")
    r.add_argument("--extrinsics", help="the extrinsics YAML from planarvo calibrate")
    r.add_argument("--truth", help="true extrinsics YAML (default: DATASET/extrinsics_gt.yaml when present)")
    r.add_argument("--windows", type=int, default=4)
    r.add_argument("-o", "--output", required=True, metavar="HTML", help="the HTML file to write")
    add_bag_options(r)
    m = sub.add_parser("mosaic", help="floor mosaics in metres, side by side, with the trajectory over them",
                       description="mosaic.FMT (or --name): each mosaic that planarvo mosaic wrote (its image and "
                       "map_server YAML) in metric axes, side by side, optionally with a trajectory over it and "
                       "a zoom, to compare two calibrations or trajectories.")
    m.add_argument("images", metavar="MOSAIC", nargs="+", help="mosaic images (each with its .yaml beside it)")
    m.add_argument("--title", action="append", default=[], help="a panel's title, once per mosaic in order "
                   "(default: the file names)")
    m.add_argument("--trajectory", help="a TUM trajectory in the mosaics' frame to draw over them")
    m.add_argument("--zoom", metavar="X0,Y0,X1,Y1", help="show only this box, metres")
    m.add_argument("--name", default="mosaic", help="the figure's file stem (default mosaic)")
    _common(m)
    return ap


def _run(args: argparse.Namespace) -> List[str]:
    if args.command == "track":
        formats = _formats(args.format)
        os.makedirs(args.out_dir, exist_ok=True)
        from ._track import plot_track
        return plot_track(args.dataset, args.trajectory, args.stats, args.out_dir, formats, bag_options(args))
    if args.command == "calibration":
        formats = _formats(args.format)
        if (args.dataset is None) == (args.motions is None):
            raise InputError("give either DATASET or --motions FILE (one of them)")
        if args.motions is not None and bag_options(args):
            raise InputError("the bag options (--odom-topic, ...) apply to DATASET, not to --motions")
        if args.windows < 0:
            raise InputError("--windows must be 0 or more")
        os.makedirs(args.out_dir, exist_ok=True)
        from ._calibration_command import plot_calibration
        return plot_calibration(args)
    if args.command == "mosaic":
        formats = _formats(args.format)
        os.makedirs(args.out_dir, exist_ok=True)
        from ._mosaic_figure import mosaic_figure
        return mosaic_figure(args.images, args.title, args.trajectory, args.zoom, args.out_dir, args.name, formats)
    if args.command == "outliers":
        _formats(args.format)
        os.makedirs(args.out_dir, exist_ok=True)
        from ._outliers import plot_outliers
        return plot_outliers(args)
    from ._report import full_report
    return full_report(args)


def main(argv: Optional[List[str]] = None) -> int:
    ap = _parser()
    args = ap.parse_args(argv)
    if args.command is None:
        ap.print_help(sys.stderr)
        return 2
    t0 = time.perf_counter()
    try:
        written = _run(args)
    except InputError as e:
        print("%s %s: %s" % (PROG, args.command, e), file=sys.stderr)
        return 2
    except OSError as e:
        print("%s %s: %s" % (PROG, args.command, e), file=sys.stderr)
        return 2
    for path in written:
        print("wrote " + path)
    print("%d files in %.2f s" % (len(written), time.perf_counter() - t0), file=sys.stderr)
    return 0
