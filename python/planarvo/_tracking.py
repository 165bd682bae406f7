"""Visual odometry: the Tracker, its options and its per-frame TrackResult."""
from __future__ import annotations

import ctypes
import enum
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from . import _native as N
from ._camera import Camera, Extrinsics
from ._context import Context
from ._errors import _check
from ._frame import _image
from ._handle import _Handle
from ._native import lib
from ._se2 import SE2
from ._util import _c_options, _require


class TrackStatus(enum.IntEnum):
    """planarvo_track_status."""
    FIRST = 0
    OK = 1
    DEGRADED = 2
    LOST = 3


@dataclass
class TrackerOptions:
    """planarvo_tracker_options; None keeps the library's default (see planarvo.h)."""
    levels: Optional[int] = None
    finest_level: Optional[int] = None
    max_iterations: Optional[int] = None
    keyframe_overlap: Optional[float] = None
    estimate_brightness: Optional[bool] = None
    level0_subsample: Optional[int] = None


def _tracker_options(options: Optional[TrackerOptions]) -> N.TrackerOptions:
    return _c_options(N.TrackerOptions, "planarvo_tracker_options_init", options)


@dataclass
class TrackResult:
    """One tracked frame. motion: the frame's robot pose in the previous frame's robot frame;
    covariance: (3, 3) of motion (x, y, theta); pose: relative to the first frame; ms: the
    engine's time for the frame (upload, undistortion, pyramid, tracking)."""
    status: TrackStatus
    reason: str
    motion: SE2
    covariance: np.ndarray
    pose: SE2
    iterations: Tuple[int, ...]
    levels_used: int
    final_cost: float
    inlier_fraction: float
    overlap: float
    keyframe: bool
    ms: float


class Tracker(_Handle):
    """Dense planar visual odometry (planarvo_tracker): tracks each frame against a keyframe.

    camera: the distorted camera the frames come from; extrinsics: the camera on the robot. The
    context must stay open while the tracker is used (the tracker keeps a reference to it)."""
    _destroy_name = "planarvo_tracker_destroy"

    def __init__(self, context: Context, camera: Camera, extrinsics: Extrinsics,
                 options: Optional[TrackerOptions] = None):
        self.camera = _require(camera, Camera, "camera")
        self.extrinsics = _require(extrinsics, Extrinsics, "extrinsics")
        o = _tracker_options(options)
        h = ctypes.c_void_p()
        _check(lib.planarvo_tracker_create(context._h(), ctypes.byref(camera._to_c()), ctypes.byref(extrinsics._to_c()),
                                           ctypes.byref(o), ctypes.byref(h)))
        self._own(h, context)
        self._image = N.Image()
        self._result = N.sized(N.TrackResult)

    def track(self, frame: np.ndarray, timestamp: float) -> TrackResult:
        """Tracks one frame: uint8 (H, W) grey or (H, W, 3) BGR (or float32 grey), the camera's
        size, any row stride; timestamps in seconds, increasing. A frame that cannot be tracked
        is not an error: the result's status is LOST or DEGRADED with the reason."""
        image, keep = _image(frame, self.camera.width, self.camera.height, self._image)
        r = self._result
        _check(lib.planarvo_tracker_track(self._h(), ctypes.byref(image), float(timestamp), ctypes.byref(r)))
        del keep
        return TrackResult(TrackStatus(r.status), r.reason.decode() if r.reason else "",
                           SE2(r.motion.x, r.motion.y, r.motion.theta),
                           np.frombuffer(r.covariance, dtype=np.float64).reshape(3, 3).copy(),
                           SE2(r.pose.x, r.pose.y, r.pose.theta), tuple(r.iterations), r.levels_used,
                           r.final_cost, r.inlier_fraction, r.overlap, bool(r.keyframe), r.ms)

    def reset(self) -> None:
        """Forgets the keyframe and the pose: the next frame is FIRST again."""
        _check(lib.planarvo_tracker_reset(self._h()))
