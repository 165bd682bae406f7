"""`plot calibration`: the estimates and residual figures, and the HTML report."""
from __future__ import annotations

import os
import sys
from typing import List

from . import _calibration_data as C
from ._errors import InputError
from ._io import read_extrinsics


def prepare(dataset, motions, extrinsics, truth_path, n_windows, fix_scale):
    """Reads the inputs and runs the calibrations: (data, extrinsics, truth or None)."""
    extr = read_extrinsics(extrinsics)
    if truth_path is None and dataset is not None:
        default = os.path.join(dataset, "extrinsics_gt.yaml")
        truth_path = default if os.path.isfile(default) else None
    truth = read_extrinsics(truth_path) if truth_path else None
    if dataset is not None:
        pairs, source = C.pairs_from_dataset(dataset, extr), "tracked from %s" % dataset
    else:
        pairs, source = C.load_pairs(motions), motions
    if len(pairs) < 3:
        raise InputError("%d motion pairs with odometry: too few to calibrate" % len(pairs))
    options = C.options_for(extr, dataset is not None, fix_scale)
    data = C.CalibrationData(source, pairs, options, bool(options.fix_scale) and options.fixed_scale == 1.0
                             and float(extr.values[2]) == 0.0)
    data.whole = C.calibrate(pairs, options, "all", 0, len(pairs))
    if data.whole.result is None:
        raise InputError("the calibration of the whole drive failed: %s" % data.whole.problem)
    data.windows = C.windows(pairs, options, n_windows)
    C.residuals(data)
    return data, extr, truth, truth_path


def plot_calibration(args) -> List[str]:
    from . import _calibration_figures as F
    from ._style import parse_formats
    formats = parse_formats(args.format)
    data, extr, truth, truth_path = prepare(args.dataset, args.motions, args.extrinsics, args.truth, args.windows,
                                            args.fix_scale)
    written = F.estimates_figure(data, extr, truth, args.out_dir, formats)
    written += F.residuals_figure(data, args.out_dir, formats)
    if args.report:
        from ._report import calibration_report
        inputs = {"extrinsics": args.extrinsics, "motion pairs": data.source, "truth": truth_path or "none"}
        calibration_report(args.report, data, extr, truth, inputs)
        written.append(args.report)
    if not data.whole.result.ok:
        print("note: the whole drive's calibration is not determined: %s" % data.whole.problem, file=sys.stderr)
    return written
