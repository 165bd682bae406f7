"""The library's version, its OpenCL devices and the Context that holds one."""
from __future__ import annotations

import ctypes
import os
from dataclasses import dataclass, fields
from typing import List, Optional, Sequence, Union, cast

from . import _native as N
from ._errors import Status, _check
from ._handle import _Handle
from ._native import lib
from ._util import PathLike, _names, _path


def version() -> str:
    """The loaded library's version, "major.minor.patch"."""
    return cast(str, lib.planarvo_version_string().decode())


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
    driver_caches_kernels: bool  # the driver keeps compiled kernels itself (PoCL): no program cache by default

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
        return os.fsdecode(lib.planarvo_context_cache_dir(self._h()))

    def prepare_kernels(self, uses: Optional[str] = None) -> None:
        """Builds (or loads) the kernel programs now, so that the first frame does not pay for it:
        every one, or those of uses ("track", "calibrate", "simulate", comma-separated)."""
        if uses is None:
            _check(lib.planarvo_context_prepare_kernels(self._h()))
        else:
            _check(lib.planarvo_context_prepare_kernels_for(self._h(), uses.encode()))

    def __repr__(self) -> str:
        if self.closed:
            return "<planarvo.Context (closed)>"
        d = self.device
        return "<planarvo.Context on %s (%s), kernel cache %s>" % (d.device_name, d.platform_name,
                                                                   self.cache_dir or "off")

    def export_kernels(self, directory: PathLike, uses: Union[None, str, Sequence[str]] = None) -> int:
        """Writes the kernel binaries for this device into directory (for kernel_binaries_dir):
        all of them, or those that uses ("track", "calibrate", "simulate"; one name or several)
        need. Returns the count."""
        n = ctypes.c_size_t(0)
        _check(lib.planarvo_context_export_kernels_for(self._h(), _path(directory),
                                                        _names(uses), ctypes.byref(n)))
        return n.value
