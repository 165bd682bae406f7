"""Tracker.residuals and `plot outliers`: an occluding rectangle pasted into one frame of a simulated
drive is what the robust norm down-weights. The ground truth is independent of the engine: where
the simulator's true poses and extrinsics (ground-plane geometry and the camera's distortion,
computed here) put each keyframe pixel in the live frame, and whether that lands on the rectangle."""
import os
import re
import shutil

import numpy as np
import pytest

pytest.importorskip("matplotlib")  # planarvo.plot, and PIL with it (python3-matplotlib)

from PIL import Image  # noqa: E402

import planarvo  # noqa: E402
from planarvo.plot import _cli  # noqa: E402
from planarvo.plot._outliers import track_frame  # noqa: E402

FRAME = 12
RECT = (140, 150, 30, 25)  # x, y, width, height in the live frame's (distorted) pixels, where the keyframe saw the ground


def _matrix(text, key):
    m = re.search(r"^%s:\s*!!opencv-matrix(.*?)data:\s*\[(.*?)\]" % key, text, re.S | re.M)
    rows = int(re.search(r"rows:\s*(\d+)", m.group(1)).group(1))
    return np.array([float(v) for v in m.group(2).replace("\n", " ").split(",") if v.strip()]).reshape(rows, -1)


def _se2(p):
    c, s = np.cos(p.theta), np.sin(p.theta)
    return np.array([[c, -s, p.x], [s, c, p.y], [0, 0, 1.0]])


def live_pixels(directory, keyframe, live, shape):
    """Where the ground seen at each undistorted keyframe pixel appears in the live frame's
    distorted image, from the true poses and extrinsics: (u, v) arrays of `shape`, NaN where the
    ray misses the ground."""
    with open(os.path.join(directory, "extrinsics_gt.yaml")) as f:
        T = _matrix(f.read(), "T_robot_camera")
    with open(os.path.join(directory, "camera.yaml")) as f:
        text = f.read()
    K = _matrix(text, "camera_matrix")
    k1, k2, p1, p2, k3 = _matrix(text, "distortion_coefficients").ravel()
    R, t = T[:3, :3], T[:3, 3]
    with planarvo.Dataset(directory) as ds:
        m = np.linalg.inv(_se2(ds.frame_data(keyframe).groundtruth)) @ _se2(ds.frame_data(live).groundtruth)
    v, u = np.mgrid[0:shape[0], 0:shape[1]].astype(float)
    rays = np.linalg.solve(K, np.stack([u.ravel(), v.ravel(), np.ones(u.size)]))
    d = R @ rays
    s = np.where(d[2] < 0, -t[2] / np.where(d[2] < 0, d[2], -1), np.nan)
    ground = t[:, None] + s * d                       # keyframe robot frame, z = 0
    gl = np.linalg.solve(m, np.vstack([ground[:2], np.ones(u.size)]))  # live robot frame
    Xc = R.T @ (np.vstack([gl[:2], np.zeros(u.size)]) - t[:, None])
    x, y = Xc[0] / Xc[2], Xc[1] / Xc[2]
    r2 = x * x + y * y
    radial = 1 + k1 * r2 + k2 * r2 ** 2 + k3 * r2 ** 3
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    return (K[0, 0] * xd + K[0, 2]).reshape(shape), (K[1, 1] * yd + K[1, 2]).reshape(shape)


@pytest.fixture(scope="module")
def occluded(drive, tmp_path_factory):
    """The session's drive with a bright rectangle pasted into frame FRAME's image."""
    out = tmp_path_factory.mktemp("occluded") / "drive"
    shutil.copytree(drive, out)
    with open(out / "frames.txt") as f:
        rows = [line.split() for line in f if line.strip() and not line.startswith("#")]
    path = out / rows[FRAME][1]
    img = np.array(Image.open(path))
    x, y, w, h = RECT
    img[y:y + h, x:x + w] = np.clip(img[y:y + h, x:x + w].astype(int) + 60, 0, 255)
    Image.fromarray(img).save(path)
    return out


def test_the_pasted_rectangle_is_what_the_robust_norm_down_weights(occluded):
    fr = track_frame(str(occluded), str(occluded / "extrinsics_gt.yaml"), FRAME, 0)
    res = fr.residuals
    # The tracker's match check (the mean square residual against the keyframe's variance, not a
    # robust measure) calls this frame lost, "images do not match", although its alignment holds
    # (the "clear" check below): the residuals are at that alignment.
    assert fr.status != "lost" or fr.reason == "images do not match"
    u, v = live_pixels(str(occluded), fr.keyframe_frame, FRAME, res.weight.shape)
    x, y, w, h = RECT
    margin_in, margin_out = 2.5, 5.0  # the prefilter's and bilinear sampling's reach, plus the lens
    inside = (u > x + margin_in) & (u < x + w - 1 - margin_in) & (v > y + margin_in) & (v < y + h - 1 - margin_in)
    near = (u > x - margin_out) & (u < x + w - 1 + margin_out) & (v > y - margin_out) & (v < y + h - 1 + margin_out)
    valid = res.weight > 0
    down = valid & (res.weight < 1)
    blob, clear = inside & valid, ~near & valid
    assert blob.sum() > 400 and clear.sum() > 40000
    # Nearly all of the rectangle is down-weighted, and far beyond the threshold (weight k / |r|).
    assert down[blob].mean() > 0.95
    assert np.median(res.weight[blob]) < 0.3
    # Elsewhere: the Gaussian tail of k = 2 sigma (about 5 %), residuals of pixel noise.
    assert down[clear].mean() < 0.12
    assert np.median(np.abs(res.residual[clear])) < 2.0
    # The weight is the Huber weight of the residual; invalid pixels are 0 in both.
    k = res.threshold
    assert k > 0
    expect = np.minimum(1.0, k / np.maximum(np.abs(res.residual[valid]), 1e-12))
    assert np.allclose(res.weight[valid], expect, rtol=1e-5, atol=1e-6)
    assert np.all(res.residual[~valid] == 0)
    # The keyframe image where it is valid, grey levels.
    seen = np.isfinite(res.intensity)
    assert seen.mean() > 0.8 and np.all((res.intensity[seen] >= 0) & (res.intensity[seen] <= 255))
    assert not np.any(valid & ~seen)


def test_levels_and_errors(context, drive):
    with planarvo.Dataset(str(drive)) as ds:
        info = ds.info
        with planarvo.Tracker(context, info.camera, info.extrinsics_gt) as tracker:
            with pytest.raises(planarvo.Error) as e:
                tracker.residuals()
            assert e.value.status == planarvo.Status.INVALID_ARGUMENT
            tracker.track(ds.frame(0), ds.frame_data(0).timestamp)
            with pytest.raises(planarvo.Error) as e:
                tracker.residuals()  # the first frame has nothing to be compared with
            assert e.value.status == planarvo.Status.INVALID_ARGUMENT
            tracker.track(ds.frame(1), ds.frame_data(1).timestamp)
            full, half = tracker.residuals(0), tracker.residuals(1)
            assert full.residual.shape == (info.camera.height, info.camera.width)
            assert half.weight.shape == ((info.camera.height + 1) // 2, (info.camera.width + 1) // 2)
            assert full.threshold == half.threshold  # the finest level's threshold at every level
            with pytest.raises(planarvo.Error) as e:
                tracker.residuals(4)
            assert e.value.status == planarvo.Status.INVALID_ARGUMENT
            black = np.zeros((info.camera.height, info.camera.width), np.uint8)
            assert tracker.track(black, ds.frame_data(2).timestamp).status == planarvo.TrackStatus.LOST
            with pytest.raises(planarvo.Error) as e:
                tracker.residuals()
            assert e.value.status == planarvo.Status.FAILED


def test_plot_outliers_writes_the_figure(occluded, tmp_path):
    rc = _cli.main(["outliers", str(occluded), "--extrinsics", str(occluded / "extrinsics_gt.yaml"),
                    "--frame", str(FRAME), "--out-dir", str(tmp_path), "--format", "png,svg"])
    assert rc == 0
    with Image.open(tmp_path / ("outliers_%d.png" % FRAME)) as im:
        assert im.size[0] == 1125 and 400 < im.size[1] < 700
    assert (tmp_path / ("outliers_%d.svg" % FRAME)).stat().st_size > 0
    assert _cli.main(["outliers", str(occluded), "--extrinsics", str(occluded / "extrinsics_gt.yaml"),
                      "--frame", "100000", "--out-dir", str(tmp_path)]) == 2
