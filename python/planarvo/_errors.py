"""Status codes and errors: every failed planarvo call raises Error (_check) with the library's
message."""
from __future__ import annotations

import enum
from typing import Any, Callable, Tuple

from ._native import lib


class IntEnum(enum.IntEnum):
    """The package's enums: integers the C API takes, printed by name (Python 3.11's IntEnum
    prints its bare value), e.g. str(TrackStatus.OK) == "TrackStatus.OK"."""

    def __str__(self) -> str:
        return "%s.%s" % (type(self).__name__, self.name)


class Status(IntEnum):
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

    def __reduce__(self) -> Tuple[Callable[[int, str, Any], Error], Tuple[int, str, Any]]:
        # Pickled with its own arguments, so that it crosses processes (multiprocessing,
        # concurrent.futures) as itself, of the same class.
        return (_error, (int(self.status), self.message, self.result))


# Error's subclasses that are also the built-in exceptions they mean, so that `except ValueError`
# or `except FileNotFoundError` catches them as Python code expects.
class InvalidArgumentError(Error, ValueError):
    """Status.INVALID_ARGUMENT: a value the call cannot take (a NaN, a height in millimetres...)."""


class InvalidInputError(Error, ValueError):
    """Status.INVALID_INPUT: a file or data that is malformed."""


class MissingFileError(Error, FileNotFoundError):
    """Status.INVALID_INPUT for an input file that does not exist."""


class PermissionDeniedError(Error, PermissionError):
    """An input that cannot be read, or an output that cannot be written, for want of permission."""


def _error(status: int, message: str, result: Any = None) -> Error:
    """The Error of the right class for a status and the library's message."""
    if "Permission denied" in message and status in (Status.INVALID_INPUT, Status.IO):
        return PermissionDeniedError(status, message, result)
    if status == Status.INVALID_INPUT and "does not exist" in message:
        return MissingFileError(status, message, result)
    if status == Status.INVALID_INPUT:
        return InvalidInputError(status, message, result)
    if status == Status.INVALID_ARGUMENT:
        return InvalidArgumentError(status, message, result)
    return Error(status, message, result)


def _check(status: int, result: Any = None) -> None:
    if status != 0:
        raise _error(status, lib.planarvo_last_error().decode(errors="replace"), result)
