"""`plot track`: the trajectory, velocity, velocity-histogram and tracking figures of a run, and
with the local plane the body's roll against the yaw rate and its pitch over time."""
from __future__ import annotations

import sys
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from ._errors import InputError
from ._io import read_dataset, read_plane, read_stats, read_tum
from ._motion import match_frames, velocities


def _note(text: str) -> None:
    print("note: " + text, file=sys.stderr)


def _bag_hint(series) -> str:
    return " (a bag's odometry and ground truth need --odom-topic, --groundtruth-topic)" if series.is_bag else ""


def plot_track(dataset: str, trajectory: str, stats: Optional[str], out_dir: str,
               formats: Sequence[str], options: Optional[Dict[str, Any]] = None) -> List[str]:
    """Writes the figures, returns their paths (options: planarvo.Dataset's bag keywords, as the
    track that wrote the trajectory was given). Raises InputError for bad input."""
    from . import _trajectory, _velocity  # noqa: F401  (matplotlib only once the input is read)
    traj = read_tum(trajectory)
    st = read_stats(stats) if stats else None
    series = read_dataset(dataset, options)
    frames = match_frames(traj, series)
    times = series.times[frames]
    if np.any(np.diff(times) <= 0):  # two poses matched to one frame
        k = int(np.nonzero(np.diff(times) <= 0)[0][0]) + 1
        raise InputError("%s pose %d: time %.9f matches the same frame as the pose before it"
                         % (trajectory, k + 1, traj.stamps[k]))
    first, last = int(frames[0]), int(frames[-1])
    span = slice(first, last + 1)
    written = _trajectory.trajectory_figure(
        traj.poses, [("ground truth", "groundtruth", None if series.groundtruth is None else series.groundtruth[span]),
                     ("wheel odometry", "odometry", None if series.odometry is None else series.odometry[span])],
        out_dir, formats)
    est = velocities(times, traj.poses)
    if series.groundtruth is not None:
        ref, ref_label, ref_key = series.groundtruth, "ground truth", "groundtruth"
    elif series.odometry is not None:
        ref, ref_label, ref_key = series.odometry, "wheel odometry", "odometry"
    else:
        ref = None
    if ref is not None and len(traj.stamps) > 1:
        written += _velocity.velocity_figure(est, velocities(times, ref[frames]), ref_label, ref_key, out_dir, formats)
    elif len(traj.stamps) < 2:
        _note("the trajectory %s has one pose: no velocities to plot" % trajectory)
    else:
        _note("no ground truth and no odometry in %s: velocity left out%s" % (dataset, _bag_hint(series)))
    if series.groundtruth is None:
        _note("no ground truth in %s: velocity_hist left out%s" % (dataset, _bag_hint(series)))
    elif len(traj.stamps) > 2:
        written += _velocity.velocity_hist_figure(est, velocities(times, series.groundtruth[frames]), out_dir, formats)
    if st is not None:
        from . import _tracking
        written += _tracking.tracking_figure(st, st["timestamp"] - series.time_origin_s, out_dir, formats)
        from . import _plane
        if _plane.has_attitude(st):
            truth = read_plane(dataset) if not series.is_bag else None
            written += _plane.lean_figure(st, truth, out_dir, formats)
            written += _plane.pitch_figure(st, st["timestamp"] - series.time_origin_s, truth, series.time_origin_s,
                                           out_dir, formats)
    return written
