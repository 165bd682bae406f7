"""Pose graphs: optimising a g2o 2-D pose graph, and the solver's summary."""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import Optional

from . import _native as N
from ._errors import IntEnum, _check
from ._native import lib
from ._util import LogFn, PathLike, _Callback, _path


class PosegraphInit(IntEnum):
    """planarvo_posegraph_init."""
    NONE = 0
    ROTATION_FIRST = 1


@dataclass
class SolverSummary:
    """How a solve went (planarvo_solver_summary)."""
    converged: bool
    termination: str
    iterations: int
    factorizations: int
    initial_chi2: float
    final_chi2: float
    seconds: float

    @classmethod
    def _from_c(cls, s: N.SolverSummary) -> "SolverSummary":
        return cls(bool(s.converged), s.termination.decode(errors="replace"), s.iterations, s.factorizations,
                   s.initial_chi2, s.final_chi2, s.seconds)


def posegraph_optimize(in_path: PathLike, out_path: Optional[PathLike] = None, max_iterations: int = 100,
                       init: PosegraphInit = PosegraphInit.NONE, log: Optional[LogFn] = None) -> SolverSummary:
    """Optimises a g2o 2-D pose graph (first vertex fixed) and writes it to out_path (if given).
    Raises Error (Status.FAILED, .result the SolverSummary) when the solver did not converge."""
    o = N.sized(N.PosegraphOptions)
    lib.planarvo_posegraph_options_init(ctypes.byref(o))
    o.max_iterations, o.init = max_iterations, int(init)
    cb = _Callback(log, N.LOG_FN)
    o.log = cb.c
    s = N.sized(N.SolverSummary)
    status = lib.planarvo_posegraph_optimize(_path(in_path), None if out_path is None else _path(out_path),
                                             ctypes.byref(o), ctypes.byref(s))
    cb.reraise()
    summary = SolverSummary._from_c(s)
    _check(status, summary)
    return summary
