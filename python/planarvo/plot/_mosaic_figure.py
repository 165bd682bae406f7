"""The mosaic figure: one or more floor mosaics (planarvo mosaic's image and map_server YAML) in
metric axes side by side, optionally with the trajectory drawn over them, and an optional zoom."""
from __future__ import annotations

import os
import re
from typing import List, Optional, Sequence, Tuple

import numpy as np

from . import _style as S
from ._errors import InputError
from ._io import read_tum


def read_map(image_path: str) -> Tuple[np.ndarray, float, float, float]:
    """The image (uint8) and the resolution and origin of the map_server YAML beside it."""
    yaml_path = os.path.splitext(image_path)[0] + ".yaml"
    try:
        with open(yaml_path) as f:
            text = f.read()
    except OSError as e:
        raise InputError("cannot read %s (the YAML beside the mosaic): %s" % (yaml_path, e.strerror)) from None
    res = re.search(r"^resolution:\s*(\S+)\s*$", text, re.M)
    org = re.search(r"^origin:\s*\[\s*([^,\]]+),\s*([^,\]]+),\s*([^\]]+)\]", text, re.M)
    if not res or not org:
        raise InputError("%s lacks resolution or origin: [x, y, yaw]" % yaml_path)
    if float(org.group(3)) != 0.0:
        raise InputError("%s: an origin yaw other than 0 is not drawn" % yaml_path)
    from PIL import Image
    try:
        image = np.asarray(Image.open(image_path).convert("L"))
    except OSError as e:
        raise InputError("cannot read the mosaic %s: %s" % (image_path, e)) from None
    return image, float(res.group(1)), float(org.group(1)), float(org.group(2))


def _parse_box(text: Optional[str]) -> Optional[Tuple[float, float, float, float]]:
    if not text:
        return None
    try:
        v = [float(s) for s in text.split(",")]
    except ValueError:
        raise InputError("--zoom: expected x0,y0,x1,y1 in metres, got %r" % text) from None
    if len(v) != 4 or not (v[2] > v[0] and v[3] > v[1]):
        raise InputError("--zoom: expected x0,y0,x1,y1 with x1 > x0 and y1 > y0, got %r" % text)
    return v[0], v[1], v[2], v[3]


def mosaic_figure(images: Sequence[str], titles: Sequence[str], trajectory: Optional[str], zoom: Optional[str],
                  out_dir: str, stem: str, formats: Sequence[str]) -> List[str]:
    """Each mosaic in its own panel, x and y in metres as its YAML places it (unseen pixels white)."""
    if not images:
        raise InputError("no mosaic given")
    if titles and len(titles) != len(images):
        raise InputError("--title: %d titles for %d mosaics" % (len(titles), len(images)))
    box = _parse_box(zoom)
    path = read_tum(trajectory) if trajectory else None
    maps = [read_map(p) for p in images]
    if box is None:  # the union of the mosaics' extents
        box = (min(ox for _, _, ox, _ in maps), min(oy for _, _, _, oy in maps),
               max(ox + im.shape[1] * r for im, r, ox, _ in maps), max(oy + im.shape[0] * r for im, r, _, oy in maps))
        zoomed = False
    else:
        zoomed = True
    # One display range for every panel: the first mosaic's seen pixels from 1 % to 99 %, so that
    # low-contrast ground shows its texture and the panels compare.
    seen = maps[0][0][maps[0][0] > 0]
    lo, hi = (np.percentile(seen, [1, 99]) if seen.size else (0, 255))
    n = len(images)
    panel_w = (S.WIDTH_IN * 0.9) / n
    height = panel_w * (box[3] - box[1]) / (box[2] - box[0]) + 1.0
    fig, axes = S.figure(min(max(height, 2.5), 9.0), 1, n, squeeze=False,
                         margins=dict(left=0.1, right=0.98, bottom=0.6 / height, top=1 - 0.35 / height, wspace=0.25))
    for k, (ax, (image, res, ox, oy)) in enumerate(zip(axes[0], maps)):
        h, w = image.shape
        shown = np.ma.masked_equal(image, 0)
        cmap = S.plt.get_cmap("gray").copy()
        cmap.set_bad("white")
        ax.imshow(shown, cmap=cmap, vmin=lo, vmax=max(hi, lo + 1), interpolation="nearest" if zoomed else "antialiased",
                  extent=(ox, ox + w * res, oy, oy + h * res), origin="upper")
        if path is not None:
            ax.plot(path.poses[:, 0], path.poses[:, 1], color=S.COLORS["estimate"], lw=0.9, alpha=0.9,
                    label="trajectory")
            ax.plot(path.poses[0, 0], path.poses[0, 1], marker="o", ms=5, color="white", mec="black", ls="none")
        ax.set_xlim(box[0], box[2])
        ax.set_ylim(box[1], box[3])
        ax.set_aspect("equal")
        ax.grid(False)
        ax.xaxis.set_major_locator(S.plt.MaxNLocator(4))
        ax.yaxis.set_major_locator(S.plt.MaxNLocator(5))
        ax.set_xlabel("x (m)")
        if k == 0:
            ax.set_ylabel("y (m)")
        ax.set_title(titles[k] if titles else os.path.basename(images[k]))
    if path is not None:
        axes[0][0].legend(loc="best")
    return S.save(fig, out_dir, stem, formats)
