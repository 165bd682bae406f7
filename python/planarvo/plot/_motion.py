"""Numbers behind the track figures, no drawing: trajectory lines matched to data-set frames,
velocities from consecutive poses, the fitted slope of estimated against true, status spans."""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional, Tuple

import numpy as np

from ._errors import InputError
from ._io import Series, Trajectory

TIME_TOLERANCE = 1e-4  # s: a trajectory line belongs to the frame within this of its time


def wrap(a):
    return np.arctan2(np.sin(a), np.cos(a))


def match_frames(traj: Trajectory, series: Series) -> np.ndarray:
    """The data-set frame index of every trajectory pose (by time, within TIME_TOLERANCE; a
    trajectory may skip frames). Stamps are the data set's times plus its time origin (a bag's
    first stamp; 0 for a folder). Raises InputError naming the first pose that matches no frame."""
    t = traj.stamps - series.time_origin_s
    times = series.times
    j = np.clip(np.searchsorted(times, t), 1, len(times) - 1) if len(times) > 1 else np.zeros(len(t), int)
    if len(times) > 1:
        left_closer = np.abs(t - times[j - 1]) <= np.abs(t - times[j])
        j = np.where(left_closer, j - 1, j)
    bad = np.nonzero(np.abs(times[j] - t) > TIME_TOLERANCE)[0]
    if len(bad):
        k = int(bad[0])
        raise InputError("%s pose %d: time %.9f matches no frame of %s (nearest frame %.9f, %.3g s away; "
                         "tolerance %g s)" % (traj.path, k + 1, traj.stamps[k], series.path,
                                              times[j[k]] + series.time_origin_s, abs(times[j[k]] - t[k]),
                                              TIME_TOLERANCE))
    return j


def relative_to_first(poses: np.ndarray) -> np.ndarray:
    """Poses (N, 3) expressed in the frame of the first: it becomes the origin, heading +x."""
    p0 = poses[0]
    c, s = np.cos(p0[2]), np.sin(p0[2])
    d = poses[:, :2] - p0[:2]
    return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1], wrap(poses[:, 2] - p0[2])])


def relative_motions(poses: np.ndarray) -> np.ndarray:
    """Frame-to-frame motions T_{k-1}^-1 T_k of poses (N, 3), in the earlier pose's frame: (N-1, 3)."""
    d = poses[1:, :2] - poses[:-1, :2]
    c, s = np.cos(poses[:-1, 2]), np.sin(poses[:-1, 2])
    return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1],
                            wrap(poses[1:, 2] - poses[:-1, 2])])


@dataclass
class Velocities:
    """Per interval between consecutive trajectory lines: its end time t (data-set clock), vx
    (forward, m/s), vy (left, m/s), omega (rad/s, positive turning left)."""
    t: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    omega: np.ndarray


def velocities(times: np.ndarray, poses: np.ndarray) -> Velocities:
    """Velocities over consecutive poses: relative motion in the earlier pose's frame over dt.
    Intervals with dt <= 0 or a pose that is NaN give NaN."""
    m = relative_motions(poses)
    dt = np.diff(times)
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.where((dt > 0)[:, None], m / dt[:, None], np.nan)
    return Velocities(times[1:], v[:, 0], v[:, 1], v[:, 2])


@dataclass
class LineFit:
    """Least-squares line est = slope * true + intercept, over n finite pairs."""
    slope: float
    intercept: float
    n: int


def fit_line(true: np.ndarray, est: np.ndarray) -> Optional[LineFit]:
    """The least-squares line (with intercept) of est against true; None with fewer than 2
    finite pairs or no spread in true."""
    ok = np.isfinite(true) & np.isfinite(est)
    x, y = true[ok], est[ok]
    if len(x) < 2:
        return None
    dx = x - x.mean()
    sxx = float(dx @ dx)
    if sxx <= 0.0:
        return None
    slope = float(dx @ (y - y.mean())) / sxx
    return LineFit(slope, float(y.mean() - slope * x.mean()), int(len(x)))


def status_runs(statuses: np.ndarray, which: str) -> List[Tuple[int, int]]:
    """Runs of consecutive rows whose status is `which`: (first row, last row) inclusive."""
    hit = np.concatenate([[False], np.asarray(statuses) == which, [False]]).astype(np.int8)
    edges = np.diff(hit)
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0] - 1
    return list(zip(starts.tolist(), ends.tolist()))


def status_spans(times: np.ndarray, statuses: np.ndarray, which: str) -> List[Tuple[float, float]]:
    """The time spans of status_runs, each widened by half a frame interval on either side so that
    a single frame covers its own slot: (start, end) in the times' clock."""
    half = 0.5 * float(np.median(np.diff(times))) if len(times) > 1 else 0.5
    return [(times[a] - half, times[b] + half) for a, b in status_runs(statuses, which)]
