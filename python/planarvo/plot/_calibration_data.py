"""The numbers behind the calibration figures: the motion pairs (given, or tracked from the data
set as `planarvo calibrate` tracks them), the graph calibration of the whole drive and of
consecutive windows, and the residuals at the final estimate."""
from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional

import numpy as np

from ._errors import InputError
from ._io import ExtrinsicsFile, open_dataset, read_extrinsics

GRAPH_NAMES = ("x", "y", "z", "yaw")  # the graph's (x, y, scale, yaw); the scale is the camera height


@dataclass
class Run:
    """One graph calibration: label, pair index range [start, stop), the result (None when the
    call failed outright) and why not ok ('' when ok)."""
    label: str
    start: int
    stop: int
    result: object = None
    problem: str = ""


@dataclass
class CalibrationData:
    source: str                     # the pairs' origin in words
    pairs: list
    options: object                 # planarvo.CalibrationOptions
    metric: bool                    # scale held at 1 (a metric sensor)
    whole: Run = None
    windows: List[Run] = field(default_factory=list)
    residuals: Optional[object] = None  # planarvo.PairResiduals: the library's, at the whole drive's estimate
    outlier: Optional[np.ndarray] = None
    odometry_noise: str = ""        # how the odometry's sigmas were taken


def _log(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def pairs_from_dataset(path: str, extr: ExtrinsicsFile, options: Optional[Dict[str, Any]] = None) -> list:
    """Tracks the data set (options: planarvo.Dataset's bag keywords) at x = y = 0, z = 1, yaw = 0
    with the calibrated roll and pitch, as the calibration's second stage does, and keeps the
    pairs with odometry."""
    import planarvo
    roll, pitch = extr.values[3], extr.values[4]
    with open_dataset(path, options) as ds:
        if not ds.info.has_odometry:
            raise InputError("%s has no wheel odometry%s: the residuals need the odometry method's pairs" % (
                path, " (give its topic: --odom-topic TOPIC)" if ds.info.is_bag else ""))
        _log("tracking %s at roll %.3f deg, pitch %.3f deg for the motion pairs..." % (
            path, math.degrees(roll), math.degrees(pitch)))
        try:
            with planarvo.Context() as ctx:
                pairs = planarvo.track_motions(ctx, ds, planarvo.Extrinsics(0.0, 0.0, 1.0, roll, pitch, 0.0))
        except planarvo.Error as e:
            raise InputError("cannot track %s: %s" % (path, e.message)) from None
    return [p for p in pairs if p.odometry is not None]


def load_pairs(path: str) -> list:
    import planarvo
    try:
        pairs = planarvo.load_motion_pairs(path)
    except planarvo.Error as e:
        raise InputError("cannot read the motion pairs %s: %s" % (path, e.message)) from None
    if any(p.odometry is None for p in pairs):
        raise InputError("%s: pairs without odometry; the figures need the odometry method's pairs" % path)
    return pairs


def options_for(extr: ExtrinsicsFile, from_dataset: bool, fix_scale: Optional[float]):
    """The options planarvo calibrate used: from a data set the odometry's noise is fitted to the
    residuals; a scale not in the YAML's estimated list is held (at 1 for a metric sensor, whose
    YAML has z 0, else at the YAML's z)."""
    import planarvo
    o = planarvo.CalibrationOptions(method=planarvo.CalibrationMethod.ODOMETRY)
    if from_dataset:
        o.estimate_odometry_noise = True
    if fix_scale is not None:
        o.fix_scale, o.fixed_scale = True, float(fix_scale)
    elif "z" not in extr.estimated:
        z = float(extr.values[2])
        o.fix_scale, o.fixed_scale = True, (z if z > 0 else 1.0)
    return o


def calibrate(pairs: list, options, label: str, start: int, stop: int) -> Run:
    import planarvo
    run = Run(label, start, stop)
    try:
        run.result = planarvo.calibrate(pairs[start:stop], options)
    except planarvo.Error as e:
        run.result, run.problem = e.result, e.message
    except ValueError as e:
        run.problem = str(e)
    return run


def windows(pairs: list, options, n: int) -> List[Run]:
    """n consecutive windows of the pairs, each calibrated on its own."""
    edges = np.linspace(0, len(pairs), n + 1).round().astype(int) if n > 0 else []
    return [calibrate(pairs, options, "%d" % (k + 1), int(edges[k]), int(edges[k + 1])) for k in range(n)]


def residuals(data: CalibrationData) -> None:
    """Fills data.residuals, data.outlier and data.odometry_noise: the whole drive's calibration's
    own, from the library (planarvo_calibrate_residuals)."""
    from planarvo import calibrate_residuals
    usable = [p for p in data.pairs if p.odometry is not None]
    if not usable:
        return
    _, res = calibrate_residuals(usable, data.options)
    data.residuals, data.outlier = res, res.outlier
    data.odometry_noise = ("the calibration options' default model" if res.odometry_noise is None else
                           "a model fitted to these residuals by the calibration (variance per component: "
                           "constant + per travel² + per turn²)")


def prepare(dataset, motions, extrinsics, truth_path, n_windows, fix_scale, options=None):
    """Reads the inputs and runs the calibrations: (data, extrinsics, truth or None). options:
    planarvo.Dataset's bag keywords for the data set."""
    extr = read_extrinsics(extrinsics)
    if truth_path is None and dataset is not None and os.path.isdir(dataset):
        default = os.path.join(dataset, "extrinsics_gt.yaml")
        truth_path = default if os.path.isfile(default) else None
    truth = read_extrinsics(truth_path) if truth_path else None
    if dataset is not None:
        pairs, source = pairs_from_dataset(dataset, extr, options), "tracked from %s" % dataset
    else:
        pairs, source = load_pairs(motions), motions
    if len(pairs) < 3:
        raise InputError("%d motion pairs with odometry: too few to calibrate" % len(pairs))
    options = options_for(extr, dataset is not None, fix_scale)
    data = CalibrationData(source, pairs, options, bool(options.fix_scale) and options.fixed_scale == 1.0
                             and float(extr.values[2]) == 0.0)
    data.whole = calibrate(pairs, options, "all", 0, len(pairs))
    if data.whole.result is None:
        raise InputError("the calibration of the whole drive failed: %s" % data.whole.problem)
    data.windows = windows(pairs, options, n_windows)
    residuals(data)
    return data, extr, truth, truth_path
