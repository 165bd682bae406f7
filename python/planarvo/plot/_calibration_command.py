"""`plot calibration`: the estimates and residual figures, and the HTML report."""
from __future__ import annotations

import sys
from typing import List

from . import _calibration_data as C
from ._io import bag_options


def plot_calibration(args) -> List[str]:
    from . import _calibration_figures as F
    from ._style import parse_formats
    formats = parse_formats(args.format)
    data, extr, truth, truth_path = C.prepare(args.dataset, args.motions, args.extrinsics, args.truth, args.windows,
                                            args.fix_scale, bag_options(args))
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
