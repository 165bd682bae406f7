#!/usr/bin/env python3
"""The planarvo Python package end to end: simulates a short drive of a downward-looking camera
into a temporary directory, calibrates the camera's extrinsics from it (roll and pitch from the
images, then x, y, height and yaw against the wheel odometry), prints them with their standard
deviations next to the simulator's truth, and plots the tracked trajectory against the true one
when matplotlib is installed (python3-matplotlib).

    PYTHONPATH=<repo>/python PLANARVO_LIBRARY=<build>/libplanarvo.so \
        python3 calibrate_simulated_drive.py [--seconds S] [--plot FILE.png]

Exit status: 0 done; 1 the calibration or a planarvo call failed.
"""
import argparse
import math
import sys
import tempfile
from typing import TYPE_CHECKING, List, cast

import numpy as np

import planarvo

if TYPE_CHECKING:  # numpy.typing (numpy 1.21+) for the type checker only: the example runs with an older numpy
    from numpy.typing import NDArray


def main(argv: List[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=8.0, help="length of the drive (default 8)")
    parser.add_argument("--plot", default="trajectory.png", help="where to save the plot (default trajectory.png)")
    args = parser.parse_args(argv[1:])
    try:
        with planarvo.Context() as ctx, tempfile.TemporaryDirectory(prefix="planarvo-sim-") as tmp:
            print("device: %s" % ctx.device.device_name)
            options = planarvo.SimOptions(camera=planarvo.Camera.simulator_default(320, 240, 80.0),
                                          seconds=args.seconds, fps=15.0)
            planarvo.simulate(ctx, tmp, options)
            with planarvo.Dataset(tmp) as ds:
                info = ds.info
                print("simulated %d frames (%dx%d, %.1f s) into %s" % (info.frame_count, info.camera.width,
                                                                       info.camera.height, args.seconds, tmp))
                result = planarvo.calibrate_dataset(ctx, ds)
                truth = info.extrinsics_gt
                print("%-6s %12s %12s %12s" % ("", "calibrated", "sigma", "true"))
                for i, name in enumerate(planarvo.EXTRINSICS_NAMES):
                    scale, unit = (1000.0, "mm") if i < 3 else (180.0 / math.pi, "deg")
                    print("%-6s %9.3f %-2s %9.3f %-2s %9.3f %-2s" % (
                        name, getattr(result.extrinsics, name) * scale, unit, result.sigmas[i] * scale, unit,
                        getattr(truth, name) * scale, unit))
                print("tracking: %d frames, %d ok, %d lost, median %.1f ms per frame; calibration %.1f s"
                      % (result.frames, result.frames_ok, result.frames_lost, result.tracking_median_ms,
                         result.seconds_total))
                # Track the drive with the calibrated extrinsics for the plot.
                poses, truth_poses = [], []
                with planarvo.Tracker(ctx, info.camera, result.extrinsics) as tracker:
                    for i in range(info.frame_count):
                        data = ds.frame_data(i)
                        poses.append(tracker.track(ds.frame(i), data.timestamp).pose.as_array())
                        # A simulated drive has ground truth at every frame.
                        truth_poses.append(cast(planarvo.SE2, data.groundtruth).as_array())
        plot(np.array(poses), np.array(truth_poses), args.plot)
        return 0
    except planarvo.Error as e:
        print("calibrate_simulated_drive.py: %s" % e, file=sys.stderr)
        if isinstance(e.result, planarvo.CameraCalibrationResult):
            print("  status %s: %s" % (e.result.status.name, e.result.reason), file=sys.stderr)
        return 1


def plot(poses: "NDArray[np.float64]", truth: "NDArray[np.float64]", path: str) -> None:
    try:
        # Debian's matplotlib (3.6) has neither type stubs nor a py.typed marker: untyped here.
        import matplotlib  # type: ignore[import]
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt  # type: ignore[import]
    except ImportError:
        print("matplotlib is not installed (apt-get install python3-matplotlib): no plot")
        return
    # The true trajectory relative to its first pose, as the tracker's.
    c, s = math.cos(truth[0, 2]), math.sin(truth[0, 2])
    d = truth[:, :2] - truth[0, :2]
    rel = np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)
    # A figure of the drive's own shape (equal axes), so the plot fills it.
    span = np.ptp(np.vstack([rel, poses[:, :2]]), axis=0) + 1e-3
    width = 7.0
    height = min(7.0, max(2.5, width * span[1] / span[0] + 1.0))
    fig, ax = plt.subplots(figsize=(width, height))
    ax.plot(rel[:, 0], rel[:, 1], "k-", label="true")
    ax.plot(poses[:, 0], poses[:, 1], "r--", label="tracked (calibrated extrinsics)")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    fig.savefig(path, dpi=100, bbox_inches="tight")
    print("wrote %s" % path)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
