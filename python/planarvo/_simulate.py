"""The simulator: renders a data set of a drive over a textured ground plane."""
from __future__ import annotations

import ctypes
import os
from dataclasses import dataclass
from typing import Optional

from . import _native as N
from ._camera import Camera, Extrinsics
from ._context import Context
from ._errors import IntEnum, _check
from ._native import lib
from ._util import PathLike, ProgressFn, _c_options, _Callback, _path


class MotionProfile(IntEnum):
    """planarvo_motion_profile (the simulator's drive)."""
    MIXED = 0
    STRAIGHT = 1
    CIRCLE = 2
    SPIN = 3
    CAR = 4


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
    readout_time: Optional[float] = None    # rolling shutter, seconds first row to last; default 0
    exposure_time: Optional[float] = None   # seconds of motion blur before each row's read; default 0
    # Light fixed to the camera: a lamp's falloff (the darkest corner gets 1 - lamp_falloff),
    # its reflection on a glossy floor (peak grey levels added), the robot's shadow (fraction).
    lamp_falloff: Optional[float] = None
    reflection: Optional[float] = None
    shadow: Optional[float] = None
    # A car's body and its camera's mounting: the body rolls lean * yaw rate (seconds: degrees
    # per degree/s; the paper's car about -0.07) and pitches over speed bumps every 10 m (peak
    # pitch, radians); the data set then gets plane.txt, the true attitude per frame. At
    # knock_time seconds the mounting's roll, pitch (radians) and height (metres) change by the
    # knock_* amounts, and the data set gets extrinsics_knocked.yaml.
    lean: Optional[float] = None
    bumps: Optional[float] = None
    knock_time: Optional[float] = None
    knock_roll: Optional[float] = None
    knock_pitch: Optional[float] = None
    knock_z: Optional[float] = None
    # True lets extrinsics outside the plausible ranges through (see TrackerOptions).
    accept_unusual_extrinsics: Optional[bool] = None


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
    frames.txt, odometry.txt, direction.txt, groundtruth.txt, extrinsics_gt.yaml (and plane.txt,
    extrinsics_knocked.yaml for a body that leans or a knocked mounting)."""
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
    with cb.interruptible():
        status = lib.planarvo_simulate(context._h(), ctypes.byref(c), _path(out_directory))
    cb.reraise()
    _check(status)
