"""Data sets (docs/formats.md): a directory read and validated on open, frames decoded on demand."""
from __future__ import annotations

import ctypes
import operator
import os
from dataclasses import dataclass
from typing import Iterator, List, Optional, Tuple, Union, overload

import numpy as np

from . import _native as N
from ._camera import Camera, Extrinsics
from ._errors import Error, Status, _check, _error
from ._handle import _Handle
from ._native import lib
from ._se2 import SE2
from ._util import NDArray, PathLike, ProgressFn, _Callback, _opt, _path


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
    time_origin_ns: int = 0
    """A bag's first frame's stamp (integer ns since the Unix epoch); times are seconds after it."""
    is_bag: bool = False


@dataclass
class FrameData:
    """A frame's time stamp, and its odometry pose, true pose and direction label (+1 forwards,
    -1 backwards, 0 no linear motion) where the data set has them (else None)."""
    timestamp: float
    odometry: Optional[SE2]
    groundtruth: Optional[SE2]
    direction: Optional[int]


def bag_topics(path: PathLike) -> List[Tuple[str, str, int]]:
    """The topics of a ROS 1 bag or MCAP file: (name, type, message count; -1 when the file does
    not say), in the file's order."""
    needed = ctypes.c_size_t(0)
    _check(lib.planarvo_bag_topics(_path(path), None, 0, ctypes.byref(needed)))
    buf = ctypes.create_string_buffer(needed.value)
    _check(lib.planarvo_bag_topics(_path(path), buf, needed.value, None))
    out = []
    for line in buf.value.decode().splitlines():
        name, type_, count = line.rsplit("\t", 2)
        out.append((name, type_, int(count)))
    return out


# The tool's options that the library's data-set messages name, as this package's keywords.
_KEYWORDS = (("--image-topic", "image_topic="), ("--camera-info-topic", "camera_info_topic="),
             ("--camera FILE", "camera_yaml=FILE"), ("--odom-topic", "odometry_topic="),
             ("--odometry-topic", "odometry_topic="), ("--groundtruth-topic", "groundtruth_topic="),
             ("--video", "video="))


class Dataset(_Handle):
    """A data set directory (docs/formats.md), or a ROS 1 bag or MCAP file, read and validated on
    open; frames are decoded on demand. video: a video file standing in for frames.txt + images/.
    For a bag: image_topic (None: the bag's only image topic), camera_info_topic or camera_yaml
    (None for both: the only CameraInfo topic), odometry_topic and groundtruth_topic
    (nav_msgs/Odometry), use_receive_time (time by the recorder's clock, not header stamps)."""
    _destroy_name = "planarvo_dataset_destroy"

    def __init__(self, directory: PathLike, video: Optional[PathLike] = None, verify_images: bool = False,
                 allow_missing_images: bool = False, progress: Optional[ProgressFn] = None, *,
                 image_topic: Optional[str] = None, camera_info_topic: Optional[str] = None,
                 camera_yaml: Optional[PathLike] = None, odometry_topic: Optional[str] = None,
                 groundtruth_topic: Optional[str] = None, use_receive_time: bool = False):
        o = N.sized(N.DatasetOptions)
        lib.planarvo_dataset_options_init(ctypes.byref(o))
        o.video = None if video is None else _path(video)
        o.verify_images = int(verify_images)
        o.allow_missing_images = int(allow_missing_images)
        for name, value in (("image_topic", image_topic), ("camera_info_topic", camera_info_topic),
                            ("odometry_topic", odometry_topic), ("groundtruth_topic", groundtruth_topic)):
            if value is not None and not isinstance(value, str):
                raise ValueError(f"{name} must be a str, not {type(value).__name__}")
            setattr(o, name, _opt(value))
        o.camera_yaml = None if camera_yaml is None else _path(camera_yaml)
        o.use_receive_time = int(bool(use_receive_time))
        cb = _Callback(progress, N.PROGRESS_FN)
        o.progress = cb.c
        h = ctypes.c_void_p()
        with cb.interruptible():
            status = lib.planarvo_dataset_open(_path(directory), ctypes.byref(o), ctypes.byref(h))
        cb.reraise()
        try:
            _check(status)
        except Error as e:
            # The library's messages name the planarvo tool's options; name this call's arguments.
            message = e.message
            for flag, keyword in _KEYWORDS:
                message = message.replace(flag, keyword)
            raise _error(int(e.status), message) from None
        self._own(h)
        self.path = os.fspath(directory)

    @property
    def info(self) -> DatasetInfo:
        i = N.sized(N.DatasetInfo)
        _check(lib.planarvo_dataset_info_get(self._h(), ctypes.byref(i)))
        return DatasetInfo(i.frame_count, i.first_timestamp, i.last_timestamp, Camera._from_c(i.camera),
                           bool(i.has_odometry), bool(i.has_direction), bool(i.has_groundtruth),
                           Extrinsics._from_c(i.extrinsics) if i.has_extrinsics else None,
                           Extrinsics._from_c(i.extrinsics_gt) if i.has_extrinsics_gt else None,
                           int(i.time_origin_ns), bool(i.is_bag))

    def __len__(self) -> int:
        return self.info.frame_count

    # A sequence of (timestamp, grey frame): ds[i] (negative i from the end), ds[a:b:c] (a list),
    # iter(ds), len(ds).
    @overload
    def __getitem__(self, index: int) -> Tuple[float, NDArray[np.uint8]]: ...

    @overload
    def __getitem__(self, index: slice) -> List[Tuple[float, NDArray[np.uint8]]]: ...

    def __getitem__(self, index: Union[int, slice]
                    ) -> Union[Tuple[float, NDArray[np.uint8]], List[Tuple[float, NDArray[np.uint8]]]]:
        n = len(self)
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(n))]
        i = operator.index(index)
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError("frame index %d out of range for a data set of %d frames" % (index, n))
        return self.frame_data(i).timestamp, self.frame(i)

    def __iter__(self) -> Iterator[Tuple[float, NDArray[np.uint8]]]:
        return self.frames()

    def __repr__(self) -> str:
        if self.closed:
            return "<planarvo.Dataset %r (closed)>" % getattr(self, "path", "")
        i = self.info
        return "<planarvo.Dataset %r: %s, %d frames, %dx%d, %.3f .. %.3f s%s%s%s>" % (
            self.path, "bag" if i.is_bag else "folder", i.frame_count, i.camera.width, i.camera.height,
            i.first_timestamp, i.last_timestamp, ", odometry" if i.has_odometry else "",
            ", direction labels" if i.has_direction else "", ", ground truth" if i.has_groundtruth else "")

    def set_roi(self, roi: Optional[Tuple[int, int, int, int]]) -> None:
        """Replaces the camera's region of interest (x, y, width, height); None: the whole image."""
        _check(lib.planarvo_dataset_set_roi(self._h(), None if roi is None else ctypes.byref(N.Region(*roi))))

    def set_readout(self, seconds: float) -> None:
        """Replaces the camera's rolling-shutter readout: seconds from the first row's read to the
        last's (0: a global shutter), as camera.yaml's rolling_shutter_readout. Raises when it is
        negative, not finite or longer than the frames' interval."""
        _check(lib.planarvo_dataset_set_readout(self._h(), float(seconds), b"readout"))

    def frame_data(self, index: int) -> FrameData:
        d = N.FrameData()
        _check(lib.planarvo_dataset_frame_data(self._h(), index, ctypes.byref(d)))
        return FrameData(d.timestamp, SE2._from_c(d.odometry) if d.has_odometry else None,
                         SE2._from_c(d.groundtruth) if d.has_groundtruth else None,
                         d.direction if d.has_direction else None)

    def frame(self, index: int) -> NDArray[np.uint8]:
        """Frame index decoded as 8-bit grey: a new (H, W) uint8 array."""
        img = N.Image()
        _check(lib.planarvo_dataset_frame(self._h(), index, ctypes.byref(img)))
        if img.format != 0 or img.stride < img.width:
            raise Error(Status.INTERNAL, "planarvo_dataset_frame returned format %d, stride %d"
                        % (img.format, img.stride))
        buf = (ctypes.c_uint8 * (img.stride * img.height)).from_address(img.data)
        return np.frombuffer(buf, dtype=np.uint8).reshape(img.height, img.stride)[:, :img.width].copy()

    def frames(self) -> Iterator[Tuple[float, NDArray[np.uint8]]]:
        """(timestamp, grey frame) for every frame in order."""
        for i in range(len(self)):
            yield self.frame_data(i).timestamp, self.frame(i)
