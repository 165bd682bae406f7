"""The floor mosaic (planarvo/mosaic.h): the ground under a trajectory as one 8-bit image,
placed as ROS map_server places a map."""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from . import _native as N
from ._camera import Extrinsics
from ._context import Context
from ._dataset import Dataset
from ._errors import _check
from ._handle import _Handle
from ._native import lib
from ._se2 import _se2_array
from ._util import ArrayLike, NDArray, PathLike, ProgressFn, _Callback, _path


@dataclass(frozen=True)
class MosaicInfo:
    width: int
    height: int
    resolution: float     # metres per pixel
    origin: Tuple[float, float]  # the lower-left corner of the lower-left pixel, metres
    frames_given: int
    frames_used: int
    covered_pixels: int
    gain_min: float
    gain_max: float
    peak_tile_bytes: int
    seconds_decode: float
    seconds_warp: float
    seconds_blend: float
    seconds_total: float


class Mosaic(_Handle):
    """Built by build_mosaic. image: (height, width) uint8, 0 where no frame saw the ground; row 0
    is the top (+y), columns run along +x; pixel (col, row) covers x in origin[0] + [col, col + 1)
    * resolution, y in origin[1] + [height - 1 - row, height - row) * resolution."""
    _destroy_name = "planarvo_mosaic_destroy"

    @property
    def info(self) -> MosaicInfo:
        i = N.sized(N.MosaicInfo)
        _check(lib.planarvo_mosaic_info_get(self._h(), ctypes.byref(i)))
        return MosaicInfo(i.width, i.height, i.resolution, (i.origin_x, i.origin_y), i.frames_given, i.frames_used,
                          i.covered_pixels, i.gain_min, i.gain_max, i.peak_tile_bytes, i.seconds_decode,
                          i.seconds_warp, i.seconds_blend, i.seconds_total)

    @property
    def image(self) -> NDArray[np.uint8]:
        """A copy of the 8-bit image."""
        img = N.Image()
        _check(lib.planarvo_mosaic_image(self._h(), ctypes.byref(img)))
        buf = (ctypes.c_uint8 * (img.stride * img.height)).from_address(img.data)
        return np.frombuffer(buf, dtype=np.uint8).reshape(img.height, img.stride)[:, :img.width].copy()

    def save(self, image_path: PathLike) -> None:
        """Writes the image (PNG for .png) and the map_server YAML beside it (same stem, .yaml)."""
        _check(lib.planarvo_mosaic_save(self._h(), _path(image_path)))

    def save_preview(self, path: PathLike) -> None:
        """Writes a contrast-stretched copy of the image for an ordinary viewer (format by extension)."""
        _check(lib.planarvo_mosaic_save_preview(self._h(), _path(path)))


def build_mosaic(context: Context, dataset: Dataset, extrinsics: Extrinsics, timestamps: Sequence[float],
                 poses: ArrayLike, resolution: float = 0.001, max_range: float = 0.0, frame_spacing: float = 0.0,
                 estimate_gain: bool = True, max_side: int = 20000,
                 progress: Optional[ProgressFn] = None, accept_unusual_extrinsics: bool = False) -> Mosaic:
    """The mosaic of the data set's frames at the robot's poses: timestamps (N,) in the data set's
    times (seconds after its first frame's stamp for a bag), poses (N, 3) or SE2s, e.g. from
    read_tum of what planarvo track wrote (subtract dataset.info.time_origin_ns * 1e-9 for a bag).
    resolution: metres per pixel; max_range: metres from the camera's foot point (0: 4 x the
    camera height); frame_spacing: metres between frames used (0: automatic, negative: every
    frame). Raises Error (INVALID_INPUT) for a time that is no frame's, no poses, or a mosaic over
    max_side pixels on a side, and InvalidArgumentError for extrinsics outside the plausible ranges
    (millimetres or degrees by mistake) unless accept_unusual_extrinsics."""
    t = np.ascontiguousarray(timestamps, dtype=np.float64)
    p = _se2_array(poses, "poses")
    if t.ndim != 1 or t.shape[0] != p.shape[0]:
        raise ValueError("timestamps: expected shape (%d,), got %s" % (p.shape[0], t.shape))
    for name, v in (("resolution", resolution), ("max_range", max_range), ("frame_spacing", frame_spacing)):
        if not np.isfinite(v):
            raise ValueError("%s must be finite" % name)
    if not (isinstance(max_side, int) and 1 <= max_side <= 2**31 - 1):
        raise ValueError("max_side must be a positive int")
    o = N.sized(N.MosaicOptions)
    lib.planarvo_mosaic_options_init(ctypes.byref(o))
    o.resolution, o.max_range, o.frame_spacing = float(resolution), float(max_range), float(frame_spacing)
    o.estimate_gain, o.max_side = int(bool(estimate_gain)), max_side
    o.accept_unusual_extrinsics = int(bool(accept_unusual_extrinsics))
    cb = _Callback(progress, N.PROGRESS_FN)
    o.progress = cb.c
    e = extrinsics._to_c()
    h = ctypes.c_void_p()
    with cb.interruptible():
        status = lib.planarvo_mosaic_build(context._h(), dataset._h(), ctypes.byref(e),
                                           t.ctypes.data_as(N.P(ctypes.c_double)), p.ctypes.data_as(N.P(N.SE2)),
                                           p.shape[0], ctypes.byref(o), ctypes.byref(h))
    cb.reraise()
    _check(status)
    m = Mosaic.__new__(Mosaic)
    m._own(h)
    return m
