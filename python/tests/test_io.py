"""Files: camera and extrinsics YAML, motion pairs, TUM trajectories; the extrinsics matrix
against docs/conventions.md's definition."""
import math

import numpy as np
import pytest

import planarvo


def test_camera_round_trip(tmp_path):
    cam = planarvo.Camera(640, 480, 501.25, 499.5, 319.75, 241.125, -0.12, 0.03, 0.001, -0.002, 0.0004,
                          roi=(8, 16, 600, 400))
    cam.save(tmp_path / "camera.yaml")
    assert planarvo.Camera.load(tmp_path / "camera.yaml") == cam


def test_simulated_body_writes_its_true_plane_and_knocked_mount(context, tmp_path):
    ext = planarvo.Extrinsics(-1.0, 0.0, 0.9, 0.0, math.radians(40.0), math.pi)
    options = planarvo.SimOptions(camera=planarvo.Camera.simulator_default(96, 64, 60.0), seconds=4.0, fps=10.0,
                                  extrinsics=ext, motion=planarvo.MotionProfile.CAR, max_speed=3.0,
                                  min_turn_radius=6.0, lean=-0.07, bumps=math.radians(5.0), knock_time=2.0,
                                  knock_roll=0.0, knock_pitch=math.radians(2.0), knock_z=0.01, supersampling=1)
    planarvo.simulate(context, tmp_path / "car", options)
    plane = np.loadtxt(tmp_path / "car" / "plane.txt")
    assert plane.shape == (40, 5)
    assert np.all(np.abs(plane[:, 1]) < math.radians(3.0)) and np.all(np.abs(plane[:, 2]) <= math.radians(5.0))
    assert np.all(plane[:, 3:] == 0.0)
    knocked = planarvo.Extrinsics.load(tmp_path / "car" / "extrinsics_knocked.yaml")
    assert knocked.z == pytest.approx(0.91, abs=1e-12)
    assert knocked.pitch == pytest.approx(math.radians(42.0), abs=1e-12)


def test_rolling_shutter_readout_round_trip_and_simulated(context, tmp_path):
    cam = planarvo.Camera(640, 480, 501.25, 499.5, 319.75, 241.125, rolling_shutter_readout=0.0271,
                          exposure_time=0.0043)
    cam.save(tmp_path / "camera.yaml")
    assert planarvo.Camera.load(tmp_path / "camera.yaml") == cam
    assert planarvo.Camera.simulator_default(96, 64, 80.0).rolling_shutter_readout == 0.0
    options = planarvo.SimOptions(camera=planarvo.Camera.simulator_default(96, 64, 80.0), seconds=0.2,
                                  readout_time=0.02, exposure_time=0.004)
    planarvo.simulate(context, tmp_path / "rs", options)
    assert planarvo.Camera.load(tmp_path / "rs" / "camera.yaml").rolling_shutter_readout == 0.02
    assert planarvo.Camera.load(tmp_path / "rs" / "camera.yaml").exposure_time == 0.004
    with pytest.raises(planarvo.Error):
        planarvo.simulate(context, tmp_path / "bad", planarvo.SimOptions(seconds=0.2, readout_time=-1.0))
    # A data set's readout replaced for one run; refused when negative or longer than a frame.
    ds = planarvo.Dataset(tmp_path / "rs")
    ds.set_readout(0.01)
    assert ds.info.camera.rolling_shutter_readout == 0.01
    for bad in (-0.001, float("nan"), 0.5):
        with pytest.raises(planarvo.Error):
            ds.set_readout(bad)
    assert ds.info.camera.rolling_shutter_readout == 0.01


def test_extrinsics_round_trip_and_matrix(tmp_path):
    e = planarvo.Extrinsics(0.2441, -0.0185, 0.1787, math.radians(12.4), math.radians(17.6), math.radians(-9.2))
    cov = np.diag([1e-6, 2e-6, 3e-6, 1e-4, 2e-4, 3e-4])
    e.save(tmp_path / "e.yaml", covariance=cov, estimated=["x", "y", "z", "roll", "pitch", "yaw"], method="test",
           notes="round trip")
    loaded = planarvo.Extrinsics.load(tmp_path / "e.yaml")
    np.testing.assert_allclose(loaded.as_array(), e.as_array(), rtol=0, atol=1e-15)
    f = planarvo.ExtrinsicsFile.load(tmp_path / "e.yaml")
    assert f.extrinsics == e  # every value exactly
    np.testing.assert_array_equal(f.covariance, cov)
    np.testing.assert_array_equal(f.sigmas, np.sqrt(np.diag(cov)))
    assert f.estimated == planarvo.EXTRINSICS_NAMES
    assert (f.method, f.notes) == ("test", "round trip")
    e.save(tmp_path / "bare.yaml")
    bare = planarvo.ExtrinsicsFile.load(tmp_path / "bare.yaml")
    assert bare.estimated == () and bare.method == "" and not bare.covariance.any()

    def rx(a):
        return np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])

    def ry(a):
        return np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])

    def rz(a):
        return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])

    r0 = np.array([[0, -1, 0], [-1, 0, 0], [0, 0, -1]])  # looking down, image top forward
    expected = np.eye(4)
    expected[:3, :3] = rz(e.yaw) @ ry(e.pitch) @ rx(e.roll) @ r0
    expected[:3, 3] = [e.x, e.y, e.z]
    np.testing.assert_allclose(e.matrix(), expected, rtol=0, atol=1e-12)


def test_motion_pairs_round_trip(tmp_path):
    pairs = [planarvo.MotionPair(0.1 * (i + 1), planarvo.SE2(0.01 * i, -0.002 * i, 0.003 * i),
                                 odometry=planarvo.SE2(0.02 * i, 0.0, 0.001 * i), direction=(1, -1, 0)[i % 3])
             for i in range(5)]
    planarvo.save_motion_pairs(tmp_path / "pairs.csv", pairs)
    loaded = planarvo.load_motion_pairs(tmp_path / "pairs.csv")
    assert len(loaded) == len(pairs)
    for a, b in zip(loaded, pairs):
        assert a.interval == pytest.approx(b.interval, abs=1e-15)
        np.testing.assert_allclose(a.sensor.as_array(), b.sensor.as_array(), rtol=0, atol=1e-15)
        np.testing.assert_allclose(a.odometry.as_array(), b.odometry.as_array(), rtol=0, atol=1e-15)
        assert a.direction == b.direction and a.sensor_covariance is None


def test_write_tum(tmp_path):
    t = np.array([0.0, 0.1, 0.2])
    poses = np.array([[0, 0, 0], [0.1, 0.02, 0.3], [0.25, -0.5, -1.0]])
    planarvo.write_tum(tmp_path / "t.txt", t, poses)
    rows = np.loadtxt(tmp_path / "t.txt", comments="#")
    np.testing.assert_allclose(rows[:, 0], t)
    np.testing.assert_allclose(rows[:, 1:3], poses[:, :2], atol=1e-15)
    np.testing.assert_allclose(2 * np.arctan2(rows[:, 6], rows[:, 7]), poses[:, 2], atol=1e-12)


def test_devices_and_context(context):
    devices = planarvo.list_devices()
    assert devices, "no OpenCL device"
    assert context.device.device_name in [d.device_name for d in devices]
    assert isinstance(context.cache_dir, str)
    assert planarvo.version() == planarvo.__version__


def test_stats_writer(tmp_path):
    path = tmp_path / "stats.csv"
    with planarvo.StatsWriter(path) as w:
        w.add(0.0, 0.0, 0.0, 0.0, 0, 0.0, 1.0, 3.5, "first")
        w.add(0.1, 0.5, -0.01, 0.2, 7, 0.25, 0.9, 4.25, "ok")
        assert not path.exists()  # written as stats.csv.partial until closed
        w.add(0.2, 0.5, -0.01, 0.2, 7, 0.25, 0.9, 4.25, "ok", attitude=(0.015625, -0.25, 0.001, 0.002),
              mounting_changed=True)
    lines = path.read_text().splitlines()
    assert lines[0].startswith("timestamp") and len(lines) == 4
    assert lines[0].split(",")[9:] == ["roll", "pitch", "sigma_roll", "sigma_pitch", "mounting_changed"]
    assert lines[2].split(",")[8] == "ok" and float(lines[2].split(",")[1]) == 0.5
    assert lines[2].split(",")[9:] == [""] * 5  # no attitude: empty
    assert [float(v) for v in lines[3].split(",")[9:]] == [0.015625, -0.25, 0.001, 0.002, 1.0]
    # An exception inside the block discards: the complete file stays as it was.
    with pytest.raises(RuntimeError):
        with planarvo.StatsWriter(path) as w:
            w.add(0.0, 0.0, 0.0, 0.0, 0, 0.0, 1.0, 3.5, "first")
            raise RuntimeError("stop")
    assert path.read_text().splitlines() == lines
    assert not (tmp_path / "stats.csv.partial").exists()
    # Read back by the library: each column as written; no attitude is NaN.
    st = planarvo.read_stats(path)
    assert set(st) == set(planarvo.STATS_COLUMNS)
    np.testing.assert_array_equal(st["timestamp"], [0.0, 0.1, 0.2])
    np.testing.assert_array_equal(st["vx"], [0.0, 0.5, 0.5])
    np.testing.assert_array_equal(st["iterations"], [0, 7, 7])
    assert list(st["status"]) == ["first", "ok", "ok"]
    assert np.isnan(st["roll"][:2]).all() and st["roll"][2] == 0.015625 and st["sigma_pitch"][2] == 0.002
    assert list(st["mounting_changed"]) == [False, False, True]
    path.write_text("timestamp,vx\n0,1\n")
    with pytest.raises(planarvo.Error) as err:
        planarvo.read_stats(path)
    assert err.value.status == planarvo.Status.INVALID_INPUT and str(path) + ":1:" in err.value.message


def test_plane_reads_back(tmp_path):
    path = tmp_path / "plane.txt"
    path.write_text("# t roll pitch sigma_roll sigma_pitch\n0.0 0.01 -0.02 0.001 0.002\n0.1 0.015 -0.025 0 0\n")
    np.testing.assert_array_equal(planarvo.read_plane(path),
                                  [[0.0, 0.01, -0.02, 0.001, 0.002], [0.1, 0.015, -0.025, 0, 0]])
    path.write_text("0.0 12.4 0 0 0\n")  # degrees by mistake
    with pytest.raises(planarvo.Error):
        planarvo.read_plane(path)


def test_dataset_is_a_sequence_of_timestamped_frames(drive):
    with planarvo.Dataset(drive) as ds:
        n = len(ds)
        assert n == ds.info.frame_count > 3
        t0, f0 = ds[0]
        assert t0 == ds.frame_data(0).timestamp and np.array_equal(f0, ds.frame(0))
        t_last, f_last = ds[-1]
        assert t_last == ds.frame_data(n - 1).timestamp and np.array_equal(f_last, ds.frame(n - 1))
        part = ds[1:4]
        assert [t for t, _ in part] == [ds.frame_data(i).timestamp for i in (1, 2, 3)]
        assert [t for t, _ in ds[::-2]][:2] == [ds.frame_data(n - 1).timestamp, ds.frame_data(n - 3).timestamp]
        assert [t for t, _ in ds] == [t for t, _ in ds.frames()]
        for bad in (n, -n - 1):
            with pytest.raises(IndexError):
                ds[bad]
        text = repr(ds)
        assert str(drive) in text and "%d frames" % n in text
    assert "closed" in repr(ds)
