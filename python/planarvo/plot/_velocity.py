"""The velocity figures: time series of the estimated against the reference velocity, and the
paper's Figure 14, 2-D histograms of estimated against true velocity with the fitted line."""
from __future__ import annotations

from typing import List, Sequence

import numpy as np
from matplotlib.colors import LogNorm

from . import _style as S
from ._motion import Velocities, fit_line


def velocity_figure(est: Velocities, ref: Velocities, ref_label: str, ref_key: str,
                    out_dir: str, formats: Sequence[str]) -> List[str]:
    """Forward and angular velocity over time, two stacked axes sharing time."""
    fig, (a1, a2) = S.figure(5.0, 2, 1, sharex=True, margins=dict(left=0.1, bottom=0.1, top=0.86, hspace=0.12))
    for ax, e, r, unit, name in ((a1, est.vx, ref.vx, "m/s", "forward velocity $v_x$"),
                                 (a2, est.omega, ref.omega, "rad/s", r"angular velocity $\omega$")):
        ax.plot(ref.t, r, color=S.COLORS[ref_key], lw=2.2, alpha=0.6, label=ref_label)
        ax.plot(est.t, e, color=S.COLORS["estimate"], lw=0.9, label="visual odometry")
        ax.set_ylabel("%s (%s)" % (name, unit))
    a1.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=2, frameon=False)
    a2.set_xlabel("time (s)")
    a1.set_title("Velocity over each frame interval", loc="left")
    return S.save(fig, out_dir, "velocity", formats)


def _hist_panel(fig, ax, true: np.ndarray, est: np.ndarray, unit: str, name: str) -> None:
    ok = np.isfinite(true) & np.isfinite(est)
    x, y = true[ok], est[ok]
    lo, hi = float(min(x.min(), y.min())), float(max(x.max(), y.max()))
    pad = 0.05 * (hi - lo) if hi > lo else 0.1
    lim = (lo - pad, hi + pad)
    ax.grid(False)  # the style's grid under a pcolormesh (matplotlib deprecates removing it there)
    _, _, _, img = ax.hist2d(x, y, bins=70, range=[lim, lim], cmap="viridis", norm=LogNorm(), cmin=1)
    fig.colorbar(img, ax=ax, label="intervals", fraction=0.046, pad=0.04)
    ax.plot(lim, lim, color="black", ls=":", lw=1.2, label="y = x", zorder=3)
    f = fit_line(x, y)
    if f is not None:
        xs = np.array(lim)
        ax.plot(xs, f.slope * xs + f.intercept, color="#d62728", lw=0.9, alpha=0.8, zorder=2,
                label="fit: slope %.4f\nintercept %.1e %s" % (f.slope, f.intercept, unit))
    ax.set_xlim(lim)
    ax.set_ylim(lim)
    ax.set_aspect("equal")
    ax.set_xlabel("true %s (%s)" % (name, unit))
    ax.set_ylabel("estimated %s (%s)" % (name, unit))
    ax.legend(loc="upper left", fontsize=8, handlelength=1.5)


def velocity_hist_figure(est: Velocities, truth: Velocities, out_dir: str, formats: Sequence[str]) -> List[str]:
    """Estimated against true velocity, linear and angular side by side, with the least-squares
    line (with intercept) and y = x."""
    fig, (a1, a2) = S.figure(3.4, 1, 2, margins=dict(left=0.09, right=0.93, bottom=0.15, top=0.87, wspace=0.75))
    _hist_panel(fig, a1, truth.vx, est.vx, "m/s", "$v_x$")
    _hist_panel(fig, a2, truth.omega, est.omega, "rad/s", r"$\omega$")
    fig.suptitle("Estimated against true velocity (least-squares line with intercept)", fontsize=10.5)
    return S.save(fig, out_dir, "velocity_hist", formats)
