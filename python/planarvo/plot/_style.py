"""One look for every figure: sizes, fonts, colours, and saving in the formats asked for.

Figures are 7.5 in wide at 150 dpi (1125 px), 10 pt text: a column of a paper at 100 % zoom."""
from __future__ import annotations

import os
from typing import List, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

WIDTH_IN = 7.5
DPI = 150
FORMATS = ("png", "pdf", "svg")

# One colour per source, the same in every figure.
COLORS = {
    "estimate": "#1f77b4",     # visual odometry / the calibration
    "groundtruth": "#2ca02c",
    "odometry": "#ff7f0e",
    "truth": "#2ca02c",
    "lost": "#d62728",
    "degraded": "#ffbf00",
    "skipped": "#7f7f7f",
    "outlier": "#d62728",
}

RC = {
    "font.size": 10,
    "axes.titlesize": 10.5,
    "axes.labelsize": 10,
    "legend.fontsize": 8.5,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.6,
    "lines.linewidth": 1.2,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.framealpha": 0.85,
    "figure.dpi": DPI,
    "savefig.dpi": DPI,
    "svg.fonttype": "none",
    "pdf.fonttype": 42,
}
plt.rcParams.update(RC)


def figure(height_in: float, nrows: int = 1, ncols: int = 1, margins=None, **kwargs):
    """A figure WIDTH_IN wide with a grid of axes (plt.subplots' arguments otherwise). margins:
    subplots_adjust's left, right, bottom, top, wspace, hspace (fractions of the figure), fixed per
    figure rather than computed by tight_layout, which costs ~0.3 s a figure."""
    fig, axes = plt.subplots(nrows, ncols, figsize=(WIDTH_IN, height_in), **kwargs)
    m = dict(left=0.1, right=0.97, bottom=0.1, top=0.92)
    m.update(margins or {})
    fig.subplots_adjust(**m)
    return fig, axes


def parse_formats(text: str) -> List[str]:
    """'png,pdf' -> ['png', 'pdf']; raises ValueError naming an unknown one."""
    out = []
    for f in (s.strip().lower() for s in text.split(",")):
        if f not in FORMATS:
            raise ValueError("--format: %r is not one of %s" % (f, ", ".join(FORMATS)))
        if f not in out:
            out.append(f)
    if not out:
        raise ValueError("--format: no format given")
    return out


def save(fig, out_dir: str, stem: str, formats: Sequence[str]) -> List[str]:
    """Writes fig as out_dir/stem.FMT for each format, closes it, returns the paths."""
    paths = []
    for fmt in formats:
        path = os.path.join(out_dir, "%s.%s" % (stem, fmt))
        # zlib level 1: a third of the default's encoding time for PNGs ~20 % larger
        fig.savefig(path, format=fmt, **({"pil_kwargs": {"compress_level": 1}} if fmt == "png" else {}))
        paths.append(path)
    plt.close(fig)
    return paths


def close(fig) -> None:
    plt.close(fig)
