"""Shared fixtures: one OpenCL context and one short simulated drive (320x240) per test session.

Environment: PLANARVO_LIBRARY (the library under test), PLANARVO_CLI (the `planarvo` program;
default: beside the library), PLANARVO_SHARED_DIR (the shared/ folder with data/posegraphs;
default: /work/shared, else ../shared beside the checkout)."""
import os
import shutil

import numpy as np
import pytest

import planarvo

HERE = os.path.dirname(os.path.abspath(__file__))


def cli_path():
    path = os.environ.get("PLANARVO_CLI")
    if not path and os.environ.get("PLANARVO_LIBRARY"):
        path = os.path.join(os.path.dirname(os.environ["PLANARVO_LIBRARY"]), "planarvo")
    if not path or not os.access(path, os.X_OK):
        path = shutil.which("planarvo")
    return path


def shared_dir():
    for d in (os.environ.get("PLANARVO_SHARED_DIR"), os.path.join(HERE, "..", "..", "..", "shared"), "/work/shared"):
        if d and os.path.isdir(os.path.join(d, "data")):
            return os.path.normpath(d)
    return None


@pytest.fixture(scope="session")
def context():
    with planarvo.Context() as ctx:
        yield ctx


def simulate_drive(context, out, seconds, seed, supersampling):
    """A mixed drive at 15 fps, 320x240, rendered by planarvo.simulate into out; returns out."""
    options = planarvo.SimOptions(camera=planarvo.Camera.simulator_default(320, 240, 80.0), seconds=seconds,
                                  fps=15.0, seed=seed, supersampling=supersampling)
    planarvo.simulate(context, out, options)
    return out


@pytest.fixture(scope="session")
def drive(context, tmp_path_factory):
    """A 2 s mixed drive at 15 fps, 320x240."""
    return simulate_drive(context, tmp_path_factory.mktemp("sim") / "drive", 2.0, seed=7, supersampling=2)


def true_motions(poses):
    """Frame-to-frame motions T_{k-1}^-1 T_k of (N, 3) poses: (N-1, 3)."""
    p = np.asarray(poses)
    d = p[1:, :2] - p[:-1, :2]
    c, s = np.cos(p[:-1, 2]), np.sin(p[:-1, 2])
    dtheta = np.arctan2(np.sin(p[1:, 2] - p[:-1, 2]), np.cos(p[1:, 2] - p[:-1, 2]))
    return np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1], dtheta], axis=1)
