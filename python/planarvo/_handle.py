"""C handles owned by Python objects: destroyed exactly once, dependants first."""
from __future__ import annotations

import ctypes
import weakref
from types import TracebackType
from typing import Callable, Optional, Type, TypeVar

from ._native import lib

_H = TypeVar("_H", bound="_Handle")


def _release(destroy: Callable[[ctypes.c_void_p], None], handle: ctypes.c_void_p, _keep_alive: object) -> None:
    destroy(handle)


class _Handle:
    """Owns one C handle, destroyed exactly once by close(), the with-statement or, failing
    those, the garbage collector."""
    _destroy_name = ""

    def _own(self, handle: ctypes.c_void_p, *parents: object) -> None:
        self._handle = handle
        self._children: "weakref.WeakSet[_Handle]" = weakref.WeakSet()
        # The finalizer holds the handles this one needs (a tracker its context), so that they
        # outlive it; closing a parent closes its children first.
        self._finalizer = weakref.finalize(self, _release, getattr(lib, self._destroy_name), handle, parents)
        for p in parents:
            if isinstance(p, _Handle):
                p._children.add(self)

    def close(self) -> None:
        """Releases the handle now, and first those that depend on it (a context's trackers);
        later calls raise ValueError. Calling it again does nothing."""
        if getattr(self, "_finalizer", None) is not None:
            for child in list(self._children):
                child.close()
            self._finalizer()

    @property
    def closed(self) -> bool:
        return getattr(self, "_finalizer", None) is None or not self._finalizer.alive

    def _h(self) -> ctypes.c_void_p:
        if self.closed:
            raise ValueError("%s is closed" % type(self).__name__)
        return self._handle

    def __enter__(self: _H) -> _H:
        return self

    def __exit__(self, exc_type: Optional[Type[BaseException]], exc_value: Optional[BaseException],
                 traceback: Optional[TracebackType]) -> None:
        self.close()
