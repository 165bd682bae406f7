"""Status codes and errors: every failed planarvo call raises Error (_check) with the library's
message."""
from __future__ import annotations

import enum
from typing import Any

from ._native import lib


class Status(enum.IntEnum):
    """planarvo_status."""
    OK = 0
    INVALID_ARGUMENT = 1
    INVALID_INPUT = 2
    IO = 3
    NO_DEVICE = 4
    OPENCL = 5
    FAILED = 6
    CANCELLED = 7
    BUFFER_TOO_SMALL = 8
    INTERNAL = 9
    OUT_OF_MEMORY = 10


class Error(Exception):
    """A failed planarvo call. status: the Status; status_name: its C name (planarvo_status_name);
    message: planarvo_last_error()'s text; result: the filled-in result of a call that fills one
    in even when it fails (calibrations, pose graphs), else None."""

    def __init__(self, status: int, message: str, result: Any = None):
        self.status = Status(status) if status in Status._value2member_map_ else status
        self.status_name = lib.planarvo_status_name(int(status)).decode()
        self.message = message
        self.result = result
        super().__init__("%s: %s" % (self.status_name, message))

    def __reduce__(self):
        # Pickled with its own arguments, so that it crosses processes (multiprocessing,
        # concurrent.futures) as itself.
        return (Error, (int(self.status), self.message, self.result))


def _check(status: int, result: Any = None) -> None:
    if status != 0:
        raise Error(status, lib.planarvo_last_error().decode(errors="replace"), result)
