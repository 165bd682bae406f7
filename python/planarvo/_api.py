"""The Python API over the C API (include/planarvo/planarvo.h): plain data as dataclasses and
numpy arrays, handles as classes with close() and context managers. Units: metres, radians,
seconds; frames and conventions as in docs/conventions.md."""
from __future__ import annotations

import ctypes
import enum
import os
import weakref
from dataclasses import dataclass, fields
from typing import Any, Callable, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native as N
from ._native import lib

PathLike = Union[str, "os.PathLike[str]"]
ProgressFn = Callable[[float, str], Optional[bool]]  # return True to cancel
LogFn = Callable[[str], None]


# ------------------------------------------------------------------------------------------------
# Enums and errors


class Status(enum.IntEnum):
    """planarvo_status."""
    OK = 0
    INVALID_ARGUMENT = 1
    INVALID_INPUT = 2
    IO = 3
    NO_DEVICE = 4
    OPENCL = 5
    FAILED = 6
    CANCELLED = 7
    BUFFER_TOO_SMALL = 8
    INTERNAL = 9


class TrackStatus(enum.IntEnum):
    """planarvo_track_status."""
    FIRST = 0
    OK = 1
    DEGRADED = 2
    LOST = 3


class CalibrationStatus(enum.IntEnum):
    """planarvo_calibration_status."""
    OK = 0
    TOO_LITTLE_TEXTURE = 1
    TOO_LITTLE_MOTION = 2
    UNOBSERVABLE = 3
    FAILED = 4


class CalibrationMethod(enum.IntEnum):
    """planarvo_calibration_method."""
    ODOMETRY = 0
    NONHOLONOMIC = 1


class RobustLoss(enum.IntEnum):
    """planarvo_robust_loss."""
    NONE = 0
    HUBER = 1
    CAUCHY = 2
    TUKEY = 3


class MotionProfile(enum.IntEnum):
    """planarvo_motion_profile (the simulator's drive)."""
    MIXED = 0
    STRAIGHT = 1
    CIRCLE = 2
    SPIN = 3
    CAR = 4


class PosegraphInit(enum.IntEnum):
    """planarvo_posegraph_init."""
    NONE = 0
    ROTATION_FIRST = 1


class Error(Exception):
    """A failed planarvo call. status: the Status; status_name: its C name (planarvo_status_name);
    message: planarvo_last_error()'s text; result: the filled-in result of a call that fills one
    in even when it fails (calibrations, pose graphs), else None."""

    def __init__(self, status: int, message: str, result: Any = None):
        self.status = Status(status) if status in Status._value2member_map_ else status
        self.status_name = lib.planarvo_status_name(int(status)).decode()
        self.message = message
        self.result = result
        super().__init__("%s: %s" % (self.status_name, message))


def _check(status: int, result: Any = None) -> None:
    if status != 0:
        raise Error(status, lib.planarvo_last_error().decode(errors="replace"), result)


def _path(p: PathLike) -> bytes:
    return os.fsencode(p)


def _opt(s: Optional[str]) -> Optional[bytes]:
    return None if s is None else s.encode()


def version() -> str:
    """The loaded library's version, "major.minor.patch"."""
    return lib.planarvo_version_string().decode()


class _Callback:
    """A Python progress or log function as a C callback, kept alive for the call; an exception
    raised in it cancels the call (progress) and is re-raised after it."""

    def __init__(self, fn: Optional[Callable], kind):
        self.fn, self.error = fn, None
        if fn is None:
            self.c = kind()  # NULL
        elif kind is N.PROGRESS_FN:
            self.c = kind(self._progress)
        else:
            self.c = kind(self._log)

    def _progress(self, _user, fraction, stage):
        try:
            return 1 if self.fn(fraction, stage.decode(errors="replace") if stage else "") else 0
        except BaseException as e:  # noqa: B902 - never let an exception unwind through C
            self.error = e
            return 1

    def _log(self, _user, line):
        if self.error is None:
            try:
                self.fn(line.decode(errors="replace") if line else "")
            except BaseException as e:  # noqa: B902
                self.error = e

    def reraise(self) -> None:
        if self.error is not None:
            raise self.error


# ------------------------------------------------------------------------------------------------
# Plain data


@dataclass
class SE2:
    """A planar pose or motion: x, y (metres), theta (radians)."""
    x: float = 0.0
    y: float = 0.0
    theta: float = 0.0

    def __array__(self, dtype=None):
        return np.array([self.x, self.y, self.theta], dtype=dtype or np.float64)

    def as_array(self) -> np.ndarray:
        """(x, y, theta) as a float64 array of shape (3,)."""
        return np.array([self.x, self.y, self.theta])

    @classmethod
    def _from_c(cls, s: N.SE2) -> "SE2":
        return cls(s.x, s.y, s.theta)

    def _to_c(self) -> N.SE2:
        return N.SE2(self.x, self.y, self.theta)


def _se2_array(poses: Any, what: str) -> np.ndarray:
    """(N, 3) float64 C-contiguous from an (N, 3) array or a sequence of SE2."""
    if isinstance(poses, (list, tuple)) and poses and isinstance(poses[0], SE2):
        poses = [p.as_array() for p in poses]
    a = np.asarray(poses, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError("%s: expected an (N, 3) array of (x, y, theta), got shape %s" % (what, a.shape))
    return np.ascontiguousarray(a)


def _matrix(values, n: int) -> np.ndarray:
    return np.array(values[:n * n], dtype=np.float64).reshape(n, n)


def _fill_matrix(dst, value, n: int, what: str) -> None:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != (n, n):
        raise ValueError("%s: expected a (%d, %d) array, got shape %s" % (what, n, n, a.shape))
    for i, v in enumerate(a.ravel()):
        dst[i] = v


@dataclass
class Camera:
    """Pinhole camera with OpenCV's radial-tangential distortion (k1 k2 p1 p2 k3); roi
    (x, y, width, height) the only pixels used, all zero for the whole image."""
    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    k1: float = 0.0
    k2: float = 0.0
    p1: float = 0.0
    p2: float = 0.0
    k3: float = 0.0
    roi: Tuple[int, int, int, int] = (0, 0, 0, 0)

    @classmethod
    def load(cls, path: PathLike) -> "Camera":
        """Reads an OpenCV calibration YAML (docs/formats.md, camera.yaml)."""
        c = N.Camera()
        _check(lib.planarvo_camera_load(_path(path), ctypes.byref(c)))
        return cls._from_c(c)

    def save(self, path: PathLike) -> None:
        """Writes the camera as OpenCV calibration YAML."""
        _check(lib.planarvo_camera_save(_path(path), ctypes.byref(self._to_c())))

    @classmethod
    def simulator_default(cls, width: int = 640, height: int = 480, fov_deg: float = 80.0) -> "Camera":
        """The simulator's camera for a size and horizontal field of view (degrees)."""
        c = N.Camera()
        _check(lib.planarvo_sim_default_camera(width, height, fov_deg, ctypes.byref(c)))
        return cls._from_c(c)

    @classmethod
    def _from_c(cls, c: N.Camera) -> "Camera":
        return cls(c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3,
                   (c.roi.x, c.roi.y, c.roi.width, c.roi.height))

    def _to_c(self) -> N.Camera:
        return N.Camera(self.width, self.height, self.fx, self.fy, self.cx, self.cy, self.k1, self.k2, self.p1,
                        self.p2, self.k3, N.Region(*self.roi))


EXTRINSICS_NAMES = ("x", "y", "z", "roll", "pitch", "yaw")


@dataclass
class Extrinsics:
    """The camera's pose on the robot (T_robot_camera): centre x, y, z (metres, z the height above
    the ground), roll, pitch, yaw (radians); see docs/conventions.md."""
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0

    @classmethod
    def load(cls, path: PathLike) -> "Extrinsics":
        """Reads extrinsics YAML (docs/formats.md)."""
        e = N.Extrinsics()
        _check(lib.planarvo_extrinsics_load(_path(path), ctypes.byref(e)))
        return cls._from_c(e)

    def save(self, path: PathLike, covariance: Optional[np.ndarray] = None, estimated: Sequence[str] = (),
             method: Optional[str] = None, notes: Optional[str] = None) -> None:
        """Writes extrinsics YAML: covariance a (6, 6) array (order x y z roll pitch yaw) or None
        (zeros); estimated the names of the estimated parameters."""
        cov = None
        if covariance is not None:
            cov = (ctypes.c_double * 36)()
            _fill_matrix(cov, covariance, 6, "covariance")
        bad = [n for n in estimated if n not in EXTRINSICS_NAMES]
        if bad:
            raise ValueError("estimated: unknown parameter names %s (known: %s)" % (bad, ", ".join(EXTRINSICS_NAMES)))
        _check(lib.planarvo_extrinsics_save(_path(path), ctypes.byref(self._to_c()), cov,
                                            ",".join(estimated).encode() if estimated else None,
                                            _opt(method), _opt(notes)))

    def matrix(self) -> np.ndarray:
        """T_robot_camera as a (4, 4) float64 array."""
        m = (ctypes.c_double * 16)()
        _check(lib.planarvo_extrinsics_matrix(ctypes.byref(self._to_c()), m))
        return _matrix(m, 4)

    def as_array(self) -> np.ndarray:
        """(x, y, z, roll, pitch, yaw) as a float64 array of shape (6,)."""
        return np.array([getattr(self, n) for n in EXTRINSICS_NAMES])

    @classmethod
    def _from_c(cls, e: N.Extrinsics) -> "Extrinsics":
        return cls(*(getattr(e, n) for n in EXTRINSICS_NAMES))

    def _to_c(self) -> N.Extrinsics:
        return N.Extrinsics(*(getattr(self, n) for n in EXTRINSICS_NAMES))


# ------------------------------------------------------------------------------------------------
# Frames: numpy arrays as planarvo_image


def _image(frame: Any, width: Optional[int] = None, height: Optional[int] = None,
           out: Optional[N.Image] = None) -> Tuple[N.Image, np.ndarray]:
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
    if frame.strides[0] < w * bpp:
        raise ValueError("frame: rows must be in increasing memory order without overlap (row stride %d bytes)"
                         % frame.strides[0])
    if (width is not None and w != width) or (height is not None and h != height):
        raise ValueError("frame: %dx%d does not match the camera's %dx%d" % (w, h, width, height))
    image = out if out is not None else N.Image()
    image.data, image.width, image.height, image.stride, image.format = frame.ctypes.data, w, h, frame.strides[0], fmt
    return image, frame


# ------------------------------------------------------------------------------------------------
# Handles


def _release(destroy, handle, _keep_alive) -> None:
    destroy(handle)


class _Handle:
    """Owns one C handle, destroyed exactly once by close(), the with-statement or, failing
    those, the garbage collector."""
    _destroy_name = ""

    def _own(self, handle: ctypes.c_void_p, *parents: Any) -> None:
        self._handle = handle
        self._children: "weakref.WeakSet[_Handle]" = weakref.WeakSet()
        # The finalizer holds the handles this one needs (a tracker its context), so that they
        # outlive it; closing a parent closes its children first.
        self._finalizer = weakref.finalize(self, _release, getattr(lib, self._destroy_name), handle, parents)
        for p in parents:
            if isinstance(p, _Handle):
                p._children.add(self)

    def close(self) -> None:
        """Releases the handle now, and first those that depend on it (a context's trackers);
        later calls raise ValueError. Calling it again does nothing."""
        if getattr(self, "_finalizer", None) is not None:
            for child in list(self._children):
                child.close()
            self._finalizer()

    @property
    def closed(self) -> bool:
        return getattr(self, "_finalizer", None) is None or not self._finalizer.alive

    def _h(self) -> ctypes.c_void_p:
        if self.closed:
            raise ValueError("%s is closed" % type(self).__name__)
        return self._handle

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


@dataclass
class DeviceInfo:
    """An OpenCL device (planarvo_device_info); index selects it (Context(device=str(index)))."""
    index: int
    platform_name: str
    device_name: str
    device_type: str
    device_version: str
    opencl_c_version: str
    driver_version: str
    image_support: bool
    fp64: bool
    local_mem_size: int
    global_mem_size: int
    max_work_group_size: int
    compute_units: int

    @classmethod
    def _from_c(cls, d: N.DeviceInfo) -> "DeviceInfo":
        values = []
        for f in fields(cls):
            v = getattr(d, f.name)
            values.append(v.decode(errors="replace") if isinstance(v, bytes) else
                          bool(v) if f.type in (bool, "bool") else v)
        return cls(*values)


def list_devices() -> List[DeviceInfo]:
    """Every OpenCL device (an empty list on a machine without OpenCL)."""
    count = ctypes.c_size_t(0)
    _check(lib.planarvo_list_devices(None, 0, ctypes.byref(count)))
    while True:
        devices = (N.DeviceInfo * max(count.value, 1))()
        for d in devices:
            d.struct_size = ctypes.sizeof(N.DeviceInfo)
        status = lib.planarvo_list_devices(devices, len(devices), ctypes.byref(count))
        if status != Status.BUFFER_TOO_SMALL:
            break
    _check(status)
    return [DeviceInfo._from_c(d) for d in devices[:count.value]]


class Context(_Handle):
    """An OpenCL device with its queue and kernel programs (planarvo_context).

    device: None for $PLANARVO_DEVICE, else the first GPU or accelerator, else the first device;
    an index (int or str) from list_devices(), or a substring of "platform / device name".
    cache_dir: the kernel program cache (None: the default); disable_cache: always compile;
    kernel_binaries_dir: load prebuilt binaries (export_kernels) and never compile.
    Raises Error (Status.NO_DEVICE) when no device matches."""
    _destroy_name = "planarvo_context_destroy"

    def __init__(self, device: Union[None, int, str] = None, cache_dir: Optional[PathLike] = None,
                 disable_cache: bool = False, kernel_binaries_dir: Optional[PathLike] = None):
        o = N.sized(N.ContextOptions)
        lib.planarvo_context_options_init(ctypes.byref(o))
        o.device = None if device is None else str(device).encode()
        o.cache_dir = None if cache_dir is None else _path(cache_dir)
        o.disable_cache = int(bool(disable_cache))
        o.kernel_binaries_dir = None if kernel_binaries_dir is None else _path(kernel_binaries_dir)
        h = ctypes.c_void_p()
        _check(lib.planarvo_context_create(ctypes.byref(o), ctypes.byref(h)))
        self._own(h)

    @property
    def device(self) -> DeviceInfo:
        """The context's device."""
        d = N.sized(N.DeviceInfo)
        _check(lib.planarvo_context_device(self._h(), ctypes.byref(d)))
        return DeviceInfo._from_c(d)

    @property
    def cache_dir(self) -> str:
        """The kernel program cache directory; "" when the cache is off."""
        return lib.planarvo_context_cache_dir(self._h()).decode()

    def prepare_kernels(self) -> None:
        """Builds (or loads) every kernel program now, so that the first frame does not pay for it."""
        _check(lib.planarvo_context_prepare_kernels(self._h()))

    def export_kernels(self, directory: PathLike, uses: Optional[Sequence[str]] = None) -> int:
        """Writes the kernel binaries for this device into directory (for kernel_binaries_dir):
        all of them, or those that uses ("track", "calibrate", "simulate") need. Returns the count."""
        n = ctypes.c_size_t(0)
        _check(lib.planarvo_context_export_kernels_for(self._h(), _path(directory),
                                                        ",".join(uses).encode() if uses else None, ctypes.byref(n)))
        return n.value


# ------------------------------------------------------------------------------------------------
# Options: dataclasses whose None fields keep the library's defaults


def _c_options(struct_type, init_name: str, options: Any, skip: Sequence[str] = ()):
    """The C option struct: the library's defaults (init), then every field of options that is
    not None."""
    c = N.sized(struct_type)
    getattr(lib, init_name)(ctypes.byref(c))
    if options is not None:
        for f in fields(options):
            v = getattr(options, f.name)
            if v is None or f.name in skip:
                continue
            setattr(c, f.name, int(v) if isinstance(v, (bool, enum.IntEnum)) else v)
    return c


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
        self.camera = camera
        self.extrinsics = extrinsics
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


# ------------------------------------------------------------------------------------------------
# Data sets


@dataclass
class DatasetInfo:
    """What a data set holds; extrinsics / extrinsics_gt None when it has none."""
    frame_count: int
    first_timestamp: float
    last_timestamp: float
    camera: Camera
    has_odometry: bool
    has_direction: bool
    has_groundtruth: bool
    extrinsics: Optional[Extrinsics]
    extrinsics_gt: Optional[Extrinsics]


@dataclass
class FrameData:
    """A frame's time stamp, and its odometry pose, true pose and direction label (+1 forwards,
    -1 backwards, 0 no linear motion) where the data set has them (else None)."""
    timestamp: float
    odometry: Optional[SE2]
    groundtruth: Optional[SE2]
    direction: Optional[int]


class Dataset(_Handle):
    """A data set directory (docs/formats.md), read and validated on open; frames are decoded on
    demand. video: a video file standing in for frames.txt + images/."""
    _destroy_name = "planarvo_dataset_destroy"

    def __init__(self, directory: PathLike, video: Optional[PathLike] = None, verify_images: bool = False,
                 allow_missing_images: bool = False, progress: Optional[ProgressFn] = None):
        o = N.sized(N.DatasetOptions)
        lib.planarvo_dataset_options_init(ctypes.byref(o))
        o.video = None if video is None else _path(video)
        o.verify_images = int(verify_images)
        o.allow_missing_images = int(allow_missing_images)
        cb = _Callback(progress, N.PROGRESS_FN)
        o.progress = cb.c
        h = ctypes.c_void_p()
        status = lib.planarvo_dataset_open(_path(directory), ctypes.byref(o), ctypes.byref(h))
        cb.reraise()
        _check(status)
        self._own(h)
        self.path = os.fspath(directory)

    @property
    def info(self) -> DatasetInfo:
        i = N.sized(N.DatasetInfo)
        _check(lib.planarvo_dataset_info_get(self._h(), ctypes.byref(i)))
        return DatasetInfo(i.frame_count, i.first_timestamp, i.last_timestamp, Camera._from_c(i.camera),
                           bool(i.has_odometry), bool(i.has_direction), bool(i.has_groundtruth),
                           Extrinsics._from_c(i.extrinsics) if i.has_extrinsics else None,
                           Extrinsics._from_c(i.extrinsics_gt) if i.has_extrinsics_gt else None)

    def __len__(self) -> int:
        return self.info.frame_count

    def set_roi(self, roi: Optional[Tuple[int, int, int, int]]) -> None:
        """Replaces the camera's region of interest (x, y, width, height); None: the whole image."""
        _check(lib.planarvo_dataset_set_roi(self._h(), None if roi is None else ctypes.byref(N.Region(*roi))))

    def frame_data(self, index: int) -> FrameData:
        d = N.FrameData()
        _check(lib.planarvo_dataset_frame_data(self._h(), index, ctypes.byref(d)))
        return FrameData(d.timestamp, SE2._from_c(d.odometry) if d.has_odometry else None,
                         SE2._from_c(d.groundtruth) if d.has_groundtruth else None,
                         d.direction if d.has_direction else None)

    def frame(self, index: int) -> np.ndarray:
        """Frame index decoded as 8-bit grey: a new (H, W) uint8 array."""
        img = N.Image()
        _check(lib.planarvo_dataset_frame(self._h(), index, ctypes.byref(img)))
        if img.format != 0 or img.stride < img.width:
            raise Error(Status.INTERNAL, "planarvo_dataset_frame returned format %d, stride %d"
                        % (img.format, img.stride))
        buf = (ctypes.c_uint8 * (img.stride * img.height)).from_address(img.data)
        return np.frombuffer(buf, dtype=np.uint8).reshape(img.height, img.stride)[:, :img.width].copy()

    def frames(self) -> Iterator[Tuple[float, np.ndarray]]:
        """(timestamp, grey frame) for every frame in order."""
        for i in range(len(self)):
            yield self.frame_data(i).timestamp, self.frame(i)


def write_tum(path: PathLike, timestamps: Sequence[float], poses: Any) -> None:
    """Writes a TUM trajectory: timestamps (N,), poses (N, 3) of (x, y, theta) or a list of SE2."""
    t = np.ascontiguousarray(timestamps, dtype=np.float64)
    p = _se2_array(poses, "poses")
    if t.ndim != 1 or t.shape[0] != p.shape[0]:
        raise ValueError("timestamps: expected shape (%d,), got %s" % (p.shape[0], t.shape))
    _check(lib.planarvo_write_tum(_path(path), t.ctypes.data_as(N.P(ctypes.c_double)),
                                  p.ctypes.data_as(N.P(N.SE2)), p.shape[0]))


class StatsWriter(_Handle):
    """Per-frame statistics CSV (docs/formats.md): rows are flushed as they are added to
    PATH.partial, which close() renames onto path (complete or untouched). Leaving a with-block
    by an exception, discard(), or a writer never closed (garbage collection) removes the
    partial file and leaves path as it was."""
    _destroy_name = "planarvo_stats_writer_discard"

    def __init__(self, path: PathLike):
        h = ctypes.c_void_p()
        _check(lib.planarvo_stats_writer_open(_path(path), ctypes.byref(h)))
        self._own(h)

    def add(self, timestamp: float, vx: float, vy: float, omega: float, iterations: int, final_cost: float,
            inlier_fraction: float, ms: float, status: str) -> None:
        """One row: the robot-frame velocity over the interval ending at the frame, and the
        tracker's figures for it (status "first", "ok", "degraded", "lost", ...)."""
        row = N.FrameStats(timestamp, vx, vy, omega, iterations, final_cost, inlier_fraction, ms, status.encode())
        _check(lib.planarvo_stats_writer_add(self._h(), ctypes.byref(row)))

    def close(self) -> None:
        """Completes the file (renames it onto path); raises Error when a write failed."""
        if not self.closed:
            handle = self._handle
            self._finalizer.detach()
            _check(lib.planarvo_stats_writer_close(handle))

    def discard(self) -> None:
        """Removes the partial file and leaves path as it was."""
        _Handle.close(self)

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is None:
            self.close()
        else:
            self.discard()


# ------------------------------------------------------------------------------------------------
# Simulator


@dataclass
class SimOptions:
    """planarvo_sim_options; None keeps the library's default (planarvo.h). texture None: the
    C API requires one, so the installed or source tree's asphalt_01.png is looked up."""
    texture: Optional[PathLike] = None
    texel_size: Optional[float] = None
    extrinsics: Optional[Extrinsics] = None
    camera: Optional[Camera] = None
    seconds: Optional[float] = None
    fps: Optional[float] = None
    seed: Optional[int] = None
    motion: Optional[MotionProfile] = None
    max_speed: Optional[float] = None
    max_turn_rate: Optional[float] = None
    pixel_noise: Optional[float] = None
    gain_variation: Optional[float] = None
    odometry_noise: Optional[float] = None
    supersampling: Optional[int] = None
    min_turn_radius: Optional[float] = None


def default_texture() -> str:
    """The built-in ground texture asphalt_01.png: installed (<prefix>/share/planarvo/textures) or
    in the source tree (data/textures). Raises FileNotFoundError when neither exists."""
    here = os.path.dirname(os.path.abspath(__file__))
    candidates = [os.path.join(here, "..", "..", "..", "..", "share", "planarvo", "textures", "asphalt_01.png"),
                  os.path.join(here, "..", "..", "data", "textures", "asphalt_01.png")]
    for c in candidates:
        if os.path.exists(c):
            return os.path.normpath(c)
    raise FileNotFoundError("asphalt_01.png not found (looked in %s): give SimOptions.texture"
                            % ", ".join(os.path.normpath(c) for c in candidates))


def simulate(context: Context, out_directory: PathLike, options: Optional[SimOptions] = None,
             progress: Optional[ProgressFn] = None) -> None:
    """Renders a data set into out_directory (created if missing): camera.yaml, images/,
    frames.txt, odometry.txt, direction.txt, groundtruth.txt, extrinsics_gt.yaml."""
    options = options or SimOptions()
    c = _c_options(N.SimOptions, "planarvo_sim_options_init", options,
                   skip=("texture", "extrinsics", "camera"))
    c.texture = _path(options.texture if options.texture is not None else default_texture())
    if options.extrinsics is not None:
        c.extrinsics = options.extrinsics._to_c()
    if options.camera is not None:
        c.camera = options.camera._to_c()
    cb = _Callback(progress, N.PROGRESS_FN)
    c.progress = cb.c
    status = lib.planarvo_simulate(context._h(), ctypes.byref(c), _path(out_directory))
    cb.reraise()
    _check(status)


# ------------------------------------------------------------------------------------------------
# Evaluation


@dataclass
class MotionAccuracy:
    """Accuracy of estimated motions against true ones (planarvo_motion_accuracy)."""
    intervals: int
    distance: float
    slope_linear: float
    slope_angular: float
    rms_translation: float
    max_translation: float
    rms_rotation: float
    gross_errors: int
    endpoint_error: float
    endpoint_drift: float
    endpoint_heading: float


def evaluate_motions(estimated: Any, truth: Any, dt: Sequence[float], valid: Optional[Sequence[bool]] = None,
                     gross_threshold: float = 1e-3) -> MotionAccuracy:
    """Compares (N, 3) estimated motions with (N, 3) true ones over intervals of dt (N,) seconds;
    valid (N,) flags leave intervals out of the per-interval figures (None: all count)."""
    e, t = _se2_array(estimated, "estimated"), _se2_array(truth, "truth")
    d = np.ascontiguousarray(dt, dtype=np.float64)
    if t.shape != e.shape or d.shape != (e.shape[0],):
        raise ValueError("evaluate_motions: estimated %s, truth %s and dt %s must have N rows"
                         % (e.shape, t.shape, d.shape))
    v = None
    if valid is not None:
        v = np.ascontiguousarray(valid, dtype=np.int32)
        if v.shape != d.shape:
            raise ValueError("valid: expected shape %s, got %s" % (d.shape, v.shape))
    a = N.sized(N.MotionAccuracy)
    _check(lib.planarvo_evaluate_motions(e.ctypes.data_as(N.P(N.SE2)), t.ctypes.data_as(N.P(N.SE2)),
                                         d.ctypes.data_as(N.P(ctypes.c_double)),
                                         None if v is None else v.ctypes.data_as(N.P(ctypes.c_int32)),
                                         e.shape[0], gross_threshold, ctypes.byref(a)))
    return MotionAccuracy(*(getattr(a, f.name) for f in fields(MotionAccuracy)))


# ------------------------------------------------------------------------------------------------
# Pose graphs


@dataclass
class SolverSummary:
    """How a solve went (planarvo_solver_summary)."""
    converged: bool
    termination: str
    iterations: int
    factorizations: int
    initial_chi2: float
    final_chi2: float
    seconds: float

    @classmethod
    def _from_c(cls, s: N.SolverSummary) -> "SolverSummary":
        return cls(bool(s.converged), s.termination.decode(errors="replace"), s.iterations, s.factorizations,
                   s.initial_chi2, s.final_chi2, s.seconds)


def posegraph_optimize(in_path: PathLike, out_path: Optional[PathLike] = None, max_iterations: int = 100,
                       init: PosegraphInit = PosegraphInit.NONE, log: Optional[LogFn] = None) -> SolverSummary:
    """Optimises a g2o 2-D pose graph (first vertex fixed) and writes it to out_path (if given).
    Raises Error (Status.FAILED, .result the SolverSummary) when the solver did not converge."""
    o = N.sized(N.PosegraphOptions)
    lib.planarvo_posegraph_options_init(ctypes.byref(o))
    o.max_iterations, o.init = max_iterations, int(init)
    cb = _Callback(log, N.LOG_FN)
    o.log = cb.c
    s = N.sized(N.SolverSummary)
    status = lib.planarvo_posegraph_optimize(_path(in_path), None if out_path is None else _path(out_path),
                                             ctypes.byref(o), ctypes.byref(s))
    cb.reraise()
    summary = SolverSummary._from_c(s)
    _check(status, summary)
    return summary


# ------------------------------------------------------------------------------------------------
# Motion pairs and the graph calibration


@dataclass
class MotionPair:
    """One interval of planar motion: the sensor's motion, optionally the wheel odometry's and a
    direction label (+1, -1, 0), and (3, 3) covariances of either."""
    interval: float
    sensor: SE2
    odometry: Optional[SE2] = None
    direction: Optional[int] = None
    sensor_covariance: Optional[np.ndarray] = None
    odometry_covariance: Optional[np.ndarray] = None

    @classmethod
    def _from_c(cls, p: N.MotionPair) -> "MotionPair":
        return cls(p.interval, SE2._from_c(p.sensor), SE2._from_c(p.odometry) if p.has_odometry else None,
                   p.direction if p.has_direction else None,
                   _matrix(p.sensor_covariance, 3) if p.has_sensor_covariance else None,
                   _matrix(p.odometry_covariance, 3) if p.has_odometry_covariance else None)

    def _fill(self, p: N.MotionPair) -> None:
        lib.planarvo_motion_pair_init(ctypes.byref(p))
        p.interval, p.sensor = self.interval, self.sensor._to_c()
        if self.odometry is not None:
            p.has_odometry, p.odometry = 1, self.odometry._to_c()
        if self.direction is not None:
            p.has_direction, p.direction = 1, int(self.direction)
        if self.sensor_covariance is not None:
            p.has_sensor_covariance = 1
            _fill_matrix(p.sensor_covariance, self.sensor_covariance, 3, "sensor_covariance")
        if self.odometry_covariance is not None:
            if self.odometry is None:
                raise ValueError("odometry_covariance needs odometry")
            p.has_odometry_covariance = 1
            _fill_matrix(p.odometry_covariance, self.odometry_covariance, 3, "odometry_covariance")


def _pairs_array(pairs: Sequence[MotionPair]):
    a = (N.MotionPair * len(pairs))()
    for p, c in zip(pairs, a):
        p._fill(c)
    return a


def save_motion_pairs(path: PathLike, pairs: Sequence[MotionPair]) -> None:
    """Writes motion pairs as CSV (docs/formats.md); all with odometry or none, all with a
    direction or none; covariances are not written."""
    _check(lib.planarvo_motion_pairs_save(_path(path), _pairs_array(pairs), len(pairs)))


def load_motion_pairs(path: PathLike) -> List[MotionPair]:
    """Reads a motion-pair CSV."""
    count = ctypes.c_size_t(0)
    _check(lib.planarvo_motion_pairs_load(_path(path), None, 0, ctypes.byref(count)))
    a = (N.MotionPair * max(count.value, 1))()
    lib.planarvo_motion_pair_init(ctypes.byref(a[0]))
    _check(lib.planarvo_motion_pairs_load(_path(path), a, len(a), ctypes.byref(count)))
    return [MotionPair._from_c(p) for p in a[:count.value]]


def track_motions(context: Context, dataset: Dataset, extrinsics: Extrinsics,
                  options: Optional[TrackerOptions] = None) -> List[MotionPair]:
    """Tracks every frame of dataset with extrinsics and returns one motion pair per tracked
    interval (lost ones left out): the tracker's motion and covariance as the sensor's, with the
    data set's odometry and direction labels where it has them."""
    capacity = max(len(dataset) - 1, 1)
    a = (N.MotionPair * capacity)()
    count = ctypes.c_size_t(0)
    o = _tracker_options(options)
    _check(lib.planarvo_track_motions(context._h(), dataset._h(), ctypes.byref(extrinsics._to_c()), ctypes.byref(o),
                                      a, capacity, ctypes.byref(count)))
    return [MotionPair._from_c(p) for p in a[:count.value]]


@dataclass
class CalibrationOptions:
    """planarvo_calibration_options (the graph calibration); None keeps the library's default.
    initial: (x, y, scale, yaw) to start from instead of the built-in initialisation."""
    method: Optional[CalibrationMethod] = None
    fix_scale: Optional[bool] = None
    fixed_scale: Optional[float] = None
    initial: Optional[Tuple[float, float, float, float]] = None
    velocity_form: Optional[bool] = None
    max_iterations: Optional[int] = None
    sensor_sigma_relative: Optional[float] = None
    sensor_sigma_floor: Optional[float] = None
    sensor_sigma_theta: Optional[float] = None
    odometry_sigma_relative: Optional[float] = None
    odometry_sigma_floor: Optional[float] = None
    odometry_sigma_theta: Optional[float] = None
    loss: Optional[RobustLoss] = None
    loss_scale: Optional[float] = None
    gate_sigma: Optional[float] = None
    still_speed: Optional[float] = None
    estimate_odometry_noise: Optional[bool] = None


def _calibration_options(options: Optional[CalibrationOptions], log: Optional[_Callback]) -> N.CalibrationOptions:
    c = _c_options(N.CalibrationOptions, "planarvo_calibration_options_init", options, skip=("initial",))
    if options is not None and options.initial is not None:
        if len(options.initial) != 4:
            raise ValueError("initial: expected (x, y, scale, yaw)")
        c.has_initial = 1
        c.initial[:] = [float(v) for v in options.initial]
    if log is not None:
        c.log = log.c
    return c


@dataclass
class CalibrationResult:
    """A graph calibration: value (x, y, scale, yaw), its (4, 4) covariance; per parameter
    estimated and observable; ok when converged, observable and not ambiguous."""
    value: np.ndarray
    covariance: np.ndarray
    estimated: Tuple[bool, ...]
    observable: Tuple[bool, ...]
    ambiguous: bool
    outliers: int
    ok: bool
    unobservable_reason: str
    summary: SolverSummary
    total_iterations: int
    total_seconds: float
    variance_factor: float

    def _to_c(self) -> N.CalibrationResult:
        r = N.sized(N.CalibrationResult)
        r.value[:] = [float(v) for v in self.value]
        r.covariance[:] = [float(v) for v in np.asarray(self.covariance).ravel()]
        r.estimated[:] = [int(v) for v in self.estimated]
        r.observable[:] = [int(v) for v in self.observable]
        r.ambiguous, r.outliers, r.ok = int(self.ambiguous), self.outliers, int(self.ok)
        r.unobservable_reason = self.unobservable_reason.encode()[:511]
        r.total_iterations, r.total_seconds, r.variance_factor = (self.total_iterations, self.total_seconds,
                                                                  self.variance_factor)
        return r

    @classmethod
    def _from_c(cls, r: N.CalibrationResult) -> "CalibrationResult":
        return cls(np.array(r.value[:]), _matrix(r.covariance, 4), tuple(bool(v) for v in r.estimated),
                   tuple(bool(v) for v in r.observable), bool(r.ambiguous), r.outliers, bool(r.ok),
                   r.unobservable_reason.decode(errors="replace"), SolverSummary._from_c(r.summary),
                   r.total_iterations, r.total_seconds, r.variance_factor)


def calibrate(pairs: Sequence[MotionPair], options: Optional[CalibrationOptions] = None,
              log: Optional[LogFn] = None) -> CalibrationResult:
    """Graph calibration of a sensor's x, y, scale and yaw from motion pairs. Raises Error
    (Status.FAILED, .result the CalibrationResult) when the result is not ok."""
    if not pairs:
        raise ValueError("calibrate: no motion pairs")
    cb = _Callback(log, N.LOG_FN) if log is not None else None
    o = _calibration_options(options, cb)
    r = N.sized(N.CalibrationResult)
    status = lib.planarvo_calibrate(_pairs_array(pairs), len(pairs), ctypes.byref(o), ctypes.byref(r))
    if cb is not None:
        cb.reraise()
    result = CalibrationResult._from_c(r)
    _check(status, result)
    return result


def compose_extrinsics(roll: float, pitch: float, roll_pitch_covariance: Optional[np.ndarray],
                       graph: CalibrationResult) -> Tuple[Extrinsics, np.ndarray, Tuple[bool, ...]]:
    """The camera's extrinsics from roll and pitch (with their (2, 2) covariance, or None when
    they were given) and a graph calibration's x, y, scale (the height) and yaw: returns the
    extrinsics, their (6, 6) covariance (order x y z roll pitch yaw) and per parameter whether it
    was estimated."""
    rp = None
    if roll_pitch_covariance is not None:
        rp = (ctypes.c_double * 4)()
        _fill_matrix(rp, roll_pitch_covariance, 2, "roll_pitch_covariance")
    e, cov, est = N.Extrinsics(), (ctypes.c_double * 36)(), (ctypes.c_int32 * 6)()
    _check(lib.planarvo_compose_extrinsics(roll, pitch, rp, ctypes.byref(graph._to_c()), ctypes.byref(e), cov, est))
    return Extrinsics._from_c(e), _matrix(cov, 6), tuple(bool(v) for v in est)


# ------------------------------------------------------------------------------------------------
# Camera calibration from images


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
    covariance: np.ndarray
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

    def add_frame(self, frame: np.ndarray, timestamp: float) -> bool:
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
    options."""
    method: Optional[CalibrationMethod] = None
    height: Optional[float] = None
    roll_pitch_frames: Optional[int] = None
    initial: Optional[Extrinsics] = None
    estimate_roll_pitch: Optional[bool] = None
    graph: Optional[CalibrationOptions] = None
    tracker: Optional[TrackerOptions] = None


@dataclass
class CameraCalibrationResult:
    """The whole calibration: the extrinsics, their (6, 6) covariance (order x y z roll pitch
    yaw), per parameter estimated / observable, the stages' results and timings."""
    status: CalibrationStatus
    reason: str
    extrinsics: Extrinsics
    covariance: np.ndarray
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

    @property
    def sigmas(self) -> np.ndarray:
        """Standard deviations of (x, y, z, roll, pitch, yaw); 0 where not estimated."""
        return np.sqrt(np.maximum(np.diag(self.covariance), 0.0))

    @classmethod
    def _from_c(cls, r: N.CameraCalibrationResult) -> "CameraCalibrationResult":
        return cls(CalibrationStatus(r.status), r.reason.decode(errors="replace"), Extrinsics._from_c(r.extrinsics),
                   _matrix(r.covariance, 6), tuple(bool(v) for v in r.estimated),
                   tuple(bool(v) for v in r.observable), RollPitchResult._from_c(r.roll_pitch),
                   CalibrationResult._from_c(r.graph), r.frames, r.frames_ok, r.frames_degraded, r.frames_lost,
                   r.samples, r.tracking_median_ms, r.seconds_decode, r.seconds_roll_pitch, r.seconds_tracking,
                   r.seconds_graph, r.seconds_total)


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

    def add_frame(self, frame: np.ndarray, timestamp: float, odometry_pose: Optional[SE2] = None,
                  direction: Optional[int] = None) -> None:
        """Feeds a frame with the robot's odometry pose at its time and the direction label of the
        interval ending at it (None where there is none)."""
        image, keep = _image(frame, self.camera.width, self.camera.height)
        odo = None if odometry_pose is None else ctypes.byref(odometry_pose._to_c())
        d = None if direction is None else ctypes.byref(ctypes.c_int32(int(direction)))
        status = lib.planarvo_camera_calibrator_add_frame(self._h(), ctypes.byref(image), float(timestamp), odo, d)
        self._options.callback.reraise()
        _check(status)
        del keep

    def finish(self) -> CameraCalibrationResult:
        """Runs what is left; raises Error (.result the CameraCalibrationResult) when it gives no answer."""
        r = N.sized(N.CameraCalibrationResult)
        status = lib.planarvo_camera_calibrator_finish(self._h(), ctypes.byref(r))
        self._options.callback.reraise()
        result = CameraCalibrationResult._from_c(r)
        _check(status, result)
        return result
