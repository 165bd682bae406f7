"""The camera: its intrinsics (Camera) and its pose on the robot (Extrinsics), with their YAML
files (docs/formats.md)."""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple, cast

import numpy as np

from . import _native as N
from ._errors import _check
from ._native import lib
from ._util import ArrayLike, NDArray, PathLike, _fill_matrix, _matrix, _opt, _path


@dataclass
class Camera:
    """Pinhole camera with OpenCV's radial-tangential distortion (k1 k2 p1 p2 k3); roi
    (x, y, width, height) the only pixels used, all zero for the whole image;
    rolling_shutter_readout the seconds from reading the first row to the last (0: global
    shutter; a frame's stamp is its first row's read time); exposure_time the seconds each row
    integrates before it is read (0: not modelled)."""
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
    rolling_shutter_readout: float = 0.0
    exposure_time: float = 0.0

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
                   (c.roi.x, c.roi.y, c.roi.width, c.roi.height), c.rolling_shutter_readout, c.exposure_time)

    def _to_c(self) -> N.Camera:
        return N.Camera(self.width, self.height, self.fx, self.fy, self.cx, self.cy, self.k1, self.k2, self.p1,
                        self.p2, self.k3, N.Region(*self.roi), self.rolling_shutter_readout, self.exposure_time)


# The six parameters' names in the order of every covariance and flag array: the library's table.
EXTRINSICS_NAMES = tuple(lib.planarvo_extrinsics_name(i).decode() for i in range(6))


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

    def save(self, path: PathLike, covariance: Optional[ArrayLike] = None, estimated: Sequence[str] = (),
             method: Optional[str] = None, notes: Optional[str] = None) -> None:
        """Writes extrinsics YAML: covariance a (6, 6) array (order x y z roll pitch yaw) or None
        (zeros); estimated the names of the estimated parameters."""
        cov = None
        if covariance is not None:
            cov = (ctypes.c_double * 36)()
            _fill_matrix(cov, covariance, 6, "covariance")
        if isinstance(estimated, str):
            estimated = [n.strip() for n in estimated.split(",") if n.strip()]
        bad = [n for n in estimated if n not in EXTRINSICS_NAMES]
        if bad:
            raise ValueError("estimated: unknown parameter names %s (known: %s)" % (bad, ", ".join(EXTRINSICS_NAMES)))
        _check(lib.planarvo_extrinsics_save(_path(path), ctypes.byref(self._to_c()), cov,
                                            ",".join(estimated).encode() if estimated else None,
                                            _opt(method), _opt(notes)))

    def matrix(self) -> NDArray[np.float64]:
        """T_robot_camera as a (4, 4) float64 array."""
        m = (ctypes.c_double * 16)()
        _check(lib.planarvo_extrinsics_matrix(ctypes.byref(self._to_c()), m))
        return _matrix(m, 4)

    def as_array(self) -> NDArray[np.float64]:
        """(x, y, z, roll, pitch, yaw) as a float64 array of shape (6,)."""
        return np.array([getattr(self, n) for n in EXTRINSICS_NAMES])

    @classmethod
    def _from_c(cls, e: N.Extrinsics) -> "Extrinsics":
        return cls(*(getattr(e, n) for n in EXTRINSICS_NAMES))

    def _to_c(self) -> N.Extrinsics:
        return N.Extrinsics(*(getattr(self, n) for n in EXTRINSICS_NAMES))


@dataclass
class ExtrinsicsFile:
    """Everything an extrinsics YAML holds (docs/formats.md): the extrinsics, their (6, 6)
    covariance in EXTRINSICS_NAMES order (zeros when the file has none), the names of the
    estimated parameters, and the method and notes ('' when absent)."""
    extrinsics: Extrinsics
    covariance: NDArray[np.float64]
    estimated: Tuple[str, ...]
    method: str
    notes: str

    @classmethod
    def load(cls, path: PathLike) -> "ExtrinsicsFile":
        f = N.ExtrinsicsFile()
        _check(lib.planarvo_extrinsics_file_load(_path(path), ctypes.byref(f)))
        return cls(Extrinsics._from_c(f.value), _matrix(f.covariance, 6),
                   tuple(n for n, flag in zip(EXTRINSICS_NAMES, f.estimated) if flag),
                   f.method.decode("utf-8", "replace"), f.notes.decode("utf-8", "replace"))

    @property
    def values(self) -> NDArray[np.float64]:
        """(x, y, z, roll, pitch, yaw), shape (6,)."""
        return self.extrinsics.as_array()

    @property
    def sigmas(self) -> NDArray[np.float64]:
        """The standard deviations of the six, from the covariance's diagonal."""
        return cast("NDArray[np.float64]", np.sqrt(np.maximum(np.diag(self.covariance), 0.0)))
