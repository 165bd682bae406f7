"""The trajectory figure: visual odometry against wheel odometry and ground truth, x-y in metres."""
from __future__ import annotations

from typing import List, Optional, Sequence, Tuple

import numpy as np

from . import _style as S
from ._motion import relative_to_first


def _finite(poses: np.ndarray) -> np.ndarray:
    return poses[np.all(np.isfinite(poses), axis=1)]


def trajectory_figure(estimate: np.ndarray, references: Sequence[Tuple[str, str, Optional[np.ndarray]]],
                      out_dir: str, formats: Sequence[str]) -> List[str]:
    """estimate: (N, 3) poses of the trajectory; references: (label, colour key, (M, 3) poses or
    None) over the same frames. Each curve is drawn in its own first pose's frame, so that all
    start at the origin heading +x."""
    fig, ax = S.figure(5.6, margins=dict(left=0.09, right=0.98, bottom=0.09, top=0.93))
    curves = [(lab, key, _finite(p)) for lab, key, p in references if p is not None]
    curves = [c for c in curves if len(c[2])]
    curves.append(("visual odometry", "estimate", estimate))
    for label, key, poses in curves:
        p = relative_to_first(poses)
        style = {"estimate": dict(lw=1.2, zorder=4), "groundtruth": dict(lw=3.2, alpha=0.55, zorder=2),
                 "odometry": dict(lw=1.2, ls="--", zorder=3)}[key]
        ax.plot(p[:, 0], p[:, 1], color=S.COLORS[key], label=label, **style)
        ax.plot(p[-1, 0], p[-1, 1], marker="s", ms=6, color=S.COLORS[key], mec="black", mew=0.6,
                ls="none", zorder=4)
    ax.plot(0, 0, marker="o", ms=7, color="white", mec="black", mew=1.2, ls="none", zorder=6, label="start")
    ax.plot([], [], marker="s", ms=6, color="lightgrey", mec="black", mew=0.6, ls="none", label="end (each)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Trajectory, each curve in its first pose's frame (starts at the origin heading +x)")
    ax.legend(loc="best")
    return S.save(fig, out_dir, "trajectory", formats)
