"""Frames: numpy arrays as planarvo_image, validated before any C call."""
from __future__ import annotations

from typing import Optional, Tuple, Union, cast

import numpy as np

from . import _native as N
from ._util import NDArray


def _image(frame: object, width: Optional[int] = None, height: Optional[int] = None,
           out: Optional[N.Image] = None) -> Tuple[N.Image, NDArray[Union[np.uint8, np.float32]]]:
    """A planarvo_image over frame's memory (no copy): uint8 (H, W) grey or (H, W, 3) BGR, or
    float32 (H, W) grey levels 0..255; any positive row stride, contiguous pixels. Raises
    ValueError with the reason for anything else, or a size other than width x height."""
    if not isinstance(frame, np.ndarray):
        raise ValueError("frame: expected a numpy array, got %s" % type(frame).__name__)
    if frame.ndim == 2:
        if frame.dtype == np.uint8:
            fmt, bpp = 0, 1  # PLANARVO_GRAY8
        elif frame.dtype == np.float32:
            fmt, bpp = 3, 4  # PLANARVO_GRAY32F
        else:
            raise ValueError("frame: a grey frame must be uint8 (or float32), got dtype %s" % frame.dtype)
        if frame.strides[1] != bpp:
            raise ValueError("frame: pixels of a row must be contiguous (column stride %d bytes, expected %d); "
                             "pass np.ascontiguousarray(frame)" % (frame.strides[1], bpp))
    elif frame.ndim == 3:
        if frame.shape[2] != 3:
            raise ValueError("frame: a colour frame must have 3 channels (BGR), got %d" % frame.shape[2])
        if frame.dtype != np.uint8:
            raise ValueError("frame: a BGR frame must be uint8, got dtype %s" % frame.dtype)
        fmt, bpp = 1, 3  # PLANARVO_BGR8
        if frame.strides[2] != 1 or frame.strides[1] != 3:
            raise ValueError("frame: pixels of a row must be contiguous BGR triples (strides %s, expected (.., 3, 1)); "
                             "pass np.ascontiguousarray(frame)" % (frame.strides[1:],))
    else:
        raise ValueError("frame: expected shape (H, W) or (H, W, 3), got %s" % (frame.shape,))
    h, w = frame.shape[0], frame.shape[1]
    if h == 0 or w == 0:
        raise ValueError("frame: empty (shape %s)" % (frame.shape,))
    if frame.ndim == 2 and (frame.strides[0] % bpp or not frame.flags.aligned):
        raise ValueError("frame: a float32 frame's rows must be aligned to 4 bytes (row stride %d bytes); "
                         "pass np.ascontiguousarray(frame)" % frame.strides[0])
    if frame.strides[0] < w * bpp:
        raise ValueError("frame: rows must be in increasing memory order without overlap (row stride %d bytes)"
                         % frame.strides[0])
    if (width is not None and w != width) or (height is not None and h != height):
        # Every caller gives both width and height (%d of None would raise TypeError).
        raise ValueError("frame: %dx%d does not match the camera's %dx%d" % (w, h, cast(int, width), cast(int, height)))
    image = out if out is not None else N.Image()
    image.data, image.width, image.height, image.stride, image.format = frame.ctypes.data, w, h, frame.strides[0], fmt
    return image, frame
