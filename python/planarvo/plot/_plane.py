"""The local plane's figures (the paper's section 6.4), from the statistics of `track --local-plane
--stats`: Figure 18, the body's roll against the angular velocity with the least-squares line
(the vehicle's lean: the slope is the roll per yaw rate), and Figure 19, the body's pitch over
time with its standard deviation, the data set's true attitude (plane.txt, when the simulator wrote
one) beside both, and the frames where the camera's mounting was found changed."""
from __future__ import annotations

import math
from typing import List, Optional, Sequence

import numpy as np

from . import _style as S
from ._io import Stats, degrees
from ._motion import fit_line


def has_attitude(stats: Stats) -> bool:
    """The statistics hold an attitude on some tracked frame (track ran with --local-plane)."""
    return "roll" in stats.columns and bool(np.isfinite(stats["roll"]).any())


def _slope_sigma(x: np.ndarray, y: np.ndarray, slope: float, intercept: float) -> float:
    """The least-squares slope's standard error from the residuals' scatter."""
    if len(x) < 3:
        return math.inf
    r = y - (slope * x + intercept)
    dx = x - x.mean()
    return math.sqrt(float(r @ r) / (len(x) - 2) / float(dx @ dx))


def lean_figure(stats: Stats, truth: Optional[np.ndarray], out_dir: str, formats: Sequence[str]) -> List[str]:
    """Figure 18: roll (degrees) against the angular velocity (degrees/s) over the tracked frames,
    with the fitted line; truth: (n, 3) time, roll, pitch (radians) matched by time, or None."""
    tracked = np.isin(stats["status"], ("ok", "degraded")) & np.isfinite(stats["roll"])
    w, roll = degrees(stats["omega"][tracked]), degrees(stats["roll"][tracked])
    fig, ax = S.figure(4.2, margins=dict(left=0.11, right=0.97, bottom=0.12, top=0.9))
    if truth is not None:
        k = np.searchsorted(truth[:, 0], stats["timestamp"][tracked] - 1e-6)
        ok = k < len(truth)
        ax.scatter(w[ok], degrees(truth[k[ok], 1]), s=10, color=S.COLORS["truth"], alpha=0.35, lw=0,
                   label="true roll (plane.txt)")
    ax.scatter(w, roll, s=4, color=S.COLORS["estimate"], label="estimated roll")
    f = fit_line(w, roll)
    if f is not None:
        sigma = _slope_sigma(w, roll, f.slope, f.intercept)
        xs = np.array([w.min(), w.max()])
        ax.plot(xs, f.slope * xs + f.intercept, color="#d62728", lw=1.2,
                label="fit: %.4f $\\pm$ %.4f deg per deg/s, offset %.3f deg" % (f.slope, sigma, f.intercept))
    ax.axhline(0.0, color="black", lw=0.5)
    ax.set_xlabel(r"angular velocity $\omega$ (deg/s)")
    ax.set_ylabel("body roll (deg)")
    ax.legend(loc="best", fontsize=8, frameon=False)
    ax.set_title("The body's roll against the yaw rate (%d frames)" % len(w), loc="left")
    return S.save(fig, out_dir, "body_roll", formats)


def pitch_figure(stats: Stats, times: np.ndarray, truth: Optional[np.ndarray], time_origin: float, out_dir: str,
                 formats: Sequence[str]) -> List[str]:
    """Figure 19: pitch (degrees) over time with its 1-sigma band; times: the rows' times in
    seconds (the data set's clock); truth as for lean_figure, its times on the rows' clock."""
    tracked = np.isin(stats["status"], ("ok", "degraded")) & np.isfinite(stats["pitch"])
    t = times[tracked]
    pitch, sigma = degrees(stats["pitch"][tracked]), degrees(stats["sigma_pitch"][tracked])
    fig, ax = S.figure(3.6, margins=dict(left=0.1, right=0.97, bottom=0.13, top=0.88))
    if truth is not None:
        ax.plot(truth[:, 0] - time_origin, degrees(truth[:, 2]), color=S.COLORS["truth"], lw=2.2, alpha=0.6,
                label="true pitch (plane.txt)")
    ax.fill_between(t, pitch - sigma, pitch + sigma, color=S.COLORS["estimate"], alpha=0.25, lw=0)
    ax.plot(t, pitch, color=S.COLORS["estimate"], lw=0.9, label="estimated pitch ($\\pm 1\\sigma$)")
    changed = stats["mounting_changed"] == 1 if "mounting_changed" in stats.columns else np.zeros(len(times), bool)
    for k, tc in enumerate(times[changed]):
        ax.axvline(tc, color="#d62728", lw=1.0, ls="--", label="mounting changed" if k == 0 else None)
    ax.axhline(0.0, color="black", lw=0.5)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("body pitch (deg)")
    ax.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=3, fontsize=8, frameon=False)
    ax.set_title("The body's pitch", loc="left")
    return S.save(fig, out_dir, "body_pitch", formats)
