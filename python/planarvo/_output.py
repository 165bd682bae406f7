"""Result files (docs/formats.md), written and read back by the library: TUM trajectories,
plane.txt and the per-frame statistics CSV."""
from __future__ import annotations

import ctypes
from types import TracebackType
from typing import Any, Dict, List, Optional, Sequence, Tuple, Type

import numpy as np

from . import _native as N
from ._errors import _check
from ._handle import _Handle
from ._native import lib
from ._se2 import _se2_array
from ._util import ArrayLike, NDArray, PathLike, _path


def read_tum(path: PathLike) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A TUM trajectory (planar poses only): timestamps (N,) and poses (N, 3) of (x, y, theta)."""
    n = ctypes.c_size_t()
    _check(lib.planarvo_read_tum(_path(path), None, None, 0, ctypes.byref(n)))
    t = np.zeros(n.value, dtype=np.float64)
    p = (N.SE2 * max(n.value, 1))()
    if n.value:
        _check(lib.planarvo_read_tum(_path(path), t.ctypes.data_as(N.P(ctypes.c_double)), p, n.value,
                                     ctypes.byref(n)))
    poses = np.array([(s.x, s.y, s.theta) for s in p[:n.value]], dtype=np.float64).reshape(-1, 3)
    return t, poses


def read_plane(path: PathLike) -> NDArray[np.float64]:
    """plane.txt (`planarvo track --plane-out`, the simulator's truth): (N, 5) of timestamp, roll,
    pitch, sigma_roll, sigma_pitch (radians)."""
    n = ctypes.c_size_t()
    _check(lib.planarvo_read_plane(_path(path), None, 0, ctypes.byref(n)))
    rows = (N.PlaneAttitude * max(n.value, 1))()
    if n.value:
        _check(lib.planarvo_read_plane(_path(path), rows, n.value, ctypes.byref(n)))
    return np.array([(r.timestamp, r.roll, r.pitch, r.sigma_roll, r.sigma_pitch) for r in rows[:n.value]],
                    dtype=np.float64).reshape(-1, 5)


STATS_COLUMNS = ("timestamp", "vx", "vy", "omega", "iterations", "final_cost", "inlier_fraction", "ms", "status",
                 "roll", "pitch", "sigma_roll", "sigma_pitch", "mounting_changed")


def read_stats(path: PathLike) -> Dict[str, NDArray[Any]]:
    """The per-frame statistics CSV (`planarvo track --stats`, StatsWriter) as one array per
    column, named as in the file's header (STATS_COLUMNS): float64, but iterations (int64),
    status (str) and mounting_changed (bool); roll, pitch and their sigmas NaN where a row has no
    attitude (files from before the local plane have none)."""
    table = ctypes.c_void_p()
    _check(lib.planarvo_stats_read(_path(path), ctypes.byref(table)))
    try:
        n = lib.planarvo_stats_table_size(table)
        cols: Dict[str, List[object]] = {name: [] for name in STATS_COLUMNS}
        row = N.FrameStats()
        for i in range(n):
            _check(lib.planarvo_stats_table_row(table, i, ctypes.byref(row)))
            for name in ("timestamp", "vx", "vy", "omega", "iterations", "final_cost", "inlier_fraction", "ms"):
                cols[name].append(getattr(row, name))
            cols["status"].append(row.status.decode("utf-8", "replace"))
            for name in ("roll", "pitch", "sigma_roll", "sigma_pitch"):
                cols[name].append(getattr(row, name) if row.has_attitude else np.nan)
            cols["mounting_changed"].append(bool(row.has_attitude and row.mounting_changed))
    finally:
        lib.planarvo_stats_table_free(table)
    types = {"iterations": np.int64, "status": str, "mounting_changed": bool}
    return {name: np.array(v, dtype=types.get(name, np.float64)) for name, v in cols.items()}


def write_tum(path: PathLike, timestamps: Sequence[float], poses: ArrayLike) -> None:
    """Writes a TUM trajectory: timestamps (N,), poses (N, 3) of (x, y, theta) or a list of SE2."""
    t = np.ascontiguousarray(timestamps, dtype=np.float64)
    p = _se2_array(poses, "poses")
    if t.ndim != 1 or t.shape[0] != p.shape[0]:
        raise ValueError("timestamps: expected shape (%d,), got %s" % (p.shape[0], t.shape))
    _check(lib.planarvo_write_tum(_path(path), t.ctypes.data_as(N.P(ctypes.c_double)),
                                  p.ctypes.data_as(N.P(N.SE2)), p.shape[0]))


class StatsWriter(_Handle):
    """Per-frame statistics CSV (docs/formats.md): rows are flushed as they are added to
    PATH.partial, which close() renames onto path (complete or untouched). Leaving a with-block
    by an exception, discard(), or a writer never closed (garbage collection) removes the
    partial file and leaves path as it was."""
    _destroy_name = "planarvo_stats_writer_discard"

    def __init__(self, path: PathLike):
        h = ctypes.c_void_p()
        _check(lib.planarvo_stats_writer_open(_path(path), ctypes.byref(h)))
        self._own(h)

    def add(self, timestamp: float, vx: float, vy: float, omega: float, iterations: int, final_cost: float,
            inlier_fraction: float, ms: float, status: str, attitude: Optional[Sequence[float]] = None,
            mounting_changed: bool = False) -> None:
        """One row: the robot-frame velocity over the interval ending at the frame, and the
        tracker's figures for it (status "first", "ok", "degraded", "lost", ...). With the local
        plane, attitude = (roll, pitch, sigma_roll, sigma_pitch) in radians (TrackResult.roll,
        .pitch and the square roots of attitude_covariance's diagonal) and mounting_changed;
        without, those columns stay empty."""
        a = (0.0, 0.0, 0.0, 0.0) if attitude is None else tuple(float(v) for v in attitude)
        if len(a) != 4:
            raise ValueError("attitude must be (roll, pitch, sigma_roll, sigma_pitch)")
        row = N.FrameStats(timestamp, vx, vy, omega, iterations, final_cost, inlier_fraction, ms, status.encode(),
                           attitude is not None, *a, bool(mounting_changed))
        _check(lib.planarvo_stats_writer_add(self._h(), ctypes.byref(row)))

    def close(self) -> None:
        """Completes the file (renames it onto path); raises Error when a write failed."""
        if not self.closed:
            handle = self._handle
            self._finalizer.detach()
            _check(lib.planarvo_stats_writer_close(handle))

    def discard(self) -> None:
        """Removes the partial file and leaves path as it was."""
        _Handle.close(self)

    def __exit__(self, exc_type: Optional[Type[BaseException]], exc_value: Optional[BaseException],
                 traceback: Optional[TracebackType]) -> None:
        if exc_type is None:
            self.close()
        else:
            self.discard()
