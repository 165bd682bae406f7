"""The numbers behind the calibration figures: the motion pairs (given, or tracked from the data
set as `planarvo calibrate` tracks them), the graph calibration of the whole drive and of
consecutive windows, and the residuals at the final estimate."""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from typing import List, Optional, Tuple

import numpy as np

from ._errors import InputError
from ._io import ExtrinsicsFile
from . import _residuals as R

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
    residuals: Optional[R.PairResiduals] = None
    outlier: Optional[np.ndarray] = None
    odometry_noise: str = ""        # how the odometry's sigmas were taken


def _log(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def pairs_from_dataset(path: str, extr: ExtrinsicsFile) -> list:
    """Tracks the data set at x = y = 0, z = 1, yaw = 0 with the calibrated roll and pitch, as the
    calibration's second stage does, and keeps the pairs with odometry."""
    import planarvo
    roll, pitch = extr.values[3], extr.values[4]
    _log("tracking %s at roll %.3f deg, pitch %.3f deg for the motion pairs..." % (path, math.degrees(roll),
                                                                                  math.degrees(pitch)))
    try:
        with planarvo.Context() as ctx, planarvo.Dataset(path) as ds:
            if not ds.info.has_odometry:
                raise InputError("%s has no wheel odometry: the residuals need the odometry method's pairs" % path)
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


def _arrays(pairs: list) -> Tuple[np.ndarray, np.ndarray]:
    odo = np.array([[p.odometry.x, p.odometry.y, p.odometry.theta] for p in pairs])
    sen = np.array([[p.sensor.x, p.sensor.y, p.sensor.theta] for p in pairs])
    return odo, sen


def covariances(pairs: list, options, odo: np.ndarray, sen: np.ndarray):
    """The (N, 3, 3) covariances of the sensor's and the odometry's (x, y, theta) as the calibration
    takes them: a pair's own, else the options' default model (None for the odometry when its
    model is to be fitted to the residuals)."""
    lib = _library_defaults()

    def opt(name):
        v = getattr(options, name)
        return lib[name] if v is None else v
    s_model = R.model_covariance(sen, opt("sensor_sigma_relative"), opt("sensor_sigma_floor"), opt("sensor_sigma_theta"))
    o_model = R.model_covariance(odo, opt("odometry_sigma_relative"), opt("odometry_sigma_floor"),
                                 opt("odometry_sigma_theta"))
    s_cov = np.array([R.component_covariance(sen[i:i + 1], p.sensor_covariance[None])[0]
                      if p.sensor_covariance is not None else s_model[i] for i, p in enumerate(pairs)])
    given = [p.odometry_covariance is not None for p in pairs]
    o_cov = np.array([R.component_covariance(odo[i:i + 1], p.odometry_covariance[None])[0]
                      if p.odometry_covariance is not None else o_model[i] for i, p in enumerate(pairs)])
    fit = bool(options.estimate_odometry_noise) and not any(given)
    return s_cov, o_cov, fit


def _library_defaults() -> dict:
    """planarvo_calibration_options_init's values of the noise model and the gate."""
    import ctypes
    from .. import _native as N
    c = N.sized(N.CalibrationOptions)
    N.lib.planarvo_calibration_options_init(ctypes.byref(c))
    names = ("sensor_sigma_relative", "sensor_sigma_floor", "sensor_sigma_theta", "odometry_sigma_relative",
             "odometry_sigma_floor", "odometry_sigma_theta", "gate_sigma")
    return {n: getattr(c, n) for n in names}


def residuals(data: CalibrationData) -> None:
    """Fills data.residuals, data.outlier and data.odometry_noise at the whole drive's estimate."""
    z = data.whole.result.value
    odo, sen = _arrays(data.pairs)
    s_cov, o_cov, fit = covariances(data.pairs, data.options, odo, sen)
    gate = data.options.gate_sigma if data.options.gate_sigma is not None else _library_defaults()["gate_sigma"]
    res = R.pair_residuals(odo, sen, z, o_cov, s_cov)
    outlier = R.gated(res.chi2, gate)
    data.odometry_noise = "the calibration options' default model"
    if fit:  # refitted as the calibration does: to the residuals of the inliers, twice
        e = R.right_residual(odo, R.sensor_to_robot(sen, z))
        for _ in range(2):
            coefs = R.fit_odometry_noise(odo[~outlier], e[~outlier])
            o_cov = R.component_covariance(odo, R.noise_covariance(coefs, odo))
            res = R.pair_residuals(odo, sen, z, o_cov, s_cov)
            outlier = R.gated(res.chi2, gate)
        data.odometry_noise = ("a model fitted to these residuals, as the calibration fits it (variance per "
                               "component: constant + per travel² + per turn²)")
    data.residuals, data.outlier = res, outlier
