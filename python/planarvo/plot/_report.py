"""One self-contained HTML file (figures embedded as base64 PNG), like Kalibr's report: the
extrinsics with their sigmas, what was not observable and why, the inputs, and the figures."""
from __future__ import annotations

import base64
import html
import math
import os
import tempfile
from typing import Dict, List, Optional, Tuple

import numpy as np

from planarvo import EXTRINSICS_NAMES

from ._calibration_data import CalibrationData
from ._io import ExtrinsicsFile

CSS = """body{font-family:sans-serif;max-width:1150px;margin:2em auto;color:#222}
table{border-collapse:collapse;margin:0.5em 0 1.5em}td,th{border:1px solid #bbb;padding:3px 9px;text-align:right}
th{background:#eee}td.l,th.l{text-align:left}img{max-width:100%;border:1px solid #ddd;margin:0.5em 0}
.bad{color:#b00}.note{color:#555;font-size:0.9em}"""


def _img(path: str) -> str:
    with open(path, "rb") as f:
        return '<img alt="%s" src="data:image/png;base64,%s">' % (
            html.escape(os.path.basename(path)), base64.b64encode(f.read()).decode())


def _unit(name: str):
    return (180 / math.pi, "deg") if name in ("roll", "pitch", "yaw") else (1e3, "mm")


def extrinsics_table(extr: ExtrinsicsFile, truth: Optional[ExtrinsicsFile], observable: Dict[str, bool]) -> str:
    head = ["parameter", "value", "σ", "unit", "estimated"] + (["true", "error", "error / σ"] if truth else [])
    rows = ["<tr>" + "".join('<th class="l">%s</th>' % h if i == 0 else "<th>%s</th>" % h
                             for i, h in enumerate(head)) + "</tr>"]
    for i, name in enumerate(EXTRINSICS_NAMES):
        k, unit = _unit(name)
        est = name in extr.estimated
        obs = observable.get(name, True)
        flag = ("yes" if obs else '<span class="bad">yes, not observable</span>') if est else "no (given)"
        sig = extr.sigmas[i] * k
        cells = ['<td class="l">%s</td>' % name, "<td>%.3f</td>" % (extr.values[i] * k),
                 "<td>%s</td>" % ("%.3f" % sig if est else "–"), "<td>%s</td>" % unit, "<td>%s</td>" % flag]
        if truth:
            err = (extr.values[i] - truth.values[i]) * k
            if unit == "deg":
                err = (err + 180) % 360 - 180
            cells += ["<td>%.3f</td>" % (truth.values[i] * k), "<td>%+.3f</td>" % err,
                      "<td>%s</td>" % ("%+.2f" % (err / sig) if est and sig > 0 else "–")]
        rows.append("<tr>" + "".join(cells) + "</tr>")
    return "<table>%s</table>" % "\n".join(rows)


def runs_table(data: CalibrationData) -> str:
    rows = ["<tr><th class='l'>run</th><th>pairs</th><th>x (mm)</th><th>y (mm)</th><th>z (mm)</th>"
            "<th>yaw (deg)</th><th>outliers</th><th>variance factor</th><th class='l'>status</th></tr>"]
    for r in [data.whole] + data.windows:
        res = r.result
        if res is None:
            rows.append("<tr><td class='l'>%s</td><td>%d</td><td colspan=7 class='l bad'>%s</td></tr>"
                        % (r.label, r.stop - r.start, html.escape(r.problem)))
            continue
        sig = np.sqrt(np.maximum(np.diag(res.covariance), 0))
        k = (1e3, 1e3, 1e3, 180 / math.pi)
        vals = "".join("<td>%.3f ± %.3f</td>" % (res.value[i] * k[i], sig[i] * k[i]) for i in range(4))
        status = "ok" if res.ok else '<span class="bad">%s</span>' % html.escape(r.problem or res.unobservable_reason)
        rows.append("<tr><td class='l'>%s</td><td>%d</td>%s<td>%d</td><td>%.3g</td><td class='l'>%s</td></tr>"
                    % ("whole drive" if r.label == "all" else "window " + r.label, r.stop - r.start, vals,
                       res.outliers, res.variance_factor, status))
    return "<table>%s</table>" % "\n".join(rows)


def _observability(data: CalibrationData) -> Tuple[Dict[str, bool], str]:
    res = data.whole.result
    obs = {n: bool(o) for n, o, e in zip(("x", "y", "z", "yaw"), res.observable, res.estimated) if e}
    if not res.estimated[2]:
        why = "z (the scale) was held at %g, not estimated. " % res.value[2]
    else:
        why = ""
    why += res.unobservable_reason or "Every estimated parameter of the graph is observable on this drive."
    return obs, why


def calibration_section(data: CalibrationData, extr: ExtrinsicsFile, truth: Optional[ExtrinsicsFile],
                        inputs: Dict[str, str], figures: List[str]) -> str:
    obs, why = _observability(data)
    res = data.whole.result
    items = "".join("<tr><td class='l'>%s</td><td class='l'>%s</td></tr>" % (html.escape(k), html.escape(str(v)))
                    for k, v in list(inputs.items()) + [
                        ("method (YAML)", extr.method or "–"), ("notes (YAML)", extr.notes or "–"),
                        ("motion pairs (count)", len(data.pairs)),
                        ("outliers (the calibration's gate)", res.outliers),
                        ("pairs gated out by the calibration", int(data.outlier.sum())),
                        ("variance factor (in the sigmas)", "%.3g" % res.variance_factor),
                        ("odometry noise for the residuals", data.odometry_noise),
                        ("solver", "%d iterations over all solves, %.3f s; final: %s" % (
                            res.total_iterations, res.total_seconds, res.summary.termination))])
    return ("<h2>Extrinsics (T_robot_camera)</h2>%s<p class='note'>Values and sigmas from the YAML (its covariance); "
            "x, y, z and yaw are the graph calibration's against wheel odometry, re-run below.</p>"
            "<h2>Observability</h2><p>%s</p><h2>Whole drive and windows (re-calibrated here)</h2>%s"
            "<h2>Inputs</h2><table>%s</table><h2>Figures</h2>%s"
            % (extrinsics_table(extr, truth, obs), html.escape(why), runs_table(data), items,
               "\n".join(_img(f) for f in figures)))


def write_html(path: str, title: str, body: str) -> None:
    with open(path, "w") as f:
        f.write("<!DOCTYPE html><html><head><meta charset='utf-8'><title>%s</title><style>%s</style></head>"
                "<body><h1>%s</h1>%s</body></html>\n" % (html.escape(title), CSS, html.escape(title), body))


def calibration_report(path: str, data: CalibrationData, extr: ExtrinsicsFile, truth: Optional[ExtrinsicsFile],
                       inputs: Dict[str, str]) -> None:
    from . import _calibration_figures as F
    with tempfile.TemporaryDirectory() as tmp:
        figs = F.estimates_figure(data, extr, truth, tmp, ["png"]) + F.residuals_figure(data, tmp, ["png"])
        write_html(path, "planarvo calibration report", calibration_section(data, extr, truth, inputs, figs))


def full_report(args) -> List[str]:
    """`plot report`: the track figures (with --trajectory) and the calibration (with --extrinsics)."""
    from ._errors import InputError
    from ._io import bag_options
    from ._track import plot_track
    if not args.trajectory and not args.extrinsics:
        raise InputError("give --trajectory, --extrinsics or both")
    body = []
    with tempfile.TemporaryDirectory() as tmp:
        if args.trajectory:
            figs = plot_track(args.dataset, args.trajectory, args.stats, tmp, ["png"], bag_options(args))
            body.append("<h2>Tracking</h2><p>%s</p>%s" % (html.escape("%s, trajectory %s" % (args.dataset, args.trajectory)),
                                                          "\n".join(_img(f) for f in figs)))
        if args.extrinsics:
            from . import _calibration_figures as F
            from ._calibration_data import prepare
            data, extr, truth, truth_path = prepare(args.dataset, None, args.extrinsics, args.truth, args.windows, None,
                                                    bag_options(args))
            figs = F.estimates_figure(data, extr, truth, tmp, ["png"]) + F.residuals_figure(data, tmp, ["png"])
            inputs = {"extrinsics": args.extrinsics, "motion pairs": data.source, "truth": truth_path or "none"}
            body.append("<h2>Calibration</h2>" + calibration_section(data, extr, truth, inputs, figs))
        write_html(args.output, "planarvo report: %s" % args.dataset, "\n".join(body))
    return [args.output]
