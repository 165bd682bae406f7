"""Camera calibration from images: roll and pitch (RollPitch), then the whole calibration from a
data set (calibrate_dataset) or a stream of frames (CameraCalibrator)."""
from __future__ import annotations

import ctypes
from dataclasses import dataclass, field
from typing import Optional, Tuple, Union, cast

import numpy as np

from . import _native as N
from ._calibration import CalibrationMethod, CalibrationOptions, CalibrationResult, _calibration_options
from ._camera import Camera, Extrinsics
from ._context import Context
from ._dataset import Dataset
from ._errors import IntEnum, _check
from ._frame import _image
from ._handle import _Handle
from ._native import lib
from ._se2 import SE2
from ._tracking import TrackerOptions, _tracker_options
from ._util import NDArray, PathLike, ProgressFn, _c_options, _Callback, _matrix, _opt, _path


class CalibrationStatus(IntEnum):
    """planarvo_calibration_status."""
    OK = 0
    TOO_LITTLE_TEXTURE = 1
    TOO_LITTLE_MOTION = 2
    UNOBSERVABLE = 3
    FAILED = 4


@dataclass
class RollPitchOptions:
    """planarvo_roll_pitch_options; None keeps the library's default."""
    initial_roll: Optional[float] = None
    initial_pitch: Optional[float] = None
    max_frames: Optional[int] = None
    min_keyframes: Optional[int] = None
    max_keyframes: Optional[int] = None
    keyframe_overlap: Optional[float] = None
    search: Optional[bool] = None


@dataclass
class RollPitchResult:
    """Roll and pitch (radians) with their (2, 2) covariance."""
    status: CalibrationStatus
    reason: str
    roll: float
    pitch: float
    covariance: NDArray[np.float64]
    frames_used: int
    keyframes: int
    pairs: int
    seconds: float

    @classmethod
    def _from_c(cls, r: N.RollPitchResult) -> "RollPitchResult":
        return cls(CalibrationStatus(r.status), r.reason.decode(errors="replace"), r.roll, r.pitch,
                   _matrix(r.covariance, 2), r.frames_used, r.keyframes, r.pairs, r.seconds)


class RollPitch(_Handle):
    """Roll and pitch from images alone (section 5.1): feed frames with add_frame until it returns
    True (the map of keyframes is complete), then estimate()."""
    _destroy_name = "planarvo_roll_pitch_destroy"

    def __init__(self, context: Context, camera: Camera, options: Optional[RollPitchOptions] = None):
        self.camera = camera
        o = _c_options(N.RollPitchOptions, "planarvo_roll_pitch_options_init", options)
        h = ctypes.c_void_p()
        _check(lib.planarvo_roll_pitch_create(context._h(), ctypes.byref(camera._to_c()), ctypes.byref(o),
                                              ctypes.byref(h)))
        self._own(h, context)

    def add_frame(self, frame: NDArray[Union[np.uint8, np.float32]], timestamp: float) -> bool:
        """Feeds one frame (as Tracker.track takes it); True once the map is complete."""
        image, keep = _image(frame, self.camera.width, self.camera.height)
        complete = ctypes.c_int32(0)
        _check(lib.planarvo_roll_pitch_add_frame(self._h(), ctypes.byref(image), float(timestamp),
                                                 ctypes.byref(complete)))
        del keep
        return bool(complete.value)

    def estimate(self) -> RollPitchResult:
        """Estimates from the frames fed so far. Raises Error (Status.FAILED, .result the
        RollPitchResult) when the status is not OK."""
        r = N.sized(N.RollPitchResult)
        status = lib.planarvo_roll_pitch_estimate(self._h(), ctypes.byref(r))
        result = RollPitchResult._from_c(r)
        _check(status, result)
        return result


@dataclass
class CameraCalibrationOptions:
    """planarvo_camera_calibration_options; None keeps the library's default. height: the camera
    height when known (held); initial: the extrinsics to start from; graph, tracker: the stages'
    options; readout: where the rolling shutter's readout time comes from (ReadoutSource)."""
    method: Optional[CalibrationMethod] = None
    height: Optional[float] = None
    roll_pitch_frames: Optional[int] = None
    initial: Optional[Extrinsics] = None
    estimate_roll_pitch: Optional[bool] = None
    graph: Optional[CalibrationOptions] = None
    tracker: Optional[TrackerOptions] = None
    readout: Optional["ReadoutSource"] = None
    # True lets an initial or a height outside the plausible ranges through (see TrackerOptions).
    accept_unusual_extrinsics: Optional[bool] = None


class ReadoutSource(IntEnum):
    """planarvo_readout_source: where the calibration gets the rolling shutter's readout time."""
    IF_UNKNOWN = 0  # estimated when the data set's camera file does not give it
    CAMERA = 1      # the camera's as it is (0: a global shutter); the default
    ESTIMATE = 2    # estimated from the drive


@dataclass
class CameraCalibrationResult:
    """The whole calibration: the extrinsics, their (6, 6) covariance (order x y z roll pitch
    yaw), per parameter estimated / observable, the stages' results and timings."""
    status: CalibrationStatus
    reason: str
    extrinsics: Extrinsics
    covariance: NDArray[np.float64]
    estimated: Tuple[bool, ...]
    observable: Tuple[bool, ...]
    roll_pitch: RollPitchResult
    graph: CalibrationResult
    frames: int
    frames_ok: int
    frames_degraded: int
    frames_lost: int
    samples: int
    tracking_median_ms: float
    seconds_decode: float
    seconds_roll_pitch: float
    seconds_tracking: float
    seconds_graph: float
    seconds_total: float
    # The readout time (seconds) roll, pitch and tracking used; its estimate and standard
    # deviation when one was made (readout_evaluations > 0), or why it failed (readout_reason).
    readout: float = 0.0
    readout_estimate: float = 0.0
    readout_sigma: float = 0.0
    readout_evaluations: int = 0
    readout_reason: str = ""
    method: str = ""  # how the extrinsics were found, one sentence (extrinsics.yaml's method)
    _c: Optional[N.CameraCalibrationResult] = field(default=None, repr=False, compare=False)

    def save(self, path: PathLike, notes: Optional[str] = None) -> None:
        """Writes the extrinsics as extrinsics.yaml (the values, covariance, which were estimated,
        the method; notes: where the data came from), as planarvo calibrate -o does."""
        if self._c is None:
            raise ValueError("save: this result was not made by the library")
        _check(lib.planarvo_camera_calibration_save(_path(path), ctypes.byref(self._c), _opt(notes)))

    @property
    def sigmas(self) -> NDArray[np.float64]:
        """Standard deviations of (x, y, z, roll, pitch, yaw); 0 where not estimated."""
        return cast("NDArray[np.float64]", np.sqrt(np.maximum(np.diag(self.covariance), 0.0)))

    @classmethod
    def _from_c(cls, r: N.CameraCalibrationResult) -> "CameraCalibrationResult":
        return cls(CalibrationStatus(r.status), r.reason.decode(errors="replace"), Extrinsics._from_c(r.extrinsics),
                   _matrix(r.covariance, 6), tuple(bool(v) for v in r.estimated),
                   tuple(bool(v) for v in r.observable), RollPitchResult._from_c(r.roll_pitch),
                   CalibrationResult._from_c(r.graph), r.frames, r.frames_ok, r.frames_degraded, r.frames_lost,
                   r.samples, r.tracking_median_ms, r.seconds_decode, r.seconds_roll_pitch, r.seconds_tracking,
                   r.seconds_graph, r.seconds_total, r.readout, r.readout_estimate, r.readout_sigma,
                   r.readout_evaluations, r.readout_reason.decode(errors="replace"),
                   r.method.decode(errors="replace"), r)


class _CameraCalibrationC:
    """The C options with everything they point to kept alive."""

    def __init__(self, options: Optional[CameraCalibrationOptions], progress: Optional[ProgressFn]):
        o = options or CameraCalibrationOptions()
        c = _c_options(N.CameraCalibrationOptions, "planarvo_camera_calibration_options_init", o,
                       skip=("initial", "graph", "tracker"))
        if o.initial is not None:
            c.has_initial, c.initial = 1, o.initial._to_c()
        self.graph = _calibration_options(o.graph, None) if o.graph is not None else None
        self.tracker = _tracker_options(o.tracker) if o.tracker is not None else None
        if self.graph is not None:
            c.graph = ctypes.pointer(self.graph)
        if self.tracker is not None:
            c.tracker = ctypes.pointer(self.tracker)
        self.callback = _Callback(progress, N.PROGRESS_FN)
        c.progress = self.callback.c
        self.c = c


def calibrate_dataset(context: Context, dataset: Dataset, options: Optional[CameraCalibrationOptions] = None,
                      progress: Optional[ProgressFn] = None) -> CameraCalibrationResult:
    """The whole camera calibration from a data set: roll and pitch from the images, the drive
    tracked with them, then x, y, height and yaw against odometry.txt (ODOMETRY) or from the
    nonholonomic constraint with direction.txt and a given height (NONHOLONOMIC). Raises Error
    (.result the CameraCalibrationResult) when it does not give an answer."""
    o = _CameraCalibrationC(options, progress)
    r = N.sized(N.CameraCalibrationResult)
    with o.callback.interruptible():
        status = lib.planarvo_calibrate_dataset(context._h(), dataset._h(), ctypes.byref(o.c), ctypes.byref(r))
    o.callback.reraise()
    result = CameraCalibrationResult._from_c(r)
    _check(status, result)
    return result


class CameraCalibrator(_Handle):
    """The same calibration on a stream of frames: add_frame(frame, t, odometry_pose, direction)
    for each, then finish() once."""
    _destroy_name = "planarvo_camera_calibrator_destroy"

    def __init__(self, context: Context, camera: Camera, options: Optional[CameraCalibrationOptions] = None,
                 progress: Optional[ProgressFn] = None):
        self.camera = camera
        self._options = _CameraCalibrationC(options, progress)
        h = ctypes.c_void_p()
        _check(lib.planarvo_camera_calibrator_create(context._h(), ctypes.byref(camera._to_c()),
                                                     ctypes.byref(self._options.c), ctypes.byref(h)))
        self._own(h, context, self._options)

    def add_frame(self, frame: NDArray[Union[np.uint8, np.float32]], timestamp: float,
                  odometry_pose: Optional[SE2] = None, direction: Optional[int] = None) -> None:
        """Feeds a frame with the robot's odometry pose at its time and the direction label of the
        interval ending at it (None where there is none)."""
        image, keep = _image(frame, self.camera.width, self.camera.height)
        odo = None if odometry_pose is None else ctypes.byref(odometry_pose._to_c())
        d = None if direction is None else ctypes.byref(ctypes.c_int32(int(direction)))
        status = lib.planarvo_camera_calibrator_add_frame(self._h(), ctypes.byref(image), float(timestamp), odo, d)
        self._options.callback.reraise()
        _check(status)
        del keep

    def add_odometry(self, timestamp: float, pose: SE2) -> None:
        """A wheel-odometry sample, in time order: frames fed without odometry_pose take the pose
        interpolated at their time from the samples given by then."""
        _check(lib.planarvo_camera_calibrator_add_odometry(self._h(), float(timestamp), ctypes.byref(pose._to_c())))

    def finish(self) -> CameraCalibrationResult:
        """Runs what is left; raises Error (.result the CameraCalibrationResult) when it gives no answer."""
        r = N.sized(N.CameraCalibrationResult)
        status = lib.planarvo_camera_calibrator_finish(self._h(), ctypes.byref(r))
        self._options.callback.reraise()
        result = CameraCalibrationResult._from_c(r)
        _check(status, result)
        return result
