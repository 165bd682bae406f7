"""SE2: a planar pose or motion, and arrays of them."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from . import _native as N
from ._util import ArrayLike, NDArray


@dataclass
class SE2:
    """A planar pose or motion: x, y (metres), theta (radians)."""
    x: float = 0.0
    y: float = 0.0
    theta: float = 0.0

    def __array__(self, dtype: Optional[np.dtype[Any]] = None,
                  copy: Optional[bool] = None) -> NDArray[Any]:  # copy: numpy 2's protocol (always a new array)
        return np.array([self.x, self.y, self.theta], dtype=dtype or np.float64)

    def as_array(self) -> NDArray[np.float64]:
        """(x, y, theta) as a float64 array of shape (3,)."""
        return np.array([self.x, self.y, self.theta])

    @classmethod
    def _from_c(cls, s: N.SE2) -> "SE2":
        return cls(s.x, s.y, s.theta)

    def _to_c(self) -> N.SE2:
        return N.SE2(self.x, self.y, self.theta)


def _se2_array(poses: ArrayLike, what: str) -> NDArray[np.float64]:
    """(N, 3) float64 C-contiguous from an (N, 3) array or a sequence of SE2."""
    if isinstance(poses, (list, tuple)) and poses and isinstance(poses[0], SE2):
        poses = [p.as_array() for p in poses]
    a = np.asarray(poses, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError("%s: expected an (N, 3) array of (x, y, theta), got shape %s" % (what, a.shape))
    return np.ascontiguousarray(a)
