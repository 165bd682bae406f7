"""The ctypes layer: finds and loads libplanarvo, mirrors include/planarvo/planarvo.h's structs
field by field and declares every function's signature. Private: use the names that
planarvo/__init__.py exports.

Keep the structures in step with the header: each one that begins with struct_size is versioned
(the library reads only the first struct_size bytes), so a newer library works with these, but a
field added here needs a library at least as new (see _MIN_VERSION).
"""
from __future__ import annotations

import ctypes
import ctypes.util
import glob
import os
import sys
from typing import Dict, List, Optional, Tuple, Type, TypeVar, cast

# The header version these structures mirror: a library older than this lacks fields used here.
_MIN_VERSION = (0, 2)

c_int32, c_int64, c_uint32, c_uint64 = ctypes.c_int32, ctypes.c_int64, ctypes.c_uint32, ctypes.c_uint64
c_double, c_size_t, c_char_p, c_void_p = ctypes.c_double, ctypes.c_size_t, ctypes.c_char_p, ctypes.c_void_p
c_enum = ctypes.c_int  # a C enum
P = ctypes.POINTER


class Region(ctypes.Structure):
    _fields_ = [("x", c_int32), ("y", c_int32), ("width", c_int32), ("height", c_int32)]


class Camera(ctypes.Structure):
    _fields_ = [("width", c_int32), ("height", c_int32)] + [
        (n, c_double) for n in ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")] + [
        ("roi", Region), ("rolling_shutter_readout", c_double), ("exposure_time", c_double)]


class Extrinsics(ctypes.Structure):
    _fields_ = [(n, c_double) for n in ("x", "y", "z", "roll", "pitch", "yaw")]


class ExtrinsicsFile(ctypes.Structure):
    _fields_ = [("value", Extrinsics), ("covariance", c_double * 36), ("estimated", c_int32 * 6),
                ("method", ctypes.c_char * 4097), ("notes", ctypes.c_char * 4097)]


class SE2(ctypes.Structure):
    _fields_ = [("x", c_double), ("y", c_double), ("theta", c_double)]


class Image(ctypes.Structure):
    _fields_ = [("data", c_void_p), ("width", c_int32), ("height", c_int32), ("stride", c_size_t),
                ("format", c_enum)]


PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, c_void_p, c_double, c_char_p)
LOG_FN = ctypes.CFUNCTYPE(None, c_void_p, c_char_p)


class DeviceInfo(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("index", c_int32), ("platform_name", ctypes.c_char * 128),
                ("device_name", ctypes.c_char * 128), ("device_type", ctypes.c_char * 16),
                ("device_version", ctypes.c_char * 128), ("opencl_c_version", ctypes.c_char * 64),
                ("driver_version", ctypes.c_char * 64), ("image_support", c_int32), ("fp64", c_int32),
                ("local_mem_size", c_uint64), ("global_mem_size", c_uint64),
                ("max_work_group_size", c_uint64), ("compute_units", c_uint32),
                ("driver_caches_kernels", c_int32)]


class ContextOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("device", c_char_p), ("cache_dir", c_char_p),
                ("disable_cache", c_int32), ("kernel_binaries_dir", c_char_p)]


class DatasetOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("video", c_char_p), ("verify_images", c_int32),
                ("progress", PROGRESS_FN), ("progress_user_data", c_void_p), ("allow_missing_images", c_int32),
                ("image_topic", c_char_p), ("camera_info_topic", c_char_p), ("camera_yaml", c_char_p),
                ("odometry_topic", c_char_p), ("groundtruth_topic", c_char_p), ("use_receive_time", c_int32)]


class DatasetInfo(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("frame_count", c_int64), ("first_timestamp", c_double),
                ("last_timestamp", c_double), ("camera", Camera), ("has_odometry", c_int32),
                ("has_direction", c_int32), ("has_groundtruth", c_int32), ("has_extrinsics", c_int32),
                ("has_extrinsics_gt", c_int32), ("extrinsics", Extrinsics), ("extrinsics_gt", Extrinsics),
                ("time_origin_ns", c_int64), ("is_bag", c_int32)]


class FrameData(ctypes.Structure):
    _fields_ = [("timestamp", c_double), ("has_odometry", c_int32), ("odometry", SE2),
                ("has_groundtruth", c_int32), ("groundtruth", SE2), ("has_direction", c_int32),
                ("direction", c_int32)]


class PlaneAttitude(ctypes.Structure):
    _fields_ = [(n, c_double) for n in ("timestamp", "roll", "pitch", "sigma_roll", "sigma_pitch")]


class FrameStats(ctypes.Structure):
    _fields_ = [("timestamp", c_double), ("vx", c_double), ("vy", c_double), ("omega", c_double),
                ("iterations", c_int32), ("final_cost", c_double), ("inlier_fraction", c_double), ("ms", c_double),
                ("status", c_char_p), ("has_attitude", c_int32), ("roll", c_double), ("pitch", c_double),
                ("sigma_roll", c_double), ("sigma_pitch", c_double), ("mounting_changed", c_int32)]


class SimOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("texture", c_char_p), ("texel_size", c_double),
                ("extrinsics", Extrinsics), ("camera", Camera), ("seconds", c_double), ("fps", c_double),
                ("seed", c_uint64), ("motion", c_enum), ("max_speed", c_double), ("max_turn_rate", c_double),
                ("pixel_noise", c_double), ("gain_variation", c_double), ("odometry_noise", c_double),
                ("supersampling", c_int32), ("progress", PROGRESS_FN), ("progress_user_data", c_void_p),
                ("min_turn_radius", c_double), ("readout_time", c_double), ("exposure_time", c_double),
                ("lamp_falloff", c_double), ("reflection", c_double), ("shadow", c_double),
                ("lean", c_double), ("bumps", c_double), ("knock_time", c_double), ("knock_roll", c_double),
                ("knock_pitch", c_double), ("knock_z", c_double), ("accept_unusual_extrinsics", c_int32)]


class TrackerOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("levels", c_int32), ("finest_level", c_int32),
                ("max_iterations", c_int32), ("keyframe_overlap", c_double), ("estimate_brightness", c_int32),
                ("level0_subsample", c_int32), ("flat_field", c_char_p), ("local_plane", c_int32),
                ("local_plane_prior_sigma", c_double), ("on_mounting_change", c_int32),
                ("mounting_min_step", c_double), ("accept_unusual_extrinsics", c_int32)]


class TrackResult(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("status", c_enum), ("reason", c_char_p), ("motion", SE2),
                ("covariance", c_double * 9), ("pose", SE2), ("iterations", c_int32 * 8), ("levels_used", c_int32),
                ("final_cost", c_double), ("inlier_fraction", c_double), ("overlap", c_double),
                ("keyframe", c_int32), ("ms", c_double), ("roll", c_double), ("pitch", c_double),
                ("attitude_covariance", c_double * 4), ("mounting", Extrinsics), ("attitude_observed", c_int32),
                ("mounting_changed", c_int32), ("mounting_refinement", c_int32),
                ("mounting_change_time", c_double), ("mounting_step", c_double * 4),
                ("mounting_step_sigma", c_double * 4), ("changed_mounting", Extrinsics)]


class MotionAccuracy(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("intervals", c_int32), ("distance", c_double),
                ("slope_linear", c_double), ("slope_angular", c_double), ("rms_translation", c_double),
                ("max_translation", c_double), ("rms_rotation", c_double), ("gross_errors", c_int32),
                ("endpoint_error", c_double), ("endpoint_drift", c_double), ("endpoint_heading", c_double)]


class SolverSummary(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("converged", c_int32), ("termination", ctypes.c_char * 256),
                ("iterations", c_int32), ("factorizations", c_int32), ("initial_chi2", c_double),
                ("final_chi2", c_double), ("seconds", c_double)]


class PosegraphOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("max_iterations", c_int32), ("init", c_enum), ("log", LOG_FN),
                ("log_user_data", c_void_p)]


class MotionPair(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("interval", c_double), ("sensor", SE2), ("has_odometry", c_int32),
                ("odometry", SE2), ("has_direction", c_int32), ("direction", c_int32),
                ("has_sensor_covariance", c_int32), ("sensor_covariance", c_double * 9),
                ("has_odometry_covariance", c_int32), ("odometry_covariance", c_double * 9)]


class CalibrationOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("method", c_enum), ("fix_scale", c_int32), ("fixed_scale", c_double),
                ("has_initial", c_int32), ("initial", c_double * 4), ("velocity_form", c_int32),
                ("max_iterations", c_int32), ("log", LOG_FN), ("log_user_data", c_void_p),
                ("sensor_sigma_relative", c_double), ("sensor_sigma_floor", c_double),
                ("sensor_sigma_theta", c_double), ("odometry_sigma_relative", c_double),
                ("odometry_sigma_floor", c_double), ("odometry_sigma_theta", c_double), ("loss", c_enum),
                ("loss_scale", c_double), ("gate_sigma", c_double), ("still_speed", c_double),
                ("estimate_odometry_noise", c_int32)]


class CalibrationResult(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("value", c_double * 4), ("covariance", c_double * 16),
                ("estimated", c_int32 * 4), ("observable", c_int32 * 4), ("ambiguous", c_int32),
                ("outliers", c_int32), ("ok", c_int32), ("unobservable_reason", ctypes.c_char * 512),
                ("summary", SolverSummary), ("total_iterations", c_int32), ("total_seconds", c_double),
                ("variance_factor", c_double)]


class PairResidual(ctypes.Structure):
    _fields_ = [("has_odometry", c_int32), ("outlier", c_int32), ("d", c_double * 3), ("covariance", c_double * 9),
                ("chi2", c_double)]


class OdometryNoise(ctypes.Structure):
    _fields_ = [("fitted", c_int32), ("variance", c_double * 9)]


class RollPitchOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("initial_roll", c_double), ("initial_pitch", c_double),
                ("max_frames", c_int32), ("min_keyframes", c_int32), ("max_keyframes", c_int32),
                ("keyframe_overlap", c_double), ("search", c_int32)]


class RollPitchResult(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("status", c_enum), ("reason", ctypes.c_char * 512),
                ("roll", c_double), ("pitch", c_double), ("covariance", c_double * 4), ("frames_used", c_int32),
                ("keyframes", c_int32), ("pairs", c_int32), ("seconds", c_double)]


class CameraCalibrationOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("method", c_enum), ("height", c_double),
                ("roll_pitch_frames", c_int32), ("has_initial", c_int32), ("initial", Extrinsics),
                ("estimate_roll_pitch", c_int32), ("graph", P(CalibrationOptions)), ("tracker", P(TrackerOptions)),
                ("progress", PROGRESS_FN), ("progress_user_data", c_void_p), ("readout", c_enum),
                ("accept_unusual_extrinsics", c_int32)]


class CameraCalibrationResult(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("status", c_enum), ("reason", ctypes.c_char * 512),
                ("extrinsics", Extrinsics), ("covariance", c_double * 36), ("estimated", c_int32 * 6),
                ("observable", c_int32 * 6), ("roll_pitch", RollPitchResult), ("graph", CalibrationResult),
                ("frames", c_int32), ("frames_ok", c_int32), ("frames_degraded", c_int32),
                ("frames_lost", c_int32), ("samples", c_int32), ("tracking_median_ms", c_double),
                ("seconds_decode", c_double), ("seconds_roll_pitch", c_double), ("seconds_tracking", c_double),
                ("seconds_graph", c_double), ("seconds_total", c_double), ("readout", c_double),
                ("readout_estimate", c_double), ("readout_sigma", c_double), ("readout_evaluations", c_int32),
                ("readout_frames", c_int32), ("readout_reason", ctypes.c_char * 256), ("seconds_readout", c_double),
                ("method", ctypes.c_char * 192)]


class MosaicOptions(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("resolution", c_double), ("max_range", c_double),
                ("frame_spacing", c_double), ("estimate_gain", c_int32), ("max_side", c_int32),
                ("progress", PROGRESS_FN), ("progress_user_data", c_void_p), ("accept_unusual_extrinsics", c_int32)]


class MosaicInfo(ctypes.Structure):
    _fields_ = [("struct_size", c_size_t), ("width", c_int32), ("height", c_int32), ("resolution", c_double),
                ("origin_x", c_double), ("origin_y", c_double), ("frames_given", c_int64), ("frames_used", c_int64),
                ("covered_pixels", c_int64), ("gain_min", c_double), ("gain_max", c_double),
                ("peak_tile_bytes", c_int64), ("seconds_decode", c_double), ("seconds_warp", c_double),
                ("seconds_blend", c_double), ("seconds_total", c_double)]


_S = TypeVar("_S", bound=ctypes.Structure)


def sized(struct_type: Type[_S]) -> _S:
    """A zeroed instance of a versioned struct with its struct_size set."""
    s = struct_type()
    s.struct_size = ctypes.sizeof(struct_type)
    return s


# The C types of the library's signature table (planarvo_api_signatures) as ctypes types.
_SCALARS: Dict[str, Optional[Type[ctypes._CData]]] = {
    "int": ctypes.c_int, "int32_t": c_int32, "int64_t": c_int64, "size_t": c_size_t, "double": c_double,
    "float": ctypes.c_float, "uint8_t": ctypes.c_uint8, "void": None}
_CALLBACKS = {"planarvo_progress_fn": PROGRESS_FN, "planarvo_log_fn": LOG_FN}


def _struct_class(c_name: str) -> Optional[Type[ctypes.Structure]]:
    """The mirror of struct planarvo_<name> in this module (planarvo_motion_pair -> MotionPair), or None."""
    name = "".join(w.capitalize() for w in c_name[len("planarvo_"):].split("_")).replace("Se2", "SE2")
    cls = globals().get(name)
    return cls if isinstance(cls, type) and issubclass(cls, ctypes.Structure) else None


def _ctype(c_type: str) -> Optional[Type[ctypes._CData]]:
    """The ctypes type of a C type of the signature table; KeyError when this module cannot
    express it (a struct without a mirror)."""
    t = c_type.replace("const ", "").strip()
    if t.endswith("]"):  # an array parameter is a pointer
        t = t[:t.index("[")] + "*"
    stars = len(t) - len(t.rstrip("*"))
    base = t.rstrip("*")
    if stars == 0:
        if base in _SCALARS:
            return _SCALARS[base]
        if base in _CALLBACKS:
            return _CALLBACKS[base]
        if base.startswith("planarvo_") and _struct_class(base) is None:
            return c_enum  # planarvo_status and the other enums
        raise KeyError(c_type)
    if base == "char" and stars == 1:
        return c_char_p
    if base == "void" and stars == 1:
        return c_void_p
    scalar = _SCALARS.get(base)  # None for void, whose pointer is c_void_p (above)
    if scalar is not None and stars == 1:
        return P(scalar)
    cls = _struct_class(base)
    if cls is not None and stars == 1:
        return P(cls)
    if base.startswith("planarvo_") and cls is None:  # an opaque handle
        return c_void_p if stars == 1 else P(c_void_p)
    raise KeyError(c_type)


def _signatures(table: str) -> Dict[str, Tuple[Optional[Type[ctypes._CData]], List[Type[ctypes._CData]]]]:
    """name -> (restype, argtypes) for each function of the table that this module can declare."""
    out = {}
    for line in table.splitlines():
        if not line:
            continue
        name, ret, params = line.split("|")
        try:
            # A parameter is never void: _ctype gives its type.
            out[name] = (_ctype(ret), [cast("Type[ctypes._CData]", _ctype(p)) for p in params.split(",") if p])
        except KeyError:
            pass  # a struct this module does not mirror: the function is not declared
    return out


def _candidates() -> List[str]:
    """Where to look for the library, in order (see load_library)."""
    env = os.environ.get("PLANARVO_LIBRARY")
    if env:
        return [env]
    found = []
    # Installed by cmake --install: <prefix>/lib/python3/dist-packages/planarvo -> <prefix>/lib
    # (CMAKE_INSTALL_LIBDIR lib) or <prefix>/lib/<multiarch> (Debian's GNUInstallDirs under /usr).
    libdir = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
    multiarch = getattr(sys.implementation, "_multiarch", None)
    dirs = [libdir] + ([os.path.join(libdir, multiarch)] if multiarch else []) + sorted(
        d for d in glob.glob(os.path.join(libdir, "*-linux-*")) if os.path.isdir(d))
    for d in dirs:
        for name in ("libplanarvo.so", "libplanarvo.so.%d.%d" % _MIN_VERSION):
            path = os.path.join(d, name)
            if os.path.exists(path) and path not in found:
                found.append(path)
    system = ctypes.util.find_library("planarvo")
    if system:
        found.append(system)
    found.append("libplanarvo.so.%d.%d" % _MIN_VERSION)  # the loader's own search (LD_LIBRARY_PATH)
    return found


def load_library() -> ctypes.CDLL:
    """Loads libplanarvo: $PLANARVO_LIBRARY (a path) when set, else the library installed beside
    this package (<prefix>/lib or <prefix>/lib/<multiarch>), else the system's search
    (ctypes.util.find_library, LD_LIBRARY_PATH). Raises ImportError saying where it looked."""
    tried = []
    lib: Optional[ctypes.CDLL] = None
    for path in _candidates():
        try:
            lib = ctypes.CDLL(path)
            break
        except OSError as e:
            tried.append("%s (%s)" % (path, e))
    if lib is None:
        raise ImportError("planarvo: cannot load libplanarvo; set PLANARVO_LIBRARY to the path of libplanarvo.so. "
                          "Tried: " + "; ".join(tried))
    try:
        lib.planarvo_api_signatures.restype = c_char_p
        lib.planarvo_api_signatures.argtypes = []
        for name, (restype, argtypes) in _signatures(lib.planarvo_api_signatures().decode()).items():
            function = getattr(lib, name)
            function.restype, function.argtypes = restype, argtypes
    except AttributeError as e:
        raise ImportError("planarvo: %s is not a usable libplanarvo: %s" % (lib._name, e)) from None
    number = lib.planarvo_version_number()
    version = (number // 10000, number // 100 % 100)
    if version[0] != _MIN_VERSION[0] or version < _MIN_VERSION:
        raise ImportError("planarvo: %s is version %s; this package needs %d.%d or a later %d.x" % (
            lib._name, lib.planarvo_version_string().decode(), *_MIN_VERSION, _MIN_VERSION[0]))
    return lib


lib = load_library()
