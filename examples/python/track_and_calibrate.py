#!/usr/bin/env python3
"""A Python caller of planarvo through ctypes (no other module needed): tracks a data set with given
camera extrinsics and writes the robot's trajectory (TUM), then calibrates the camera's
extrinsics from the same drive and prints them with their standard deviations. The same program
as examples/c/track_and_calibrate.c.

    python3 track_and_calibrate.py DATASET EXTRINSICS.yaml TRAJECTORY.txt [CALIBRATED.yaml]

The library: $PLANARVO_LIBRARY (a path to libplanarvo.so), else the one the system's search
finds (ctypes.util.find_library, then libplanarvo.so.0.2). DATASET is a data set directory
(docs/formats.md; `planarvo simulate --out DIR` makes one). The calibration uses the data set's
wheel odometry when it has some, else the nonholonomic method with its direction labels and the
camera height from EXTRINSICS.yaml. Exit status: 0 done; 1 a step ran but failed (no OpenCL
device, a file that could not be written, a calibration the drive does not determine); 2 bad
arguments or input files.

The structures below mirror include/planarvo/planarvo.h field by field: keep them in step with
the header of the library you load. Each struct that begins with struct_size must have it set to
ctypes.sizeof(the structure) before a call.
"""
import ctypes
import ctypes.util
import math
import os
import sys
from typing import List, Optional

c_int32, c_int64, c_double, c_size_t = ctypes.c_int32, ctypes.c_int64, ctypes.c_double, ctypes.c_size_t
c_enum = ctypes.c_int  # a C enum


class Region(ctypes.Structure):
    _fields_ = [(n, c_int32) for n in ("x", "y", "width", "height")]


class Camera(ctypes.Structure):
    _fields_ = [("width", c_int32), ("height", c_int32)] + [
        (n, c_double) for n in ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")] + [
        ("roi", Region), ("rolling_shutter_readout", c_double), ("exposure_time", c_double)]


class Extrinsics(ctypes.Structure):
    _fields_ = [(n, c_double) for n in ("x", "y", "z", "roll", "pitch", "yaw")]


class SE2(ctypes.Structure):
    _fields_ = [("x", c_double), ("y", c_double), ("theta", c_double)]


class Image(ctypes.Structure):
    _fields_ = [("data", ctypes.c_void_p), ("width", c_int32), ("height", c_int32), ("stride", c_size_t),
                ("format", c_enum)]


class DatasetInfo(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("frame_count", c_int64), ("first_timestamp", c_double),
                ("last_timestamp", c_double), ("camera", Camera), ("has_odometry", c_int32),
                ("has_direction", c_int32), ("has_groundtruth", c_int32), ("has_extrinsics", c_int32),
                ("has_extrinsics_gt", c_int32), ("extrinsics", Extrinsics), ("extrinsics_gt", Extrinsics)]


class FrameData(ctypes.Structure):
    _fields_ = [("timestamp", c_double), ("has_odometry", c_int32), ("odometry", SE2),
                ("has_groundtruth", c_int32), ("groundtruth", SE2), ("has_direction", c_int32),
                ("direction", c_int32)]


class TrackResult(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("status", c_enum), ("reason", ctypes.c_char_p), ("motion", SE2),
                ("covariance", c_double * 9), ("pose", SE2), ("iterations", c_int32 * 8), ("levels_used", c_int32),
                ("final_cost", c_double), ("inlier_fraction", c_double), ("overlap", c_double),
                ("keyframe", c_int32), ("ms", c_double)]


class SolverSummary(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("converged", c_int32), ("termination", ctypes.c_char * 256),
                ("iterations", c_int32), ("factorizations", c_int32), ("initial_chi2", c_double),
                ("final_chi2", c_double), ("seconds", c_double)]


class CalibrationResult(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("value", c_double * 4), ("covariance", c_double * 16),
                ("estimated", c_int32 * 4), ("observable", c_int32 * 4), ("ambiguous", c_int32),
                ("outliers", c_int32), ("ok", c_int32), ("unobservable_reason", ctypes.c_char * 512),
                ("summary", SolverSummary), ("total_iterations", c_int32), ("total_seconds", c_double),
                ("variance_factor", c_double)]


class RollPitchResult(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("status", c_enum), ("reason", ctypes.c_char * 512),
                ("roll", c_double), ("pitch", c_double), ("covariance", c_double * 4), ("frames_used", c_int32),
                ("keyframes", c_int32), ("pairs", c_int32), ("seconds", c_double)]


PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, c_double, ctypes.c_char_p)


class CameraCalibrationOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("method", c_enum), ("height", c_double),
                ("roll_pitch_frames", c_int32), ("has_initial", c_int32), ("initial", Extrinsics),
                ("estimate_roll_pitch", c_int32),
                ("graph", ctypes.c_void_p),    # const planarvo_calibration_options*: NULL, the defaults
                ("tracker", ctypes.c_void_p),  # const planarvo_tracker_options*: NULL, the defaults
                ("progress", PROGRESS_FN), ("progress_user_data", ctypes.c_void_p)]


class CameraCalibrationResult(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("status", c_enum), ("reason", ctypes.c_char * 512),
                ("extrinsics", Extrinsics), ("covariance", c_double * 36), ("estimated", c_int32 * 6),
                ("observable", c_int32 * 6), ("roll_pitch", RollPitchResult), ("graph", CalibrationResult),
                ("frames", c_int32), ("frames_ok", c_int32), ("frames_degraded", c_int32),
                ("frames_lost", c_int32), ("samples", c_int32), ("tracking_median_ms", c_double),
                ("seconds_decode", c_double), ("seconds_roll_pitch", c_double), ("seconds_tracking", c_double),
                ("seconds_graph", c_double), ("seconds_total", c_double)]


# planarvo_status values used here, and other constants of the header.
OK, INVALID_ARGUMENT, INVALID_INPUT = 0, 1, 2
TRACK_LOST = 3
CALIBRATE_ODOMETRY, CALIBRATE_NONHOLONOMIC = 0, 1
P = ctypes.POINTER
VOID_P = ctypes.c_void_p


def load_library() -> ctypes.CDLL:
    path = os.environ.get("PLANARVO_LIBRARY") or ctypes.util.find_library("planarvo") or "libplanarvo.so.0.2"
    lib = ctypes.CDLL(path)
    signatures = {
        "planarvo_last_error": (ctypes.c_char_p, []),
        "planarvo_extrinsics_load": (c_enum, [ctypes.c_char_p, P(Extrinsics)]),
        "planarvo_extrinsics_save": (c_enum, [ctypes.c_char_p, P(Extrinsics), P(c_double), ctypes.c_char_p,
                                              ctypes.c_char_p, ctypes.c_char_p]),
        "planarvo_dataset_open": (c_enum, [ctypes.c_char_p, VOID_P, P(VOID_P)]),
        "planarvo_dataset_destroy": (None, [VOID_P]),
        "planarvo_dataset_info_get": (c_enum, [VOID_P, P(DatasetInfo)]),
        "planarvo_dataset_frame_data": (c_enum, [VOID_P, c_int64, P(FrameData)]),
        "planarvo_dataset_frame": (c_enum, [VOID_P, c_int64, P(Image)]),
        "planarvo_context_create": (c_enum, [VOID_P, P(VOID_P)]),
        "planarvo_context_destroy": (None, [VOID_P]),
        "planarvo_tracker_create": (c_enum, [VOID_P, P(Camera), P(Extrinsics), VOID_P, P(VOID_P)]),
        "planarvo_tracker_destroy": (None, [VOID_P]),
        "planarvo_tracker_track": (c_enum, [VOID_P, P(Image), c_double, P(TrackResult)]),
        "planarvo_write_tum": (c_enum, [ctypes.c_char_p, P(c_double), P(SE2), c_size_t]),
        "planarvo_camera_calibration_options_init": (None, [P(CameraCalibrationOptions)]),
        "planarvo_calibrate_dataset": (c_enum, [VOID_P, VOID_P, P(CameraCalibrationOptions),
                                                P(CameraCalibrationResult)]),
    }
    for name, (restype, argtypes) in signatures.items():
        function = getattr(lib, name)
        function.restype, function.argtypes = restype, argtypes
    return lib


class Failure(Exception):
    """A failed call: the message and the exit status it gives."""

    def __init__(self, message: str, exit_status: int) -> None:
        super().__init__(message)
        self.exit_status = exit_status


def check(lib: ctypes.CDLL, status: int, what: str) -> None:
    if status != OK:
        exit_status = 2 if status in (INVALID_ARGUMENT, INVALID_INPUT) else 1
        raise Failure("%s: %s" % (what, lib.planarvo_last_error().decode(errors="replace")), exit_status)


def track(lib: ctypes.CDLL, context: ctypes.c_void_p, dataset: ctypes.c_void_p, info: DatasetInfo,
          extrinsics: Extrinsics, trajectory_path: str) -> None:
    """Tracks every frame and writes the poses (relative to the first frame) as a TUM trajectory."""
    n = info.frame_count
    times, poses = (c_double * n)(), (SE2 * n)()
    tracker = VOID_P()
    check(lib, lib.planarvo_tracker_create(context, ctypes.byref(info.camera), ctypes.byref(extrinsics), None,
                                           ctypes.byref(tracker)), "planarvo_tracker_create")
    lost = 0
    try:
        for i in range(n):
            data, image, result = FrameData(), Image(), TrackResult()
            result.struct_size = ctypes.sizeof(TrackResult)
            check(lib, lib.planarvo_dataset_frame_data(dataset, i, ctypes.byref(data)), "tracking")
            check(lib, lib.planarvo_dataset_frame(dataset, i, ctypes.byref(image)), "tracking")
            check(lib, lib.planarvo_tracker_track(tracker, ctypes.byref(image), data.timestamp, ctypes.byref(result)),
                  "tracking")
            times[i], poses[i] = data.timestamp, result.pose
            lost += result.status == TRACK_LOST
    finally:
        lib.planarvo_tracker_destroy(tracker)
    check(lib, lib.planarvo_write_tum(trajectory_path.encode(), times, poses, n), trajectory_path)
    last = poses[n - 1] if n else SE2()
    print("tracked %d frames (%d lost); last pose x %.4f m, y %.4f m, heading %.3f deg; wrote %s"
          % (n, lost, last.x, last.y, math.degrees(last.theta), trajectory_path))


def calibrate(lib: ctypes.CDLL, context: ctypes.c_void_p, dataset: ctypes.c_void_p, info: DatasetInfo, height: float,
              out_path: Optional[str]) -> None:
    """Calibrates the extrinsics from the drive, prints them and writes them to out_path if given."""
    names = ("x", "y", "z", "roll", "pitch", "yaw")
    options = CameraCalibrationOptions()
    lib.planarvo_camera_calibration_options_init(ctypes.byref(options))
    if not info.has_odometry:
        if not info.has_direction:
            raise Failure("the data set has neither odometry.txt nor direction.txt: nothing to calibrate against", 2)
        options.method, options.height = CALIBRATE_NONHOLONOMIC, height  # it cannot see the height
    result = CameraCalibrationResult()
    result.struct_size = ctypes.sizeof(CameraCalibrationResult)
    check(lib, lib.planarvo_calibrate_dataset(context, dataset, ctypes.byref(options), ctypes.byref(result)),
          "calibration")
    print("calibrated extrinsics (%s method), standard deviations:"
          % ("odometry" if options.method == CALIBRATE_ODOMETRY else "nonholonomic"))
    for i, name in enumerate(names):
        angle = i >= 3
        scale = 180.0 / math.pi if angle else 1000.0  # degrees, millimetres
        value = getattr(result.extrinsics, name) * scale
        unit = "deg" if angle else "mm "
        if result.estimated[i]:
            print("  %-5s %10.3f %s +- %.3f" % (name, value, unit, math.sqrt(result.covariance[i * 7]) * scale))
        else:
            print("  %-5s %10.3f %s (given)" % (name, value, unit))
    if out_path:
        estimated = ",".join(n for i, n in enumerate(names) if result.estimated[i])
        check(lib, lib.planarvo_extrinsics_save(out_path.encode(), ctypes.byref(result.extrinsics), result.covariance,
                                                estimated.encode(), b"planarvo_calibrate_dataset",
                                                b"examples/python/track_and_calibrate.py"), out_path)
        print("wrote %s" % out_path)


def main(argv: List[str]) -> int:
    if len(argv) not in (4, 5):
        print("usage: track_and_calibrate.py DATASET EXTRINSICS.yaml TRAJECTORY.txt [CALIBRATED.yaml]",
              file=sys.stderr)
        return 2
    try:
        lib = load_library()
    except OSError as e:
        print("track_and_calibrate.py: cannot load libplanarvo (set PLANARVO_LIBRARY): %s" % e, file=sys.stderr)
        return 1
    dataset, context = VOID_P(), VOID_P()
    try:
        extrinsics = Extrinsics()
        check(lib, lib.planarvo_extrinsics_load(argv[2].encode(), ctypes.byref(extrinsics)), argv[2])
        check(lib, lib.planarvo_dataset_open(argv[1].encode(), None, ctypes.byref(dataset)), argv[1])
        info = DatasetInfo()
        info.struct_size = ctypes.sizeof(DatasetInfo)
        check(lib, lib.planarvo_dataset_info_get(dataset, ctypes.byref(info)), argv[1])
        print("%s: %d frames, %dx%d, %.2f s" % (argv[1], info.frame_count, info.camera.width, info.camera.height,
                                                 info.last_timestamp - info.first_timestamp))
        # The default device: PLANARVO_DEVICE, else the first GPU or accelerator, else the first one.
        check(lib, lib.planarvo_context_create(None, ctypes.byref(context)), "planarvo_context_create")
        track(lib, context, dataset, info, extrinsics, argv[3])
        calibrate(lib, context, dataset, info, extrinsics.z, argv[4] if len(argv) > 4 else None)
        return 0
    except Failure as e:
        print("track_and_calibrate.py: %s" % e, file=sys.stderr)
        return e.exit_status
    finally:
        lib.planarvo_context_destroy(context)
        lib.planarvo_dataset_destroy(dataset)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
