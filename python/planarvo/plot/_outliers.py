"""`plot outliers`: the pixels the tracker's robust (Huber) norm down-weighted for one frame, drawn
over its keyframe's undistorted image, beside the residual image (the paper's Figure 20)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from ._errors import InputError
from ._io import bag_options, open_dataset, read_extrinsics

# Down-weighted pixels are drawn with alpha ALPHA_MIN + (1 - ALPHA_MIN) (1 - weight): those just
# beyond the threshold faintly, the ones the norm all but ignores (|r| >> k) nearly opaque.
ALPHA_MIN = 0.15
NOT_SEEN = "#1f77b4"  # keyframe pixels whose warp leaves the live frame


@dataclass
class FrameResiduals:
    """One tracked frame's residuals (planarvo.Residuals) with what the figure says about it."""
    frame: int
    timestamp: float
    status: str
    reason: str
    keyframe_frame: int   # the frame that was the keyframe it was aligned with
    residuals: object     # planarvo.Residuals


def track_frame(dataset: str, extrinsics: str, frame: int, level: int,
                options: Optional[Dict[str, Any]] = None) -> FrameResiduals:
    """Tracks frames 0..frame of the data set (options: planarvo.Dataset's bag keywords) with the
    extrinsics and returns frame's residuals against its keyframe at `level`. Raises InputError
    for bad input or a frame without them."""
    import planarvo
    values = read_extrinsics(extrinsics).values
    try:
        with open_dataset(dataset, options) as ds, planarvo.Context() as ctx:
            if not 0 <= frame < len(ds):
                raise InputError("--frame %d: the data set has frames 0..%d" % (frame, len(ds) - 1))
            with planarvo.Tracker(ctx, ds.info.camera, planarvo.Extrinsics(*map(float, values))) as tracker:
                keyframe = 0
                for k in range(frame + 1):
                    t = ds.frame_data(k).timestamp
                    result = tracker.track(ds.frame(k), t)
                    if k < frame and result.keyframe:
                        keyframe = k
                try:
                    res = tracker.residuals(level)
                except planarvo.Error as e:
                    raise InputError("frame %d (%s%s) has no residuals: %s" % (
                        frame, result.status.name.lower(), ": " + result.reason if result.reason else "",
                        e.message)) from None
    except planarvo.Error as e:
        raise InputError("cannot track %s: %s" % (dataset, e.message)) from None
    return FrameResiduals(frame, t, result.status.name.lower(), result.reason, keyframe, res)


def _overlay(res) -> np.ndarray:
    """RGBA (H, W, 4): down-weighted pixels in the outlier colour with alpha by 1 - weight,
    keyframe pixels that left the live frame in NOT_SEEN, everything else transparent."""
    from matplotlib.colors import to_rgb

    from . import _style as S
    w = res.weight
    rgba = np.zeros(w.shape + (4,), dtype=np.float32)
    out = (w > 0) & (w < 1)
    rgba[out, :3] = to_rgb(S.COLORS["outlier"])
    rgba[out, 3] = ALPHA_MIN + (1.0 - ALPHA_MIN) * (1.0 - w[out])
    unseen = (w == 0) & np.isfinite(res.intensity)
    rgba[unseen, :3] = to_rgb(NOT_SEEN)
    rgba[unseen, 3] = 0.45
    return rgba


def outliers_figure(fr: FrameResiduals, out_dir: str, formats: Sequence[str]) -> List[str]:
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    from . import _style as S
    res = fr.residuals
    h, w = res.weight.shape
    valid = res.weight > 0
    n_valid = int(np.count_nonzero(valid))
    n_out = int(np.count_nonzero(valid & (res.weight < 1)))
    inliers = 1.0 - n_out / n_valid if n_valid else math.nan
    panel_w = 3.05
    height = panel_w * h / w + 1.5
    fig, axes = S.figure(height, 1, 2, margins=dict(left=0.075, right=0.895, bottom=0.68 / height,
                                                    top=1 - 0.62 / height, wspace=0.1))
    no_image = ~np.isfinite(res.intensity)
    # Left: the keyframe in grey, the down-weighted pixels over it.
    ax = axes[0]
    ax.imshow(np.ma.masked_invalid(res.intensity), cmap=plt.get_cmap("gray").with_extremes(bad="black"),
              vmin=0, vmax=255, interpolation="nearest")
    ax.imshow(_overlay(res), interpolation="nearest")
    ax.set_title("keyframe %d: down-weighted pixels" % fr.keyframe_frame, loc="left")
    ax.set_ylabel("v (px)")
    # Right: the residual, symmetric about 0; pixels without one light grey (black: no image).
    ax = axes[1]
    background = np.where(no_image, 0, 1).astype(float)
    ax.imshow(background, cmap=ListedColormap(["black", "#d0d0d0"]), vmin=0, vmax=1, interpolation="nearest")
    span = 4.0 * res.threshold
    im = ax.imshow(np.ma.masked_where(~valid, res.residual), cmap="RdBu_r", vmin=-span, vmax=span,
                   interpolation="nearest")
    ax.set_title("residual r = e$^a$I$_{live}$(w(p)) + b \u2212 I$_{key}$(p)", loc="left")
    ax.tick_params(labelleft=False)
    for ax in axes:
        ax.grid(False)
        ax.set_xlabel("u (px)")
        for side in ("top", "right"):
            ax.spines[side].set_visible(True)
    pos = axes[1].get_position()
    cax = fig.add_axes([pos.x1 + 0.012, pos.y0, 0.014, pos.height])
    cax.grid(False)
    cb = fig.colorbar(im, cax=cax, extend="both")
    cb.set_label("r (grey levels); lines at \u00b1k")
    for sign in (-1, 1):
        cb.ax.axhline(sign * res.threshold, color="black", lw=1.2)
    fig.legend(handles=[
        Patch(color=S.COLORS["outlier"], label="|r| > k, alpha by 1 \u2212 weight"),
        Patch(color=NOT_SEEN, alpha=0.45, label="outside the live frame"),
        Patch(color="#d0d0d0", label="no residual"),
        Patch(color="black", label="no keyframe image")],
        loc="lower left", bbox_to_anchor=(0.065, 0.0), ncol=4, frameon=False, handlelength=1.2, columnspacing=1.2)

    status = fr.status + (" (%s)" % fr.reason if fr.reason else "")
    fig.suptitle("Frame %d, t = %.3f s, %s, level %d (%d \u00d7 %d)\n"
                 "%.1f %% of %s valid pixels within the Huber threshold k = %.2f grey levels"
                 % (fr.frame, fr.timestamp, status, res.level, w, h, 100.0 * inliers, format(n_valid, ","),
                    res.threshold), x=0.075, y=0.99, ha="left", va="top", fontsize=10.5, linespacing=1.4)
    return S.save(fig, out_dir, "outliers_%d" % fr.frame, formats)


def plot_outliers(args) -> List[str]:
    from ._style import parse_formats
    formats = parse_formats(args.format)
    if args.frame < 1:
        raise InputError("--frame must be 1 or more (frame 0 is the first keyframe: nothing to compare with)")
    if args.level < 0:
        raise InputError("--level must be 0 or more")
    fr = track_frame(args.dataset, args.extrinsics, args.frame, args.level, bag_options(args))
    return outliers_figure(fr, args.out_dir, formats)
