"""Motion pairs: intervals of the sensor's motion with the odometry's, their CSV files, and
tracking a data set into them."""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

import numpy as np

from . import _native as N
from ._camera import Extrinsics
from ._context import Context
from ._dataset import Dataset
from ._errors import _check
from ._native import lib
from ._se2 import SE2
from ._tracking import TrackerOptions, _tracker_options
from ._util import ArrayLike, NDArray, PathLike, _fill_matrix, _matrix, _path, _require


@dataclass
class MotionPair:
    """One interval of planar motion: the sensor's motion, optionally the wheel odometry's and a
    direction label (+1, -1, 0), and (3, 3) covariances of either."""
    interval: float
    sensor: SE2
    odometry: Optional[SE2] = None
    direction: Optional[int] = None
    sensor_covariance: Optional[NDArray[np.float64]] = None
    odometry_covariance: Optional[NDArray[np.float64]] = None

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


def _pairs_array(pairs: Sequence[MotionPair]) -> ctypes.Array[N.MotionPair]:
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


def sensor_motion(extrinsics: Extrinsics, robot_motion: SE2, covariance: Optional[ArrayLike] = None
                  ) -> Tuple[SE2, Optional[NDArray[np.float64]]]:
    """The camera's own motion (the graph calibration's sensor motion, docs/conventions.md) from a
    robot motion tracked with these extrinsics: the motion of the ground point below the camera,
    turned by its yaw, in units of its height; with the (3, 3) covariance carried through when one
    is given (planarvo_sensor_motion). Raises InvalidArgumentError unless extrinsics.z > 0."""
    _require(extrinsics, Extrinsics, "extrinsics")
    _require(robot_motion, SE2, "robot_motion")
    e, m, out = extrinsics._to_c(), robot_motion._to_c(), N.SE2()
    if covariance is None:
        _check(lib.planarvo_sensor_motion(ctypes.byref(e), ctypes.byref(m), None, ctypes.byref(out), None))
        return SE2._from_c(out), None
    cin, cout = (ctypes.c_double * 9)(), (ctypes.c_double * 9)()
    _fill_matrix(cin, covariance, 3, "covariance")
    _check(lib.planarvo_sensor_motion(ctypes.byref(e), ctypes.byref(m), cin, ctypes.byref(out), cout))
    return SE2._from_c(out), _matrix(cout, 3)


def track_motions(context: Context, dataset: Dataset, extrinsics: Extrinsics,
                  options: Optional[TrackerOptions] = None) -> List[MotionPair]:
    """Tracks every frame of dataset with extrinsics and returns one motion pair per tracked
    interval (lost ones left out): as the sensor's, the camera's own motion and covariance
    (sensor_motion() of the tracked one; the tracked one itself at x = y = 0, z = 1, yaw = 0), so
    that the pairs calibrate correctly whatever extrinsics tracked them, with the data set's
    odometry and direction labels where it has them."""
    _require(extrinsics, Extrinsics, "extrinsics")
    capacity = max(len(dataset) - 1, 1)
    a = (N.MotionPair * capacity)()
    count = ctypes.c_size_t(0)
    o = _tracker_options(options)
    _check(lib.planarvo_track_motions(context._h(), dataset._h(), ctypes.byref(extrinsics._to_c()), ctypes.byref(o),
                                      a, capacity, ctypes.byref(count)))
    return [MotionPair._from_c(p) for p in a[:count.value]]
