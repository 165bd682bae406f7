#!/usr/bin/env python3
"""A Python caller of planarvo through ctypes: lists the OpenCL devices, creates a context on the
default device (or the one named by the first argument) and prints it.

    PLANARVO_LIBRARY=/path/to/libplanarvo.so python3 list_devices.py [DEVICE]

Without PLANARVO_LIBRARY the system's library search path is used (libplanarvo.so.0.2).
"""
import ctypes
import os
import sys
from typing import Optional


class DeviceInfo(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_size_t),
        ("index", ctypes.c_int32),
        ("platform_name", ctypes.c_char * 128),
        ("device_name", ctypes.c_char * 128),
        ("device_type", ctypes.c_char * 16),
        ("device_version", ctypes.c_char * 128),
        ("opencl_c_version", ctypes.c_char * 64),
        ("driver_version", ctypes.c_char * 64),
        ("image_support", ctypes.c_int32),
        ("fp64", ctypes.c_int32),
        ("local_mem_size", ctypes.c_uint64),
        ("global_mem_size", ctypes.c_uint64),
        ("max_work_group_size", ctypes.c_uint64),
        ("compute_units", ctypes.c_uint32),
    ]


class ContextOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_size_t),
        ("device", ctypes.c_char_p),
        ("cache_dir", ctypes.c_char_p),
        ("disable_cache", ctypes.c_int32),
        ("kernel_binaries_dir", ctypes.c_char_p),
    ]


class PlanarvoError(RuntimeError):
    pass


def load(path: Optional[str] = None) -> ctypes.CDLL:
    lib = ctypes.CDLL(path or os.environ.get("PLANARVO_LIBRARY") or "libplanarvo.so.0.2")
    lib.planarvo_version_string.restype = ctypes.c_char_p
    lib.planarvo_last_error.restype = ctypes.c_char_p
    lib.planarvo_status_name.restype = ctypes.c_char_p
    lib.planarvo_status_name.argtypes = [ctypes.c_int]
    lib.planarvo_list_devices.argtypes = [ctypes.POINTER(DeviceInfo), ctypes.c_size_t,
                                          ctypes.POINTER(ctypes.c_size_t)]
    lib.planarvo_context_options_init.argtypes = [ctypes.POINTER(ContextOptions)]
    lib.planarvo_context_create.argtypes = [ctypes.POINTER(ContextOptions), ctypes.POINTER(ctypes.c_void_p)]
    lib.planarvo_context_device.argtypes = [ctypes.c_void_p, ctypes.POINTER(DeviceInfo)]
    lib.planarvo_context_destroy.argtypes = [ctypes.c_void_p]
    lib.planarvo_context_destroy.restype = None
    return lib


def check(lib: ctypes.CDLL, status: int) -> None:
    if status != 0:
        raise PlanarvoError("%s: %s" % (lib.planarvo_status_name(status).decode(),
                                        lib.planarvo_last_error().decode()))


def main() -> int:
    lib = load()
    print("planarvo", lib.planarvo_version_string().decode())
    count = ctypes.c_size_t(0)
    check(lib, lib.planarvo_list_devices(None, 0, ctypes.byref(count)))
    devices = (DeviceInfo * max(count.value, 1))()
    for d in devices:
        d.struct_size = ctypes.sizeof(DeviceInfo)
    check(lib, lib.planarvo_list_devices(devices, count.value, ctypes.byref(count)))
    for d in devices[:count.value]:
        print("device %d: %s / %s (%s)" % (d.index, d.platform_name.decode(), d.device_name.decode(),
                                           d.device_type.decode()))

    options = ContextOptions()
    lib.planarvo_context_options_init(ctypes.byref(options))
    if len(sys.argv) > 1:
        options.device = sys.argv[1].encode()
    context = ctypes.c_void_p()
    try:
        check(lib, lib.planarvo_context_create(ctypes.byref(options), ctypes.byref(context)))
    except PlanarvoError as e:
        print(e, file=sys.stderr)
        return 3 if "NO_DEVICE" in str(e) else 1
    info = DeviceInfo()
    info.struct_size = ctypes.sizeof(DeviceInfo)
    check(lib, lib.planarvo_context_device(context, ctypes.byref(info)))
    print("context on: %s (%s)" % (info.device_name.decode(), info.device_version.decode()))
    lib.planarvo_context_destroy(context)
    return 0


if __name__ == "__main__":
    sys.exit(main())
