"""Visual odometry: the Tracker, its options and its per-frame TrackResult."""
from __future__ import annotations

import ctypes
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Optional, Tuple, Union

import numpy as np

from . import _native as N
from ._camera import Camera, Extrinsics
from ._context import Context
from ._errors import IntEnum, _check
from ._frame import _image
from ._handle import _Handle
from ._native import lib
from ._se2 import SE2
from ._util import NDArray, PathLike, _c_options, _path, _require

if TYPE_CHECKING:
    from ._dataset import Dataset


class TrackStatus(IntEnum):
    """planarvo_track_status."""
    FIRST = 0
    OK = 1
    DEGRADED = 2
    LOST = 3


class MountingResponse(IntEnum):
    """What the tracker does when the local plane finds the camera's mounting changed
    (planarvo_mounting_response)."""
    IGNORE = 0       # not watched
    REPORT = 1       # reported (TrackResult.mounting_change); the extrinsics given are kept
    RECALIBRATE = 2  # reported, and tracking goes on with the mounting changed by it


@dataclass
class MountingChange:
    """A change of the camera's mounting confirmed by a frame: time, when it began (seconds);
    step_roll, step_pitch, the step in the body's attitude (radians), step_yaw, the turn about the
    body's vertical that came with it (radians, from the direction of travel), and step_z, in the
    camera's height (metres; watched only with odometry, Tracker.track's odometry), with their
    standard deviations (NaN for a part that was not judged); mounting, the extrinsics it implies
    (the camera turned about its centre and raised by step_z)."""
    time: float
    step_roll: float
    step_pitch: float
    step_yaw: float
    step_z: float
    sigma_roll: float
    sigma_pitch: float
    sigma_yaw: float
    sigma_z: float
    mounting: Extrinsics
    refinement: bool = False  # what was left of the last change taken into use, measured with it


@dataclass
class TrackerOptions:
    """planarvo_tracker_options; None keeps the library's default (see planarvo.h)."""
    levels: Optional[int] = None
    finest_level: Optional[int] = None
    max_iterations: Optional[int] = None
    keyframe_overlap: Optional[float] = None
    estimate_brightness: Optional[bool] = None
    level0_subsample: Optional[int] = None
    # A known flat field (an image file: the camera's relative brightness per distorted pixel,
    # brightest 1, 8- or 16-bit grey, the camera's size) instead of learning the light fixed to
    # the camera; None learns. Tracker.save_flat_field writes one.
    flat_field: Optional[PathLike] = None
    # The local plane (the paper's section 6.4): estimate the body's roll and pitch relative to the
    # local ground plane with every frame's motion (a car whose body leans and pitches); the
    # extrinsics are then the camera's mounting on the body at rest. local_plane_prior_sigma:
    # radians, the prior holding the attitude at the mounting where the images say nothing.
    local_plane: Optional[bool] = None
    local_plane_prior_sigma: Optional[float] = None
    # With the local plane, online recalibration: what a step in the body's attitude that persists
    # (the camera's mounting knocked) does (default RECALIBRATE), and the smallest step reported
    # (radians, default 1 degree).
    on_mounting_change: Optional[MountingResponse] = None
    mounting_min_step: Optional[float] = None
    # Extrinsics outside what a camera on a vehicle can be (an offset over 20 m, a height over 5 m,
    # an angle over a turn: millimetres or degrees by mistake) raise Error unless this is True.
    accept_unusual_extrinsics: Optional[bool] = None


def _tracker_options(options: Optional[TrackerOptions]) -> N.TrackerOptions:
    c = _c_options(N.TrackerOptions, "planarvo_tracker_options_init", options, skip=("flat_field",))
    if options is not None and options.flat_field is not None:
        c.flat_field = _path(options.flat_field)  # the structure keeps the bytes alive
    return c


@dataclass
class TrackResult:
    """One tracked frame. motion: the frame's robot pose in the previous frame's robot frame;
    covariance: (3, 3) of motion (x, y, theta); pose: relative to the first frame; ms: the
    engine's time for the frame (upload, undistortion, pyramid, tracking). With
    TrackerOptions.local_plane: roll, pitch (radians), the body's rotation relative to the local
    ground plane, R_plane_body = Rx(roll) Ry(pitch), and attitude_covariance (2, 2), zeros
    otherwise; attitude_observed, whether the images separated it from the motion (not while the
    car has not yet moved: it holds at the mounting); mounting, the extrinsics the frame was tracked
    with, and mounting_change when this frame confirmed a change of the camera's mounting (None
    otherwise)."""
    status: TrackStatus
    reason: str
    motion: SE2
    covariance: NDArray[np.float64]
    pose: SE2
    iterations: Tuple[int, ...]
    levels_used: int
    final_cost: float
    inlier_fraction: float
    overlap: float
    keyframe: bool
    ms: float
    roll: float = 0.0
    pitch: float = 0.0
    attitude_covariance: NDArray[np.float64] = field(default_factory=lambda: np.zeros((2, 2)))
    mounting: Optional[Extrinsics] = None
    mounting_change: Optional[MountingChange] = None
    attitude_observed: bool = False


@dataclass
class Residuals:
    """The last tracked frame's residuals against its keyframe at one pyramid level (see
    Tracker.residuals): float32 (height, width) arrays per keyframe pixel. residual: grey levels
    (0 where invalid); weight: the Huber weight, 1 for inliers, below 1 for the pixels the robust
    norm down-weighted, 0 where invalid; intensity: the keyframe's undistorted image, NaN where it
    has none; threshold: the Huber threshold k in grey levels."""
    level: int
    residual: NDArray[np.float32]
    weight: NDArray[np.float32]
    intensity: NDArray[np.float32]
    threshold: float

    @property
    def valid(self) -> NDArray[np.bool_]:
        """Pixels compared: a valid keyframe pixel whose warp lands on valid live pixels."""
        return self.weight > 0

    @property
    def outliers(self) -> NDArray[np.bool_]:
        """Pixels the robust norm down-weighted (|r| > threshold)."""
        return (self.weight > 0) & (self.weight < 1)


def _mounting_change(r: N.TrackResult) -> Optional[MountingChange]:
    if not r.mounting_changed:
        return None
    # Unpacked by name: mypy cannot count positional arguments after an unpacked array.
    step_roll, step_pitch, step_yaw, step_z = r.mounting_step
    sigma_roll, sigma_pitch, sigma_yaw, sigma_z = r.mounting_step_sigma
    return MountingChange(r.mounting_change_time, step_roll, step_pitch, step_yaw, step_z,
                          sigma_roll, sigma_pitch, sigma_yaw, sigma_z,
                          Extrinsics._from_c(r.changed_mounting), bool(r.mounting_refinement))


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

    def track(self, frame: NDArray[Union[np.uint8, np.float32]], timestamp: float,
              odometry: Optional[SE2] = None) -> TrackResult:
        """Tracks one frame: uint8 (H, W) grey or (H, W, 3) BGR (or float32 grey), the camera's
        size, any row stride; timestamps in seconds, increasing. odometry: the wheel odometry's
        pose at the frame, if there is one (with the local plane, the camera's height is then
        watched too). A frame that cannot be tracked is not an error: the result's status is LOST
        or DEGRADED with the reason."""
        if odometry is not None:
            _check(lib.planarvo_tracker_odometry(self._h(), ctypes.byref(N.SE2(odometry.x, odometry.y,
                                                                               odometry.theta))))
        image, keep = _image(frame, self.camera.width, self.camera.height, self._image)
        r = self._result
        _check(lib.planarvo_tracker_track(self._h(), ctypes.byref(image), float(timestamp), ctypes.byref(r)))
        del keep
        return TrackResult(TrackStatus(r.status), r.reason.decode() if r.reason else "",
                           SE2(r.motion.x, r.motion.y, r.motion.theta),
                           np.frombuffer(r.covariance, dtype=np.float64).reshape(3, 3).copy(),
                           SE2(r.pose.x, r.pose.y, r.pose.theta), tuple(r.iterations), r.levels_used,
                           r.final_cost, r.inlier_fraction, r.overlap, bool(r.keyframe), r.ms, r.roll, r.pitch,
                           np.frombuffer(r.attitude_covariance, dtype=np.float64).reshape(2, 2).copy(),
                           Extrinsics._from_c(r.mounting), _mounting_change(r), bool(r.attitude_observed))

    def residuals(self, level: int = 0) -> Residuals:
        """The last tracked frame's residuals against the keyframe it was aligned with, at pyramid
        `level` (0: full resolution, every pixel), at the final alignment, with the Huber threshold
        of the finest level tracked (planarvo_tracker_residuals). Raises Error with status
        INVALID_ARGUMENT before any frame was tracked after the first or for a level out of
        range, FAILED when the last frame was LOST without an alignment."""
        w, h, k = N.c_int32(), N.c_int32(), N.c_double()
        null = ctypes.POINTER(ctypes.c_float)()
        _check(lib.planarvo_tracker_residuals(self._h(), int(level), null, null, null, 0, ctypes.byref(w),
                                              ctypes.byref(h), ctypes.byref(k)))
        arrays = [np.empty((h.value, w.value), dtype=np.float32) for _ in range(3)]
        ptr = [a.ctypes.data_as(ctypes.POINTER(ctypes.c_float)) for a in arrays]
        _check(lib.planarvo_tracker_residuals(self._h(), int(level), ptr[0], ptr[1], ptr[2], arrays[0].size,
                                              ctypes.byref(w), ctypes.byref(h), ctypes.byref(k)))
        return Residuals(int(level), arrays[0], arrays[1], arrays[2], k.value)

    def save_flat_field(self, path: PathLike) -> None:
        """Writes the photometric model in use (learnt, or the flat field given) as a 16-bit
        flat-field PNG that TrackerOptions.flat_field reads back
        (planarvo_tracker_save_flat_field). Raises Error with status FAILED when none has been
        learnt yet (the model stays the identity until frames in motion show light fixed to the
        camera), IO when the file cannot be written."""
        _check(lib.planarvo_tracker_save_flat_field(self._h(), _path(path)))

    def reset(self) -> None:
        """Forgets the keyframe and the pose: the next frame is FIRST again."""
        _check(lib.planarvo_tracker_reset(self._h()))


@dataclass
class TrackedDrive:
    """A whole data set tracked (track_dataset), one row per frame: times (N,) seconds; poses
    (N, 3) x, y, theta relative to the first frame; motions (N, 3) each frame's motion from the
    previous (zeros for the first); covariances (N, 3, 3) of the motions; statuses (N,) TrackStatus
    values (int8; TrackStatus(s) names one); ms (N,) the engine's time per frame."""
    times: NDArray[np.float64]
    poses: NDArray[np.float64]
    motions: NDArray[np.float64]
    covariances: NDArray[np.float64]
    statuses: NDArray[np.int8]
    ms: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.times)

    def __repr__(self) -> str:
        counts = {s.name.lower(): int((self.statuses == s).sum()) for s in TrackStatus if (self.statuses == s).any()}
        return "<planarvo.TrackedDrive: %d frames, %s>" % (len(self), ", ".join("%d %s" % (n, k) for k, n in counts.items()))


def track_dataset(context: Context, dataset: "Dataset", extrinsics: Extrinsics,
                  options: Optional[TrackerOptions] = None, use_odometry: bool = False) -> TrackedDrive:
    """Tracks every frame of a data set with a new Tracker and returns the results as arrays
    (TrackedDrive). use_odometry passes the data set's odometry to the tracker (the local plane
    watches the camera height with it). Ctrl-C stops between two frames with KeyboardInterrupt."""
    n = len(dataset)
    times, ms = np.zeros(n), np.zeros(n)
    poses, motions = np.zeros((n, 3)), np.zeros((n, 3))
    covariances = np.zeros((n, 3, 3))
    statuses = np.zeros(n, dtype=np.int8)
    with Tracker(context, dataset.info.camera, extrinsics, options) as tracker:
        for i in range(n):
            data = dataset.frame_data(i)
            r = tracker.track(dataset.frame(i), data.timestamp, data.odometry if use_odometry else None)
            times[i], ms[i], statuses[i] = data.timestamp, r.ms, int(r.status)
            poses[i], motions[i] = r.pose.as_array(), r.motion.as_array()
            covariances[i] = r.covariance
    return TrackedDrive(times, poses, motions, covariances, statuses, ms)
