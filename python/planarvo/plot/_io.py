"""A run's files as the plots use them, read by the library's own readers (planarvo.read_tum,
read_stats, read_plane, ExtrinsicsFile.load), whose errors become InputError (exit status 2):
a TUM trajectory, the per-frame statistics CSV, extrinsics YAML with its covariance, plane.txt,
and a data set's per-frame times, odometry and ground truth (docs/formats.md)."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any, Callable, Dict, Optional, TypeVar

import numpy as np

import planarvo
from planarvo import ExtrinsicsFile as ExtrinsicsFile  # re-exported: the figures' modules take it from here

from ._errors import InputError

T = TypeVar("T")


def _read(what: str, path: str, read: Callable[[str], T]) -> T:
    """read(path), a library reader's error said as InputError naming what was read."""
    if not os.path.exists(path):
        raise InputError("the %s %s does not exist" % (what, path))
    try:
        return read(path)
    except planarvo.Error as e:
        raise InputError("cannot read the %s: %s" % (what, e.message)) from None


@dataclass
class Trajectory:
    """A TUM file's planar poses: stamps (N,), poses (N, 3) x y theta."""
    path: str
    stamps: np.ndarray
    poses: np.ndarray


def read_tum(path: str) -> Trajectory:
    """A TUM trajectory (planar poses, times increasing: the library's reader refuses others).
    Raises InputError when it cannot be read or is empty."""
    stamps, poses = _read("trajectory", path, planarvo.read_tum)
    if not len(stamps):
        raise InputError("the trajectory %s is empty: no poses to plot" % path)
    return Trajectory(path, stamps, poses)


@dataclass
class Stats:
    """The per-frame statistics CSV of `track --stats`, one array per column (planarvo.read_stats)."""
    path: str
    columns: Dict[str, np.ndarray]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]


def read_stats(path: str) -> Stats:
    return Stats(path, _read("statistics", path, planarvo.read_stats))


def read_extrinsics(path: str) -> ExtrinsicsFile:
    """Extrinsics YAML with its covariance, estimated parameters, method and notes."""
    return _read("extrinsics", path, ExtrinsicsFile.load)


@dataclass
class Series:
    """A data set's frames: times (N,) in the data set's clock, odometry and groundtruth (N, 3)
    (rows of NaN where a frame has none; None when the data set has none at all)."""
    path: str
    times: np.ndarray
    odometry: Optional[np.ndarray]
    groundtruth: Optional[np.ndarray]
    time_origin_s: float
    is_bag: bool


# The bag options, as `planarvo track` takes them: (flag, planarvo.Dataset keyword, help).
BAG_OPTIONS = (
    ("--image-topic", "image_topic", "bag: the images (sensor_msgs/Image or CompressedImage; default: the only one)"),
    ("--camera-info-topic", "camera_info_topic", "bag: the camera (sensor_msgs/CameraInfo; default: the only one)"),
    ("--camera", "camera_yaml", "bag: the camera from an OpenCV calibration YAML instead of a CameraInfo topic"),
    ("--odom-topic", "odometry_topic", "bag: wheel odometry (nav_msgs/Odometry; default none)"),
    ("--groundtruth-topic", "groundtruth_topic", "bag: true poses (nav_msgs/Odometry; default none)"),
)


def add_bag_options(p) -> None:
    """The bag options of `planarvo track` on an argparse parser."""
    for flag, keyword, text in BAG_OPTIONS:
        p.add_argument(flag, dest=keyword, metavar="FILE" if keyword == "camera_yaml" else "TOPIC", help=text)
    p.add_argument("--receive-time", dest="use_receive_time", action="store_true",
                   help="bag: time messages by when they were recorded, not by their header stamps")


def bag_options(args) -> Dict[str, Any]:
    """planarvo.Dataset's keywords from the options add_bag_options added (those given only)."""
    kw: Dict[str, Any] = {k: getattr(args, k) for _, k, _ in BAG_OPTIONS if getattr(args, k, None) is not None}
    if getattr(args, "use_receive_time", False):
        kw["use_receive_time"] = True
    return kw


def open_dataset(path: str, options: Optional[Dict[str, Any]] = None) -> planarvo.Dataset:
    """planarvo.Dataset(path, **options); its errors as InputError naming the tool's options."""
    if not os.path.exists(path):
        raise InputError("the data set %s does not exist" % path)
    try:
        return planarvo.Dataset(path, **(options or {}))
    except planarvo.Error as e:
        message = e.message
        for flag, keyword, _ in BAG_OPTIONS:  # the library's words for the Python keywords, back to flags
            message = message.replace(keyword + "=FILE", flag + " FILE").replace(keyword + "=", flag)
        raise InputError("cannot open the data set %s: %s" % (path, message)) from None


def read_dataset(path: str, options: Optional[Dict[str, Any]] = None) -> Series:
    """Opens the data set (a folder, a bag or MCAP file; options: planarvo.Dataset's bag keywords)
    and reads every frame's time and poses (not the images)."""
    ds = open_dataset(path, options)
    with ds:
        info = ds.info
        n = info.frame_count
        times = np.empty(n)
        odo = np.full((n, 3), np.nan)
        gt = np.full((n, 3), np.nan)
        for i in range(n):
            d = ds.frame_data(i)
            times[i] = d.timestamp
            if d.odometry is not None:
                odo[i] = (d.odometry.x, d.odometry.y, d.odometry.theta)
            if d.groundtruth is not None:
                gt[i] = (d.groundtruth.x, d.groundtruth.y, d.groundtruth.theta)
    has_odo = info.has_odometry and bool(np.isfinite(odo[:, 0]).any())
    has_gt = info.has_groundtruth and bool(np.isfinite(gt[:, 0]).any())
    return Series(path, times, odo if has_odo else None, gt if has_gt else None,
                  info.time_origin_ns * 1e-9, info.is_bag)


def read_plane(path: str) -> Optional[np.ndarray]:
    """A data set folder's plane.txt (the simulator's true body attitude) as (n, 3) time, roll,
    pitch; None when there is none."""
    f = os.path.join(path, "plane.txt")
    if not os.path.isfile(f):
        return None
    a = _read("body attitude", f, planarvo.read_plane)
    if not len(a):
        raise InputError("%s: no attitude in it" % f)
    return a[:, :3]


def degrees(rad) -> np.ndarray:
    return np.asarray(rad) * (180.0 / math.pi)
