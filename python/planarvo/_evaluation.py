"""Evaluation: the accuracy of estimated motions against true ones."""
from __future__ import annotations

import ctypes
from dataclasses import dataclass, fields
from typing import Optional, Sequence

import numpy as np

from . import _native as N
from ._errors import _check
from ._native import lib
from ._se2 import _se2_array
from ._util import ArrayLike


@dataclass
class MotionAccuracy:
    """Accuracy of estimated motions against true ones (planarvo_motion_accuracy)."""
    intervals: int
    distance: float
    slope_linear: float
    slope_angular: float
    rms_translation: float
    max_translation: float
    rms_rotation: float
    gross_errors: int
    endpoint_error: float
    endpoint_drift: float
    endpoint_heading: float


def evaluate_motions(estimated: ArrayLike, truth: ArrayLike, dt: Sequence[float],
                     valid: Optional[Sequence[bool]] = None, gross_threshold: float = 1e-3) -> MotionAccuracy:
    """Compares (N, 3) estimated motions with (N, 3) true ones over intervals of dt (N,) seconds;
    valid (N,) flags leave intervals out of the per-interval figures (None: all count)."""
    e, t = _se2_array(estimated, "estimated"), _se2_array(truth, "truth")
    d = np.ascontiguousarray(dt, dtype=np.float64)
    if t.shape != e.shape or d.shape != (e.shape[0],):
        raise ValueError("evaluate_motions: estimated %s, truth %s and dt %s must have N rows"
                         % (e.shape, t.shape, d.shape))
    v = None
    if valid is not None:
        v = np.ascontiguousarray(valid, dtype=np.int32)
        if v.shape != d.shape:
            raise ValueError("valid: expected shape %s, got %s" % (d.shape, v.shape))
    a = N.sized(N.MotionAccuracy)
    _check(lib.planarvo_evaluate_motions(e.ctypes.data_as(N.P(N.SE2)), t.ctypes.data_as(N.P(N.SE2)),
                                         d.ctypes.data_as(N.P(ctypes.c_double)),
                                         None if v is None else v.ctypes.data_as(N.P(ctypes.c_int32)),
                                         e.shape[0], gross_threshold, ctypes.byref(a)))
    return MotionAccuracy(*(getattr(a, f.name) for f in fields(MotionAccuracy)))
