"""Reading a run's files: a TUM trajectory, the per-frame statistics CSV, extrinsics YAML with
its covariance, and a data set's per-frame times, odometry and ground truth (docs/formats.md)."""
from __future__ import annotations

import csv
import math
import os
import re
from dataclasses import dataclass
from typing import Dict, List, Optional

import numpy as np

from ._errors import InputError

STATS_COLUMNS = ("timestamp", "vx", "vy", "omega", "iterations", "final_cost", "inlier_fraction", "ms", "status")
# Written since the local plane: the body's attitude (empty fields without it).
ATTITUDE_COLUMNS = ("roll", "pitch", "sigma_roll", "sigma_pitch", "mounting_changed")
EXTRINSICS_NAMES = ("x", "y", "z", "roll", "pitch", "yaw")


@dataclass
class Trajectory:
    """A TUM file's planar poses: stamps (N,), poses (N, 3) x y theta, lines (N,) 1-based line numbers."""
    path: str
    stamps: np.ndarray
    poses: np.ndarray
    lines: np.ndarray


def read_tum(path: str) -> Trajectory:
    """A TUM trajectory (timestamp x y z qx qy qz qw per line, '#' comments); the heading is the
    yaw of the quaternion (planar poses: qx = qy = 0). Raises InputError when it cannot be read or is empty."""
    try:
        with open(path) as f:
            text = f.read().splitlines()
    except OSError as e:
        raise InputError("cannot read the trajectory %s: %s" % (path, e.strerror)) from None
    rows, lines = [], []
    for n, line in enumerate(text, 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        fields = s.split()
        try:
            values = [float(v) for v in fields]
        except ValueError:
            raise InputError("%s line %d: not numbers: %r" % (path, n, s[:80])) from None
        if len(values) != 8:
            raise InputError("%s line %d: expected 8 values (timestamp x y z qx qy qz qw), found %d"
                             % (path, n, len(values)))
        rows.append(values)
        lines.append(n)
    if not rows:
        raise InputError("the trajectory %s is empty: no poses to plot" % path)
    a = np.array(rows)
    if not np.all(np.isfinite(a)):
        bad = int(np.nonzero(~np.all(np.isfinite(a), axis=1))[0][0])
        raise InputError("%s line %d: a value is not finite" % (path, lines[bad]))
    theta = 2.0 * np.arctan2(a[:, 6], a[:, 7])
    theta = np.arctan2(np.sin(theta), np.cos(theta))
    return Trajectory(path, a[:, 0], np.column_stack([a[:, 1], a[:, 2], theta]), np.array(lines))


@dataclass
class Stats:
    """The per-frame statistics CSV of `track --stats`, one array per column (status: str array)."""
    path: str
    columns: Dict[str, np.ndarray]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]


def read_stats(path: str) -> Stats:
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as e:
        raise InputError("cannot read the statistics %s: %s" % (path, e.strerror)) from None
    header = tuple(c.strip() for c in rows[0]) if rows else ()
    if header not in (STATS_COLUMNS, STATS_COLUMNS + ATTITUDE_COLUMNS):
        raise InputError("%s: the first line is not the statistics header %s" % (path, ",".join(STATS_COLUMNS + ATTITUDE_COLUMNS)))
    body = [r for r in rows[1:] if r]
    if not body:
        raise InputError("%s: no rows" % path)
    for n, r in enumerate(body, 2):
        if len(r) != len(header):
            raise InputError("%s line %d: expected %d fields, found %d" % (path, n, len(header), len(r)))
    cols: Dict[str, np.ndarray] = {}
    for k, name in enumerate(header):
        if name == "status":
            cols[name] = np.array([r[k].strip() for r in body])
            continue
        try:
            # An empty attitude field: not measured (NaN).
            cols[name] = np.array([float(r[k]) if r[k].strip() or name in STATS_COLUMNS else np.nan for r in body])
        except ValueError:
            raise InputError("%s: column %s holds something that is not a number" % (path, name)) from None
    return Stats(path, cols)


@dataclass
class ExtrinsicsFile:
    """Extrinsics YAML: values (6,) x y z roll pitch yaw, covariance (6, 6) (zeros when absent),
    the names of the estimated parameters, method and notes ('' when absent)."""
    path: str
    values: np.ndarray
    covariance: np.ndarray
    estimated: List[str]
    method: str
    notes: str

    @property
    def sigmas(self) -> np.ndarray:
        return np.sqrt(np.maximum(np.diag(self.covariance), 0.0))


def _yaml_matrix(text: str, key: str) -> Optional[np.ndarray]:
    m = re.search(r"^%s:\s*!!opencv-matrix(.*?)data:\s*\[(.*?)\]" % key, text, re.S | re.M)
    if not m:
        return None
    head, data = m.group(1), m.group(2)
    rows = int(re.search(r"rows:\s*(\d+)", head).group(1))
    cols = int(re.search(r"cols:\s*(\d+)", head).group(1))
    return np.array([float(v) for v in data.replace("\n", " ").split(",") if v.strip()]).reshape(rows, cols)


def _yaml_scalar(text: str, key: str) -> Optional[str]:
    m = re.search(r"^%s:[ \t]*(.*)$" % key, text, re.M)
    if not m:
        return None
    v = m.group(1).strip()
    return v[1:-1] if len(v) >= 2 and v[0] == v[-1] == '"' else v


def read_extrinsics(path: str) -> ExtrinsicsFile:
    """Extrinsics YAML as planarvo writes it (docs/formats.md), with the covariance and the list of
    estimated parameters that the library's loader leaves out."""
    try:
        with open(path) as f:
            text = f.read()
    except OSError as e:
        raise InputError("cannot read the extrinsics %s: %s" % (path, e.strerror)) from None
    values = []
    for name in EXTRINSICS_NAMES:
        v = _yaml_scalar(text, name)
        try:
            values.append(float(v))
        except (TypeError, ValueError):
            raise InputError("%s: no number for %s" % (path, name)) from None
    cov = _yaml_matrix(text, "covariance")
    if cov is None:
        cov = np.zeros((6, 6))
    elif cov.shape != (6, 6):
        raise InputError("%s: the covariance is %dx%d, not 6x6" % (path, *cov.shape))
    estimated: List[str] = []
    m = re.search(r"^estimated:[ \t]*(\[[^\]]*\])?((?:\n[ \t]+-[ \t]*\S+)*)", text, re.M)
    if m:
        inline = (m.group(1) or "").strip("[] ")
        estimated = [s.strip() for s in inline.split(",") if s.strip()]
        estimated += re.findall(r"-[ \t]*(\S+)", m.group(2) or "")
    return ExtrinsicsFile(path, np.array(values), cov, estimated, _yaml_scalar(text, "method") or "",
                          _yaml_scalar(text, "notes") or "")


@dataclass
class Series:
    """A data set's frames: times (N,) in the data set's clock, odometry and groundtruth (N, 3)
    (rows of NaN where a frame has none; None when the data set has none at all)."""
    path: str
    times: np.ndarray
    odometry: Optional[np.ndarray]
    groundtruth: Optional[np.ndarray]
    time_origin_s: float
    is_bag: bool


def read_dataset(path: str) -> Series:
    """Opens the data set (a folder, a bag or MCAP file) with planarvo.Dataset and reads every
    frame's time and poses (not the images)."""
    import planarvo
    if not os.path.exists(path):
        raise InputError("the data set %s does not exist" % path)
    try:
        ds = planarvo.Dataset(path)
    except planarvo.Error as e:
        raise InputError("cannot open the data set %s: %s" % (path, e.message)) from None
    with ds:
        info = ds.info
        n = info.frame_count
        times = np.empty(n)
        odo = np.full((n, 3), np.nan)
        gt = np.full((n, 3), np.nan)
        for i in range(n):
            d = ds.frame_data(i)
            times[i] = d.timestamp
            if d.odometry is not None:
                odo[i] = (d.odometry.x, d.odometry.y, d.odometry.theta)
            if d.groundtruth is not None:
                gt[i] = (d.groundtruth.x, d.groundtruth.y, d.groundtruth.theta)
    has_odo = info.has_odometry and bool(np.isfinite(odo[:, 0]).any())
    has_gt = info.has_groundtruth and bool(np.isfinite(gt[:, 0]).any())
    return Series(path, times, odo if has_odo else None, gt if has_gt else None,
                  info.time_origin_ns * 1e-9, info.is_bag)


def read_plane(path: str) -> Optional[np.ndarray]:
    """A data set folder's plane.txt (the simulator's true body attitude: t roll pitch sigma_roll
    sigma_pitch per line, # comments) as (n, 3) time, roll, pitch; None when there is none."""
    f = os.path.join(path, "plane.txt")
    if not os.path.isfile(f):
        return None
    try:
        a = np.loadtxt(f, comments="#", ndmin=2)
    except ValueError as e:
        raise InputError("%s: %s" % (f, e)) from None
    if a.shape[1] < 3 or not len(a):
        raise InputError("%s: expected lines of t roll pitch sigma_roll sigma_pitch" % f)
    return a[:, :3]


def degrees(rad) -> np.ndarray:
    return np.asarray(rad) * (180.0 / math.pi)
