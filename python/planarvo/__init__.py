"""planarvo: dense planar visual odometry from a downward-looking camera, and calibration of the
camera's pose on the robot, from Python (ctypes over libplanarvo's C API, numpy in and out).

    import planarvo
    with planarvo.Context() as ctx, planarvo.Dataset("drive") as ds:
        info = ds.info
        with planarvo.Tracker(ctx, info.camera, info.extrinsics) as tracker:
            for t, frame in ds.frames():
                r = tracker.track(frame, t)   # r.status, r.motion, r.covariance, r.pose, r.ms

The library: $PLANARVO_LIBRARY, else the one installed beside this package, else the system's
(see python/README.md). Every failed call raises planarvo.Error; invalid Python input raises
ValueError before any C call. Units: metres, radians, seconds (docs/conventions.md).
"""
from ._calibration import (CalibrationMethod, CalibrationOptions, CalibrationResult, PairResiduals, RobustLoss,
                           calibrate, calibrate_residuals, compose_extrinsics)
from ._camera import EXTRINSICS_NAMES, Camera, Extrinsics, ExtrinsicsFile
from ._camera_calibration import (CalibrationStatus, CameraCalibrationOptions, CameraCalibrationResult,
                                  CameraCalibrator, ReadoutSource, RollPitch, RollPitchOptions, RollPitchResult,
                                  calibrate_dataset)
from ._context import Context, DeviceInfo, list_devices, version
from ._dataset import Dataset, DatasetInfo, FrameData, bag_topics
from ._errors import (Error, InvalidArgumentError, InvalidInputError, MissingFileError, PermissionDeniedError,
                      Status)
from ._evaluation import MotionAccuracy, evaluate_motions
from ._mosaic import Mosaic, MosaicInfo, build_mosaic
from ._motion_pairs import MotionPair, load_motion_pairs, save_motion_pairs, sensor_motion, track_motions
from ._output import STATS_COLUMNS, StatsWriter, read_plane, read_stats, read_tum, write_tum
from ._posegraph import PosegraphInit, SolverSummary, posegraph_optimize
from ._se2 import SE2
from ._simulate import MotionProfile, SimOptions, default_texture, simulate
from ._tracking import (MountingChange, MountingResponse, Residuals, TrackedDrive, Tracker, TrackerOptions, TrackResult,
                        TrackStatus, track_dataset)
from ._native import lib as _lib

__version__ = _lib.planarvo_version_string().decode()

__all__ = ["EXTRINSICS_NAMES", "CalibrationMethod", "CalibrationOptions", "CalibrationResult",
    "CalibrationStatus", "Camera", "CameraCalibrationOptions", "CameraCalibrationResult", "CameraCalibrator",
    "Context", "Dataset", "DatasetInfo", "DeviceInfo", "Error", "InvalidArgumentError", "InvalidInputError", "MissingFileError", "PermissionDeniedError", "Extrinsics", "ExtrinsicsFile", "FrameData", "MotionAccuracy",
    "Mosaic", "MosaicInfo", "MotionPair", "MotionProfile", "MountingChange", "MountingResponse", "PosegraphInit", "ReadoutSource", "Residuals", "RobustLoss", "RollPitch",
    "RollPitchOptions",
    "RollPitchResult", "SE2", "SimOptions", "SolverSummary", "StatsWriter", "Status", "Tracker",
    "TrackedDrive", "TrackerOptions", "TrackResult", "TrackStatus", "track_dataset", "bag_topics", "calibrate", "calibrate_dataset", "calibrate_residuals", "PairResiduals", "compose_extrinsics",
    "build_mosaic", "default_texture", "evaluate_motions", "list_devices", "load_motion_pairs", "posegraph_optimize", "read_plane", "read_stats", "read_tum", "STATS_COLUMNS",
    "save_motion_pairs", "sensor_motion", "simulate", "track_motions", "version", "write_tum"]
