"""Small helpers shared by the modules: path and string arguments, Python callbacks as C
callbacks, matrices to and from C arrays, and option structs from dataclasses."""
from __future__ import annotations

import contextlib
import ctypes
import enum
import os
import signal
import threading
from dataclasses import fields
from typing import Any, Callable, Iterator, Optional, Sequence, Union

import numpy as np

from . import _native as N
from ._native import lib

try:
    # Resolved here, so that typing.get_type_hints works in every module that uses it.
    PathLike = Union[str, os.PathLike[str]]
except TypeError:  # Python 3.8: os.PathLike is not subscriptable at run time
    PathLike = Union[str, "os.PathLike[str]"]
ProgressFn = Callable[[float, str], Optional[bool]]  # return True to cancel
LogFn = Callable[[str], None]


def _path(p: PathLike) -> bytes:
    return os.fsencode(p)


def _names(names: Union[None, str, Sequence[str]]) -> Optional[bytes]:
    """One name or several as the C API's comma-separated list; None (or empty) for none."""
    if not names:
        return None
    return (names if isinstance(names, str) else ",".join(names)).encode()


def _require(value: Any, cls: type, what: str) -> Any:
    """value itself when it is a cls, else ValueError naming what was expected (a data set
    without extrinsics.yaml gives info.extrinsics None, for example)."""
    if not isinstance(value, cls):
        raise ValueError("%s: expected a planarvo.%s, got %s" % (what, cls.__name__, type(value).__name__))
    return value


def _opt(s: Optional[str]) -> Optional[bytes]:
    return None if s is None else s.encode()


class _Callback:
    """A Python progress or log function as a C callback, kept alive for the call; an exception
    raised in it cancels the call (progress) and is re-raised after it. A progress callback is
    always given to the library, with or without fn, so that Ctrl-C (interruptible()) can cancel
    the call at its next progress report."""

    def __init__(self, fn: Optional[Callable], kind):
        self.fn, self.error, self.interrupted = fn, None, False
        if kind is N.PROGRESS_FN:
            self.c = kind(self._progress)
        elif fn is None:
            self.c = kind()  # NULL
        else:
            self.c = kind(self._log)

    def _progress(self, _user, fraction, stage):
        if self.interrupted:
            if self.error is None:
                self.error = KeyboardInterrupt()
            return 1
        if self.fn is None:
            return 0
        try:
            return 1 if self.fn(fraction, stage.decode(errors="replace") if stage else "") else 0
        except BaseException as e:  # noqa: B902 - never let an exception unwind through C
            self.error = e
            return 1

    def _log(self, _user, line):
        if self.error is None:
            try:
                self.fn(line.decode(errors="replace") if line else "")
            except BaseException as e:  # noqa: B902
                self.error = e

    @contextlib.contextmanager
    def interruptible(self) -> Iterator[None]:
        """Around a long C call in the main thread: Ctrl-C only marks the call interrupted (no
        exception can cross the C frames), the progress callback cancels it at its next report,
        and reraise() raises KeyboardInterrupt after it returns. A SIGINT handler of the user's
        own is left alone."""
        if (threading.current_thread() is not threading.main_thread()
                or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
            yield
            return

        def mark(_signum, _frame):
            self.interrupted = True

        signal.signal(signal.SIGINT, mark)
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, signal.default_int_handler)
            if self.interrupted and self.error is None:
                self.error = KeyboardInterrupt()
            self.interrupted = False

    def reraise(self) -> None:
        # Raised once: a callback reused by later calls (CameraCalibrator) starts clean again.
        err, self.error = self.error, None
        if err is not None:
            raise err


def _matrix(values, n: int) -> np.ndarray:
    return np.array(values[:n * n], dtype=np.float64).reshape(n, n)


def _fill_matrix(dst, value, n: int, what: str) -> None:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != (n, n):
        raise ValueError("%s: expected a (%d, %d) array, got shape %s" % (what, n, n, a.shape))
    for i, v in enumerate(a.ravel()):
        dst[i] = v


_INT_RANGES = {ctypes.c_int32: (-2**31, 2**31 - 1), ctypes.c_int64: (-2**63, 2**63 - 1),
               ctypes.c_uint32: (0, 2**32 - 1), ctypes.c_size_t: (0, 2**64 - 1)}


def _set_field(c, name: str, v: Any) -> None:
    """Sets one field of a C struct, refusing (ValueError) what ctypes would silently truncate:
    an integer out of the field's range, or a non-integer for an integer field."""
    ctype = dict(c._fields_)[name]
    if ctype in _INT_RANGES:
        if isinstance(v, (bool, enum.IntEnum)):
            v = int(v)
        elif isinstance(v, (int, np.integer)):
            v = int(v)
        else:
            raise ValueError("%s: expected an integer, got %r" % (name, v))
        lo, hi = _INT_RANGES[ctype]
        if not lo <= v <= hi:
            raise ValueError("%s: %d is outside the C field's range [%d, %d]" % (name, v, lo, hi))
    elif ctype is ctypes.c_double:
        if isinstance(v, (bool, str, bytes)) or not isinstance(v, (int, float, np.integer, np.floating)):
            raise ValueError("%s: expected a number, got %r" % (name, v))
        v = float(v)
    setattr(c, name, v)


def _c_options(struct_type, init_name: str, options: Any, skip: Sequence[str] = ()):
    """The C option struct: the library's defaults (init), then every field of options that is
    not None."""
    c = N.sized(struct_type)
    getattr(lib, init_name)(ctypes.byref(c))
    if options is not None:
        for f in fields(options):
            v = getattr(options, f.name)
            if v is None or f.name in skip:
                continue
            _set_field(c, f.name, v)
    return c
