"""The tracking figure: per-frame status, iterations, residual cost and engine time over time,
with the spans of lost and degraded frames shaded and skipped frames marked."""
from __future__ import annotations

from typing import List, Sequence

import numpy as np
from matplotlib.patches import Patch

from . import _style as S
from ._io import Stats
from ._motion import status_runs, status_spans

STATUS_LEVELS = ("first", "ok", "degraded", "lost", "skipped")
STATUS_COLORS = {"first": "#1f77b4", "ok": "#1f77b4", "degraded": S.COLORS["degraded"],
                 "lost": S.COLORS["lost"], "skipped": S.COLORS["skipped"]}


def _shade(ax, times: np.ndarray, status: np.ndarray) -> None:
    for which, alpha in (("lost", 0.25), ("degraded", 0.35)):
        for a, b in status_spans(times, status, which):
            ax.axvspan(a, b, color=S.COLORS[which], alpha=alpha, lw=0, zorder=0)
    for a, b in status_runs(status, "skipped"):
        for k in range(a, b + 1):
            ax.axvline(times[k], color=S.COLORS["skipped"], lw=0.8, ls="--", zorder=0)


def tracking_figure(stats: Stats, times: np.ndarray, out_dir: str, formats: Sequence[str]) -> List[str]:
    """times: the rows' times in seconds (the data set's clock)."""
    status = stats["status"]
    fig, axes = S.figure(6.4, 4, 1, sharex=True, gridspec_kw={"height_ratios": [0.8, 1, 1, 1]},
                         margins=dict(left=0.12, right=0.8, bottom=0.08, top=0.94, hspace=0.15))
    ax = axes[0]
    level = {s: k for k, s in enumerate(STATUS_LEVELS)}
    y = np.array([level.get(s, len(STATUS_LEVELS)) for s in status])
    colors = [STATUS_COLORS.get(s, "black") for s in status]
    ax.scatter(times, y, c=colors, s=6, marker="|", linewidths=1.2)
    ax.set_yticks(range(len(STATUS_LEVELS)))
    ax.set_yticklabels(STATUS_LEVELS)
    ax.set_ylim(-0.6, len(STATUS_LEVELS) - 0.4)
    ax.set_ylabel("status")
    tracked = np.isin(status, ("ok", "degraded"))
    panels = ((axes[1], "iterations", "iterations"),
              (axes[2], "final_cost", "residual cost\nper pixel"),
              (axes[3], "ms", "engine time (ms)"))
    for a, col, label in panels:
        v = np.where(tracked | (col == "ms"), stats[col], np.nan)
        a.plot(times, v, color=S.COLORS["estimate"], lw=0.8, marker=".", ms=2)
        a.set_ylabel(label)
    for a in axes:
        _shade(a, times, status)
    axes[-1].set_xlabel("time (s)")
    counts = {s: int(np.sum(status == s)) for s in ("lost", "degraded", "skipped")}
    handles = [Patch(color=S.COLORS["lost"], alpha=0.4, label="lost (%d)" % counts["lost"]),
               Patch(color=S.COLORS["degraded"], alpha=0.5, label="degraded (%d)" % counts["degraded"]),
               Patch(facecolor="white", edgecolor=S.COLORS["skipped"], ls="--",
                     label="skipped (%d)" % counts["skipped"])]
    axes[0].legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    axes[0].set_title("Per-frame tracking of %d frames" % len(status), loc="left")
    return S.save(fig, out_dir, "tracking", formats)
