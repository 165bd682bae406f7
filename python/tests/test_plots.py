"""planarvo.plot: the numbers behind the figures against independent computations, the figures
written as PNGs of the expected size that are not blank, and the bad-input exits."""
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import planarvo  # noqa: E402
from planarvo.plot import _io, _motion  # noqa: E402

from conftest import true_motions  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON_DIR = os.path.dirname(HERE)


def run_plot(*args):
    env = dict(os.environ)
    env["PYTHONPATH"] = PYTHON_DIR + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-m", "planarvo.plot", *map(str, args)], env=env,
                          capture_output=True, text=True, timeout=120)


def write_tum(path, t, poses):
    with open(path, "w") as f:
        f.write("# timestamp x y z qx qy qz qw\n")
        for ti, (x, y, th) in zip(t, poses):
            f.write("%.9f %.17g %.17g 0 0 0 %.17g %.17g\n" % (ti, x, y, np.sin(th / 2), np.cos(th / 2)))


def groundtruth(drive):
    a = np.loadtxt(os.path.join(drive, "groundtruth.txt"))
    return a[:, 0], np.column_stack([a[:, 1], a[:, 2], 2 * np.arctan2(a[:, 6], a[:, 7])])


def test_velocities_of_a_circle_are_its_speed_and_turn_rate():
    v, w, dt = 0.4, 0.7, 0.05                # m/s, rad/s, s
    t = np.arange(40) * dt
    th = w * t
    poses = np.column_stack([v / w * np.sin(th), v / w * (1 - np.cos(th)), th])   # starts at 0 heading +x
    vel = _motion.velocities(t, poses)
    # the chord over one interval: (v/w) sin(w dt) forward, (v/w)(1 - cos(w dt)) left
    np.testing.assert_allclose(vel.vx, v / w * np.sin(w * dt) / dt, rtol=1e-9)
    np.testing.assert_allclose(vel.vy, v / w * (1 - np.cos(w * dt)) / dt, rtol=1e-9)
    np.testing.assert_allclose(vel.omega, w, rtol=1e-9)


def test_velocities_from_the_data_set_equal_finite_differences_of_its_ground_truth(drive):
    series = _io.read_dataset(str(drive))
    t, gt = groundtruth(drive)
    vel = _motion.velocities(series.times, series.groundtruth)
    expected = true_motions(gt) / np.diff(t)[:, None]
    np.testing.assert_allclose(np.column_stack([vel.vx, vel.vy, vel.omega]), expected, atol=1e-6)


def test_trajectory_lines_are_matched_to_frames_and_may_skip_some(drive, tmp_path):
    series = _io.read_dataset(str(drive))
    keep = np.arange(0, len(series.times), 3)
    t, gt = groundtruth(drive)
    write_tum(tmp_path / "t.txt", t[keep] + 2e-5, gt[keep])
    frames = _motion.match_frames(_io.read_tum(str(tmp_path / "t.txt")), series)
    np.testing.assert_array_equal(frames, keep)


def test_fitted_slope_equals_polyfit():
    rng = np.random.default_rng(3)
    x = rng.uniform(-1, 1, 500)
    y = 0.93 * x + 0.02 + rng.normal(0, 0.05, 500)
    fit = _motion.fit_line(x, y)
    slope, intercept = np.polyfit(x, y, 1)
    assert fit.slope == pytest.approx(slope, rel=1e-10)
    assert fit.intercept == pytest.approx(intercept, abs=1e-12)


def test_lost_and_degraded_spans_from_a_handwritten_csv(tmp_path):
    status = ["first", "ok", "lost", "lost", "ok", "degraded", "ok", "skipped", "degraded", "degraded"]
    path = tmp_path / "stats.csv"
    with open(path, "w") as f:
        f.write("timestamp,vx,vy,omega,iterations,final_cost,inlier_fraction,ms,status\n")
        for k, s in enumerate(status):
            f.write("%.9f,0,0,0,3,0.5,0.9,7.5,%s\n" % (0.1 * k, s))
    st = _io.read_stats(str(path))
    assert _motion.status_runs(st["status"], "lost") == [(2, 3)]
    assert _motion.status_runs(st["status"], "degraded") == [(5, 5), (8, 9)]
    spans = _motion.status_spans(st["timestamp"], st["status"], "lost")
    np.testing.assert_allclose(spans, [(0.15, 0.35)])


def png_ok(path, width_px, height_px):
    import matplotlib.image as mpimg
    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    img = mpimg.imread(path)
    assert img.shape[1] == width_px and img.shape[0] == height_px
    assert img[..., :3].var() > 1e-3           # not blank


def test_track_figures_are_written(drive, tmp_path):
    t, gt = groundtruth(drive)
    write_tum(tmp_path / "traj.txt", t, gt + np.array([0.001, 0, 0]))
    with open(tmp_path / "stats.csv", "w") as f:
        f.write("timestamp,vx,vy,omega,iterations,final_cost,inlier_fraction,ms,status\n")
        for k, ti in enumerate(t):
            f.write("%.9f,0,0,0,%d,0.5,0.9,7.5,%s\n" % (ti, 3 + k % 4, "lost" if k in (5, 6) else "ok"))
    r = run_plot("track", drive, "--trajectory", tmp_path / "traj.txt", "--stats", tmp_path / "stats.csv",
                 "--out-dir", tmp_path / "out", "--format", "png,svg")
    assert r.returncode == 0, r.stderr
    from planarvo.plot import _style
    for name in ("trajectory", "velocity", "velocity_hist", "tracking"):
        fig_h = {"trajectory": 5.6, "velocity": 5.0, "velocity_hist": 3.4, "tracking": 6.4}[name]
        png_ok(tmp_path / "out" / (name + ".png"), round(_style.WIDTH_IN * _style.DPI), round(fig_h * _style.DPI))
        assert os.path.getsize(tmp_path / "out" / (name + ".svg")) > 1000


def test_local_plane_figures_from_the_attitude_columns(drive, tmp_path):
    """Statistics with the attitude columns (track --local-plane) are read as written, and the
    figures of the paper's Figures 18-19 are drawn from them; without the columns (the test
    above), or with them empty, has_attitude is false."""
    t, gt = groundtruth(drive)
    write_tum(tmp_path / "traj.txt", t, gt)
    omega = 0.3 * np.sin(t)
    roll = -0.07 * omega + 0.001 * np.cos(7 * t)
    with open(tmp_path / "stats.csv", "w") as f:
        f.write("timestamp,vx,vy,omega,iterations,final_cost,inlier_fraction,ms,status,roll,pitch,sigma_roll,"
                "sigma_pitch,mounting_changed\n")
        for k, ti in enumerate(t):
            f.write("%.9f,0,0,%.9f,3,0.5,0.9,7.5,ok,%.9f,%.9f,0.001,0.001,%d\n" % (ti, omega[k], roll[k], 0.01 * k,
                                                                                   int(k == 4)))
    st = _io.read_stats(str(tmp_path / "stats.csv"))
    np.testing.assert_allclose(st["roll"], roll, atol=1e-9)
    assert st["mounting_changed"].sum() == 1
    from planarvo.plot import _plane
    assert _plane.has_attitude(st)
    empty = tmp_path / "empty.csv"
    with open(empty, "w") as f:
        f.write("timestamp,vx,vy,omega,iterations,final_cost,inlier_fraction,ms,status,roll,pitch,sigma_roll,"
                "sigma_pitch,mounting_changed\n0.0,0,0,0,0,0,0,7.5,first,,,,,\n")
    assert not _plane.has_attitude(_io.read_stats(str(empty)))
    r = run_plot("track", drive, "--trajectory", tmp_path / "traj.txt", "--stats", tmp_path / "stats.csv",
                 "--out-dir", tmp_path / "out")
    assert r.returncode == 0, r.stderr
    from planarvo.plot import _style
    png_ok(tmp_path / "out" / "body_roll.png", round(_style.WIDTH_IN * _style.DPI), round(4.2 * _style.DPI))
    png_ok(tmp_path / "out" / "body_pitch.png", round(_style.WIDTH_IN * _style.DPI), round(3.6 * _style.DPI))


def test_without_ground_truth_the_histogram_is_left_out(drive, tmp_path):
    d = tmp_path / "nogt"
    shutil.copytree(drive, d)
    t, gt = groundtruth(drive)
    os.remove(d / "groundtruth.txt")
    write_tum(tmp_path / "traj.txt", t, gt)
    r = run_plot("track", d, "--trajectory", tmp_path / "traj.txt", "--out-dir", tmp_path / "out")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "out" / "trajectory.png").exists()
    assert not (tmp_path / "out" / "velocity_hist.png").exists()


def test_a_time_that_matches_no_frame_and_an_empty_trajectory_exit_2(drive, tmp_path):
    t, gt = groundtruth(drive)
    t_bad = t.copy()
    t_bad[4] += 0.01
    write_tum(tmp_path / "bad.txt", t_bad, gt)
    r = run_plot("track", drive, "--trajectory", tmp_path / "bad.txt", "--out-dir", tmp_path / "o1")
    assert r.returncode == 2
    assert not (tmp_path / "o1" / "trajectory.png").exists()
    (tmp_path / "empty.txt").write_text("# timestamp x y z qx qy qz qw\n")
    r = run_plot("track", drive, "--trajectory", tmp_path / "empty.txt", "--out-dir", tmp_path / "o2")
    assert r.returncode == 2


def se2_matrix(p):
    c, s = np.cos(p[2]), np.sin(p[2])
    return np.array([[c, -s, p[0]], [s, c, p[1]], [0, 0, 1]])


def synthetic_pairs(z, n, rng, noise):
    """Odometry motions and the sensor's, m_s = S_1/h(T^-1 W T) by 3x3 matrices (independent of
    the code under test), odometry perturbed by noise (m, m, rad)."""
    T = se2_matrix([z[0], z[1], z[3]])
    pairs = []
    for _ in range(n):
        w = np.array([rng.uniform(-0.02, 0.03), rng.uniform(-0.002, 0.002), rng.uniform(-0.08, 0.08)])
        m = np.linalg.inv(T) @ se2_matrix(w) @ T
        s = np.array([m[0, 2] / z[2], m[1, 2] / z[2], np.arctan2(m[1, 0], m[0, 0])])
        wn = w + rng.normal(0, 1, 3) * noise
        pairs.append(planarvo.MotionPair(1 / 30, planarvo.SE2(*s), planarvo.SE2(*wn)))
    return pairs


def test_residuals_vanish_on_noise_free_pairs_at_the_true_values():
    z = (0.25, -0.02, 0.18, -0.16)
    pairs = synthetic_pairs(z, 50, np.random.default_rng(1), 0.0)
    result, res = planarvo.calibrate_residuals(pairs)
    np.testing.assert_allclose(result.value, z, atol=1e-9)
    assert res.has_odometry.all() and not res.outlier.any()
    assert np.abs(res.d).max() < 1e-9


def test_residual_chi2_is_the_solvers_at_its_least_squares_optimum():
    from planarvo.plot import _calibration_data as C
    z = (0.25, -0.02, 0.18, -0.16)
    pairs = synthetic_pairs(z, 300, np.random.default_rng(2), np.array([3e-4, 1e-4, 1e-3]))
    options = planarvo.CalibrationOptions(loss=planarvo.RobustLoss.NONE, gate_sigma=0.0)
    result, res = planarvo.calibrate_residuals(pairs, options)
    assert res.odometry_noise is None  # motion pairs given: the options' model, not fitted
    # final_chi2 is the sum of e' Omega e over the factors at the optimum (planarvo.h).
    assert res.chi2.sum() == pytest.approx(result.summary.final_chi2, rel=1e-6)
    # Each pair's chi2 is its d over its covariance.
    chi2 = np.einsum("ni,ni->n", res.d, np.linalg.solve(res.cov, res.d[:, :, None])[:, :, 0])
    np.testing.assert_allclose(res.chi2, chi2, rtol=1e-9)
    # The plots draw the library's values.
    data = C.CalibrationData("test", pairs, options, False)
    C.residuals(data)
    np.testing.assert_array_equal(data.residuals.chi2, res.chi2)
    # With the odometry's noise fitted, the model comes back.
    fitted, res_fit = planarvo.calibrate_residuals(pairs, planarvo.CalibrationOptions(estimate_odometry_noise=True))
    assert res_fit.odometry_noise is not None and res_fit.odometry_noise.shape == (3, 3)
    assert (res_fit.odometry_noise >= 0).all()


def test_mosaic_figure_reads_the_map_yaml_and_draws_each_mosaic(tmp_path):
    from PIL import Image
    from planarvo.plot import _mosaic_figure
    rng = np.random.default_rng(3)
    image = rng.integers(1, 256, size=(120, 200), dtype=np.uint8)
    image[:, :40] = 0  # unseen
    Image.fromarray(image).save(tmp_path / "a.png")
    (tmp_path / "a.yaml").write_text("image: a.png\nresolution: 0.002\norigin: [-0.1, 0.25, 0.0]\n"
                                     "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    shutil.copy(tmp_path / "a.png", tmp_path / "b.png")
    (tmp_path / "b.yaml").write_text("image: b.png\nresolution: 0.002\norigin: [0.0, 0.25, 0.0]\n")
    read, res, ox, oy = _mosaic_figure.read_map(str(tmp_path / "a.png"))
    assert np.array_equal(read, image) and (res, ox, oy) == (0.002, -0.1, 0.25)
    write_tum(tmp_path / "traj.txt", [0.0, 1.0], np.array([[0.0, 0.3, 0.0], [0.2, 0.4, 0.5]]))
    r = run_plot("mosaic", tmp_path / "a.png", tmp_path / "b.png", "--title", "one", "--title", "two",
                 "--trajectory", tmp_path / "traj.txt", "--zoom", "0,0.26,0.2,0.45", "--out-dir", tmp_path / "out")
    assert r.returncode == 0, r.stderr
    from PIL import Image as I
    with I.open(tmp_path / "out" / "mosaic.png") as im:
        assert im.size[0] == 1125 and np.asarray(im.convert("L")).std() > 10
    # What the figure draws (issue 27: the test checked only a width and a pixel spread): one
    # panel per mosaic, each image at the extent its YAML gives (origin + size x resolution), its
    # pixels as read with the unseen ones masked, the zoom box as the limits, the trajectory's
    # poses as the line.
    figures = []
    monkey = _mosaic_figure.S.save
    try:
        _mosaic_figure.S.save = lambda fig, *a, **k: figures.append(fig) or []
        _mosaic_figure.mosaic_figure([str(tmp_path / "a.png"), str(tmp_path / "b.png")], ["one", "two"],
                                     str(tmp_path / "traj.txt"), "0,0.26,0.2,0.45", str(tmp_path / "out"), "m", ["png"])
    finally:
        _mosaic_figure.S.save = monkey
    (fig,) = figures
    panels = [ax for ax in fig.axes if ax.images]
    assert len(panels) == 2
    for ax, ox, title in zip(panels, (-0.1, 0.0), ("one", "two")):
        (im,) = ax.images
        assert im.get_extent() == pytest.approx([ox, ox + 200 * 0.002, 0.25, 0.25 + 120 * 0.002])
        shown = im.get_array()
        assert np.array_equal(np.ma.getdata(shown), image)
        assert np.array_equal(np.ma.getmaskarray(shown), image == 0)
        assert ax.get_xlim() == pytest.approx((0.0, 0.2)) and ax.get_ylim() == pytest.approx((0.26, 0.45))
        assert ax.get_title() == title
        line = ax.lines[0]
        assert np.allclose(line.get_xdata(), [0.0, 0.2]) and np.allclose(line.get_ydata(), [0.3, 0.4])
    # Bad input: a YAML without an origin, a title count that does not match, a bad zoom box.
    (tmp_path / "b.yaml").write_text("image: b.png\nresolution: 0.002\n")
    assert run_plot("mosaic", tmp_path / "b.png", "--out-dir", tmp_path / "out").returncode == 2
    assert run_plot("mosaic", tmp_path / "a.png", "--title", "x", "--title", "y",
                    "--out-dir", tmp_path / "out").returncode == 2
    assert run_plot("mosaic", tmp_path / "a.png", "--zoom", "1,1,0,0", "--out-dir", tmp_path / "out").returncode == 2
