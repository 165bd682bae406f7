"""The graph calibration: a sensor's x, y, scale and yaw from motion pairs, and the camera's
extrinsics composed from it and roll and pitch."""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple, cast

import numpy as np

from . import _native as N
from ._camera import Extrinsics
from ._errors import IntEnum, Status, _check
from ._motion_pairs import MotionPair, _pairs_array
from ._native import lib
from ._posegraph import SolverSummary
from ._util import ArrayLike, LogFn, NDArray, PathLike, _c_options, _Callback, _fill_matrix, _matrix, _opt, _path


class CalibrationMethod(IntEnum):
    """planarvo_calibration_method."""
    ODOMETRY = 0
    NONHOLONOMIC = 1


class RobustLoss(IntEnum):
    """planarvo_robust_loss."""
    NONE = 0
    HUBER = 1
    CAUCHY = 2
    TUKEY = 3


@dataclass
class CalibrationOptions:
    """planarvo_calibration_options (the graph calibration); None keeps the library's default.
    initial: (x, y, scale, yaw) to start from instead of the built-in initialisation.
    estimate_odometry_noise: None lets the workflow choose (fitted when the camera's motions are
    tracked from frames, as calibrate_dataset does; kept as odometry_sigma_* for motion pairs)."""
    method: Optional[CalibrationMethod] = None
    fix_scale: Optional[bool] = None
    fixed_scale: Optional[float] = None
    initial: Optional[Tuple[float, float, float, float]] = None
    velocity_form: Optional[bool] = None
    max_iterations: Optional[int] = None
    sensor_sigma_relative: Optional[float] = None
    sensor_sigma_floor: Optional[float] = None
    sensor_sigma_theta: Optional[float] = None
    odometry_sigma_relative: Optional[float] = None
    odometry_sigma_floor: Optional[float] = None
    odometry_sigma_theta: Optional[float] = None
    loss: Optional[RobustLoss] = None
    loss_scale: Optional[float] = None
    gate_sigma: Optional[float] = None
    still_speed: Optional[float] = None
    estimate_odometry_noise: Optional[bool] = None


def _calibration_options(options: Optional[CalibrationOptions], log: Optional[_Callback]) -> N.CalibrationOptions:
    c = _c_options(N.CalibrationOptions, "planarvo_calibration_options_init", options, skip=("initial",))
    if options is not None and options.initial is not None:
        if len(options.initial) != 4:
            raise ValueError("initial: expected (x, y, scale, yaw)")
        c.has_initial = 1
        c.initial[:] = [float(v) for v in options.initial]
    if log is not None:
        c.log = log.c
    return c


@dataclass
class CalibrationResult:
    """A graph calibration: value (x, y, scale, yaw), its (4, 4) covariance; per parameter
    estimated and observable; ok when converged, observable and not ambiguous."""
    value: NDArray[np.float64]
    covariance: NDArray[np.float64]
    estimated: Tuple[bool, ...]
    observable: Tuple[bool, ...]
    ambiguous: bool
    outliers: int
    ok: bool
    unobservable_reason: str
    summary: SolverSummary
    total_iterations: int
    total_seconds: float
    variance_factor: float

    def save(self, path: PathLike, method: CalibrationMethod = CalibrationMethod.ODOMETRY,
             metric_sensor: bool = False, notes: Optional[str] = None) -> None:
        """Writes extrinsics.yaml as planarvo calibrate --motions -o does: x, y, yaw and z = the
        scale (the camera height), or z 0 with metric_sensor (the pairs' sensor measured metres);
        roll and pitch 0, not estimated; the method's sentence; notes as given."""
        _check(lib.planarvo_calibration_save(_path(path), ctypes.byref(self._to_c()), int(method),
                                             int(bool(metric_sensor)), _opt(notes)))

    def _to_c(self) -> N.CalibrationResult:
        r = N.sized(N.CalibrationResult)
        r.value[:] = [float(v) for v in self.value]
        r.covariance[:] = [float(v) for v in np.asarray(self.covariance).ravel()]
        r.estimated[:] = [int(v) for v in self.estimated]
        r.observable[:] = [int(v) for v in self.observable]
        r.ambiguous, r.outliers, r.ok = int(self.ambiguous), self.outliers, int(self.ok)
        r.unobservable_reason = self.unobservable_reason.encode()[:511]
        r.total_iterations, r.total_seconds, r.variance_factor = (self.total_iterations, self.total_seconds,
                                                                  self.variance_factor)
        return r

    @classmethod
    def _from_c(cls, r: N.CalibrationResult) -> "CalibrationResult":
        return cls(np.array(r.value[:]), _matrix(r.covariance, 4), tuple(bool(v) for v in r.estimated),
                   tuple(bool(v) for v in r.observable), bool(r.ambiguous), r.outliers, bool(r.ok),
                   r.unobservable_reason.decode(errors="replace"), SolverSummary._from_c(r.summary),
                   r.total_iterations, r.total_seconds, r.variance_factor)


def calibrate(pairs: Sequence[MotionPair], options: Optional[CalibrationOptions] = None,
              log: Optional[LogFn] = None) -> CalibrationResult:
    """Graph calibration of a sensor's x, y, scale and yaw from motion pairs. Raises Error
    (Status.FAILED, .result the CalibrationResult) when the result is not ok."""
    if not pairs:
        raise ValueError("calibrate: no motion pairs")
    cb = _Callback(log, N.LOG_FN) if log is not None else None
    o = _calibration_options(options, cb)
    r = N.sized(N.CalibrationResult)
    status = lib.planarvo_calibrate(_pairs_array(pairs), len(pairs), ctypes.byref(o), ctypes.byref(r))
    if cb is not None:
        cb.reraise()
    result = CalibrationResult._from_c(r)
    _check(status, result)
    return result


@dataclass
class PairResiduals:
    """Each pair's residual at a calibration's estimate, as the library weighs it (the odometry
    method: the robot's motion eliminated): d (N, 3) the odometry's motion less the sensor's
    mapped into the robot frame (m, m, rad), cov (N, 3, 3) its covariance, chi2 (N,), outlier (N,)
    gated out as a gross error, has_odometry (N,); normalised (N, 3) each component of d over its
    own standard deviation. odometry_noise: (3, 3) the fitted model's variance coefficients per
    component (constant, per m^2 of travel, per rad^2 of turn), None when the options' model was
    used."""
    d: NDArray[np.float64]
    cov: NDArray[np.float64]
    chi2: NDArray[np.float64]
    outlier: NDArray[np.bool_]
    has_odometry: NDArray[np.bool_]
    odometry_noise: Optional[NDArray[np.float64]]

    @property
    def normalised(self) -> NDArray[np.float64]:
        return cast("NDArray[np.float64]", self.d / np.sqrt(np.maximum(np.einsum("nii->ni", self.cov), 1e-300)))


def calibrate_residuals(pairs: Sequence[MotionPair], options: Optional[CalibrationOptions] = None
                        ) -> Tuple[CalibrationResult, PairResiduals]:
    """calibrate(), and each pair's residual at the estimate with the odometry's noise model
    (planarvo_calibrate_residuals): what the calibration plots draw. The result is returned
    whether or not it is ok (check .ok)."""
    if not pairs:
        raise ValueError("calibrate_residuals: no motion pairs")
    o = _calibration_options(options, None)
    r = N.sized(N.CalibrationResult)
    res = (N.PairResidual * len(pairs))()
    noise = N.OdometryNoise()
    status = lib.planarvo_calibrate_residuals(_pairs_array(pairs), len(pairs), ctypes.byref(o), ctypes.byref(r), res,
                                              ctypes.byref(noise))
    result = CalibrationResult._from_c(r)
    if status != Status.FAILED:  # a calibration that is not ok still fills the result and the residuals
        _check(status, result)
    n = len(pairs)
    residuals = PairResiduals(np.array([list(p.d) for p in res]).reshape(n, 3),
                              np.array([list(p.covariance) for p in res]).reshape(n, 3, 3),
                              np.array([p.chi2 for p in res]), np.array([bool(p.outlier) for p in res]),
                              np.array([bool(p.has_odometry) for p in res]),
                              np.array(noise.variance[:]).reshape(3, 3) if noise.fitted else None)
    return result, residuals


def compose_extrinsics(roll: float, pitch: float, roll_pitch_covariance: Optional[ArrayLike],
                       graph: CalibrationResult) -> Tuple[Extrinsics, NDArray[np.float64], Tuple[bool, ...]]:
    """The camera's extrinsics from roll and pitch (with their (2, 2) covariance, or None when
    they were given) and a graph calibration's x, y, scale (the height) and yaw: returns the
    extrinsics, their (6, 6) covariance (order x y z roll pitch yaw) and per parameter whether it
    was estimated."""
    rp = None
    if roll_pitch_covariance is not None:
        rp = (ctypes.c_double * 4)()
        _fill_matrix(rp, roll_pitch_covariance, 2, "roll_pitch_covariance")
    e, cov, est = N.Extrinsics(), (ctypes.c_double * 36)(), (ctypes.c_int32 * 6)()
    _check(lib.planarvo_compose_extrinsics(roll, pitch, rp, ctypes.byref(graph._to_c()), ctypes.byref(e), cov, est))
    return Extrinsics._from_c(e), _matrix(cov, 6), tuple(bool(v) for v in est)
