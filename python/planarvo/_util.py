"""Small helpers shared by the modules: path and string arguments, Python callbacks as C
callbacks, matrices to and from C arrays, and option structs from dataclasses."""
from __future__ import annotations

import contextlib
import ctypes
import enum
import os
import signal
import sys
import threading
from dataclasses import fields
from types import FrameType
from typing import TYPE_CHECKING, Any, Callable, Iterator, Optional, Sequence, Type, TypeVar, Union, cast

import numpy as np

from . import _native as N
from ._native import lib

if TYPE_CHECKING:
    from numpy.typing import ArrayLike as ArrayLike, NDArray as NDArray
else:
    try:  # the modules' annotations name these; imported so that typing.get_type_hints resolves them
        from numpy.typing import ArrayLike, NDArray
    except ImportError:  # numpy before 1.21: the annotations stay strings, nothing here evaluates them
        ArrayLike = NDArray = None

# Resolved here, so that typing.get_type_hints works in every module that uses it.
if sys.version_info >= (3, 9):
    PathLike = Union[str, os.PathLike[str]]
else:  # Python 3.8: os.PathLike is not subscriptable at run time
    PathLike = Union[str, "os.PathLike[str]"]
ProgressFn = Callable[[float, str], Optional[bool]]  # return True to cancel
LogFn = Callable[[str], None]
_T = TypeVar("_T")
_S = TypeVar("_S", bound=ctypes.Structure)


def _path(p: PathLike) -> bytes:
    return os.fsencode(p)


def _names(names: Union[None, str, Sequence[str]]) -> Optional[bytes]:
    """One name or several as the C API's comma-separated list; None (or empty) for none."""
    if not names:
        return None
    return (names if isinstance(names, str) else ",".join(names)).encode()


def _require(value: object, cls: Type[_T], what: str) -> _T:
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

    def __init__(self, fn: Union[None, ProgressFn, LogFn], kind: Type[ctypes._FuncPointer]):
        self.fn, self.interrupted = fn, False
        self.error: Optional[BaseException] = None
        if kind is N.PROGRESS_FN:
            self.c = kind(self._progress)
        elif fn is None:
            # NULL; typeshed's _FuncPointer lacks this no-argument form
            self.c = cast("Callable[[], ctypes._FuncPointer]", kind)()
        else:
            self.c = kind(self._log)

    def _progress(self, _user: Optional[int], fraction: float, stage: Optional[bytes]) -> int:
        if self.interrupted:
            if self.error is None:
                self.error = KeyboardInterrupt()
            return 1
        if self.fn is None:
            return 0
        try:  # fn is a ProgressFn (kind PROGRESS_FN)
            return 1 if cast(ProgressFn, self.fn)(fraction, stage.decode(errors="replace") if stage else "") else 0
        except BaseException as e:  # noqa: B902 - never let an exception unwind through C
            self.error = e
            return 1

    def _log(self, _user: Optional[int], line: Optional[bytes]) -> None:
        if self.error is None:
            try:
                # fn is a LogFn (kind LOG_FN, and given: else the C callback is NULL)
                cast(LogFn, self.fn)(line.decode(errors="replace") if line else "")
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

        def mark(_signum: int, _frame: Optional[FrameType]) -> None:
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


def _matrix(values: ctypes.Array[ctypes.c_double], n: int) -> NDArray[np.float64]:
    return np.array(values[:n * n], dtype=np.float64).reshape(n, n)


def _fill_matrix(dst: ctypes.Array[ctypes.c_double], value: ArrayLike, n: int, what: str) -> None:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != (n, n):
        raise ValueError("%s: expected a (%d, %d) array, got shape %s" % (what, n, n, a.shape))
    for i, v in enumerate(a.ravel()):
        dst[i] = v


_INT_RANGES = {ctypes.c_int32: (-2**31, 2**31 - 1), ctypes.c_int64: (-2**63, 2**63 - 1),
               ctypes.c_uint32: (0, 2**32 - 1), ctypes.c_size_t: (0, 2**64 - 1)}


def _set_field(c: ctypes.Structure, name: str, v: object) -> None:
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


def _c_options(struct_type: Type[_S], init_name: str, options: Any, skip: Sequence[str] = ()) -> _S:
    """The C option struct: the library's defaults (init), then every field of options (one of the
    package's option dataclasses, or None) that is not None."""
    c = N.sized(struct_type)
    getattr(lib, init_name)(ctypes.byref(c))
    if options is not None:
        for f in fields(options):
            v = getattr(options, f.name)
            if v is None or f.name in skip:
                continue
            _set_field(c, f.name, v)
    return c
