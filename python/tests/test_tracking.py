"""The tracker from Python against the CLI, the simulator's ground truth, and itself on the same
image passed as grey, BGR and a strided view."""
import math
import subprocess

import numpy as np
import pytest

import planarvo
from conftest import cli_path, true_motions


@pytest.fixture(scope="module")
def tracked(context, drive):
    """Every frame of the drive tracked from Python with the true extrinsics."""
    with planarvo.Dataset(drive) as ds:
        info = ds.info
        frames = list(ds.frames())
        truth = np.array([ds.frame_data(i).groundtruth.as_array() for i in range(len(frames))])
    with planarvo.Tracker(context, info.camera, info.extrinsics_gt) as tracker:
        results = [tracker.track(f, t) for t, f in frames]
    return info, frames, truth, results


def test_statuses_and_types(tracked):
    info, frames, _, results = tracked
    assert info.frame_count == len(frames) == 30
    assert frames[0][1].shape == (240, 320) and frames[0][1].dtype == np.uint8
    assert results[0].status == planarvo.TrackStatus.FIRST
    assert all(r.status == planarvo.TrackStatus.OK for r in results[1:]), [(r.status, r.reason) for r in results]
    r = results[-1]
    assert r.covariance.shape == (3, 3) and np.allclose(r.covariance, r.covariance.T)
    assert np.all(np.linalg.eigvalsh(r.covariance) > 0)
    assert r.ms > 0 and r.levels_used >= 1


def test_matches_cli(tracked, drive, tmp_path):
    """The same motions as `planarvo track --motions-out` on the same data set, to 1e-9."""
    cli = cli_path()
    if not cli:
        pytest.skip("the planarvo CLI was not found (set PLANARVO_CLI)")
    info, _, _, results = tracked
    out = tmp_path / "motions.csv"
    subprocess.run([cli, "track", str(drive), "--extrinsics", str(drive / "extrinsics_gt.yaml"),
                    "--motions-out", str(out), "--quiet"], check=True, capture_output=True)
    cli_motions = np.loadtxt(out, delimiter=",", comments="#")[:, 4:7]  # sensor_dx, sensor_dy, sensor_dtheta
    # The CLI writes the camera's own motion (docs/conventions.md): T^-1 M T with T = (x, y, yaw)
    # of the extrinsics, in units of the height.
    e = info.extrinsics_gt

    def hom(x, y, t):
        return np.array([[np.cos(t), -np.sin(t), x], [np.sin(t), np.cos(t), y], [0.0, 0.0, 1.0]])

    T = hom(e.x, e.y, e.yaw)
    ours = []
    for r in results[1:]:
        m = np.linalg.inv(T) @ hom(*r.motion.as_array()) @ T
        ours.append((m[0, 2] / e.z, m[1, 2] / e.z, np.arctan2(m[1, 0], m[0, 0])))
    ours = np.array(ours)
    assert cli_motions.shape == ours.shape
    np.testing.assert_allclose(ours, cli_motions, rtol=0, atol=1e-9)
    # ... and the same through planarvo.track_motions and load_motion_pairs.
    loaded = planarvo.load_motion_pairs(out)
    assert len(loaded) == len(ours) and loaded[0].odometry is not None and loaded[0].direction is not None
    np.testing.assert_allclose([p.sensor.as_array() for p in loaded], cli_motions, rtol=0, atol=1e-15)


def _camera_motions(e, robot_motions):
    """The camera's own motion (docs/conventions.md): T^-1 M T with T = (x, y, yaw) of the
    extrinsics, in units of the height; computed here, independently of the library."""
    def hom(x, y, t):
        return np.array([[np.cos(t), -np.sin(t), x], [np.sin(t), np.cos(t), y], [0.0, 0.0, 1.0]])
    T = hom(e.x, e.y, e.yaw)
    out = []
    for m in robot_motions:
        c = np.linalg.inv(T) @ hom(*m) @ T
        out.append((c[0, 2] / e.z, c[1, 2] / e.z, np.arctan2(c[1, 0], c[0, 0])))
    return np.array(out)


def test_track_motions_matches_tracker(context, drive, tracked):
    """track_motions' pairs hold the camera's own motion, whatever extrinsics tracked it (issue 25:
    pairs that calibrate correctly); at x = y = 0, z = 1, yaw = 0 that is the tracker's motion."""
    _, _, _, results = tracked
    with planarvo.Dataset(drive) as ds:
        e = ds.info.extrinsics_gt
        pairs = planarvo.track_motions(context, ds, e)
        neutral = planarvo.Extrinsics(z=1.0, roll=e.roll, pitch=e.pitch)
        neutral_pairs = planarvo.track_motions(context, ds, neutral)
        camera = ds.info.camera
    assert len(pairs) == len(results) - 1
    np.testing.assert_allclose([p.sensor.as_array() for p in pairs],
                               _camera_motions(e, [r.motion.as_array() for r in results[1:]]), rtol=0, atol=1e-12)
    # planarvo.sensor_motion is that conversion, the covariance carried through with it.
    m, cov = planarvo.sensor_motion(e, results[-1].motion, results[-1].covariance)
    np.testing.assert_allclose(m.as_array(), pairs[-1].sensor.as_array(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(cov, pairs[-1].sensor_covariance, rtol=1e-12, atol=0)
    assert planarvo.sensor_motion(e, results[-1].motion)[1] is None
    with planarvo.Tracker(context, camera, neutral) as tracker, planarvo.Dataset(drive) as ds:
        mine = [tracker.track(ds.frame(i), ds.frame_data(i).timestamp) for i in range(len(ds))]
    np.testing.assert_allclose([p.sensor.as_array() for p in neutral_pairs], [r.motion.as_array() for r in mine[1:]],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(neutral_pairs[-1].sensor_covariance, mine[-1].covariance, rtol=1e-12, atol=0)


def test_against_ground_truth(tracked):
    """Per-frame motions within 1 mm and 0.1 deg of the simulator's truth; evaluate_motions agrees
    with the same figures computed here."""
    _, frames, truth, results = tracked
    est = np.array([r.motion.as_array() for r in results[1:]])
    gt = true_motions(truth)
    err = np.hypot(*(est[:, :2] - gt[:, :2]).T)
    assert err.max() < 1e-3, err.max()
    assert np.abs(est[:, 2] - gt[:, 2]).max() < math.radians(0.1)
    assert np.abs(np.array([r.pose.as_array() for r in results])[-1, :2] - (truth[-1, :2] - truth[0, :2])).max() < 5e-3
    dt = np.diff([t for t, _ in frames])
    acc = planarvo.evaluate_motions(est, gt, dt)
    assert acc.intervals == len(est)
    assert acc.rms_translation == pytest.approx(math.sqrt(np.mean(err ** 2)), rel=1e-9)
    assert acc.max_translation == pytest.approx(err.max(), rel=1e-9)
    assert acc.distance == pytest.approx(np.hypot(*gt[:, :2].T).sum(), rel=1e-6)


def _track(context, info, frames):
    with planarvo.Tracker(context, info.camera, info.extrinsics_gt) as tracker:
        return np.array([tracker.track(f, t).motion.as_array() for t, f in frames])


def test_bgr_and_strided_frames_equal_grey(context, tracked):
    info, frames, _, _ = tracked
    frames = frames[:6]
    grey = _track(context, info, frames)
    bgr = _track(context, info, [(t, np.repeat(f[:, :, None], 3, axis=2)) for t, f in frames])
    strided = []
    for t, f in frames:
        big = np.zeros((f.shape[0], f.shape[1] + 37), dtype=np.uint8)
        big[:, 10:10 + f.shape[1]] = f
        view = big[:, 10:10 + f.shape[1]]
        assert not view.flags.c_contiguous
        strided.append((t, view))
    every_other_row = []
    for t, f in frames:
        tall = np.zeros((2 * f.shape[0], f.shape[1]), dtype=np.uint8)
        tall[::2] = f
        every_other_row.append((t, tall[::2]))
    np.testing.assert_array_equal(bgr, grey)
    np.testing.assert_array_equal(_track(context, info, strided), grey)
    np.testing.assert_array_equal(_track(context, info, every_other_row), grey)


def test_reset(context, tracked):
    info, frames, _, results = tracked
    with planarvo.Tracker(context, info.camera, info.extrinsics_gt) as tracker:
        tracker.track(frames[0][1], frames[0][0])
        tracker.reset()
        assert tracker.track(frames[1][1], frames[1][0]).status == planarvo.TrackStatus.FIRST
        r = tracker.track(frames[2][1], frames[2][0])
        assert r.status == planarvo.TrackStatus.OK
        np.testing.assert_allclose(r.pose.as_array(), r.motion.as_array())


def test_flat_field(context, tracked, tmp_path):
    """A known flat field (a 16-bit PNG written here with numpy's values) is saved back unchanged
    away from the border (within 1e-3); nothing learnt is FAILED; a file of another size is INVALID_INPUT."""
    info = tracked[0]
    w, h = info.camera.width, info.camera.height
    y, x = np.mgrid[0:h, 0:w]
    gain = np.rint(60000.0 / (1.0 + ((x - 0.3 * w) ** 2 + (y - 0.6 * h) ** 2) / 250.0 ** 2)).astype(np.uint16)
    known, saved, bad = tmp_path / "known.png", tmp_path / "saved.png", tmp_path / "bad.png"
    _write_png16(known, gain)
    _write_png16(bad, gain[:-1])
    with planarvo.Tracker(context, info.camera, info.extrinsics_gt) as tracker:
        with pytest.raises(planarvo.Error) as e:
            tracker.save_flat_field(saved)
        assert e.value.status == planarvo.Status.FAILED and "learnt" in str(e.value)
    with pytest.raises(planarvo.Error) as e:
        planarvo.Tracker(context, info.camera, info.extrinsics_gt, planarvo.TrackerOptions(flat_field=bad))
    assert e.value.status == planarvo.Status.INVALID_INPUT and str(bad) in str(e.value)
    with planarvo.Tracker(context, info.camera, info.extrinsics_gt,
                          planarvo.TrackerOptions(flat_field=str(known))) as tracker:
        tracker.save_flat_field(saved)
    back = _read_png16(saved)
    assert back.shape == (h, w)
    # Exact to 16 bits and two bilinear samplings where the model has a value; the border columns
    # without an undistorted source (barrel distortion) take the nearest value.
    np.testing.assert_allclose(back[30:-30, 30:-30] / 65535.0, gain[30:-30, 30:-30] / 60000.0, rtol=0, atol=1e-3)
    np.testing.assert_allclose(back[10:-10, 10:-10] / 65535.0, gain[10:-10, 10:-10] / 60000.0, rtol=0, atol=0.02)


def _write_png16(path, a):
    """A 16-bit grey PNG from numpy alone (zlib, no image library)."""
    import struct
    import zlib
    raw = b"".join(b"\x00" + row.astype(">u2").tobytes() for row in a)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", a.shape[1], a.shape[0], 16, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) +
                     chunk(b"IEND", b""))


def _read_png16(path):
    """A 16-bit grey PNG's pixels (any filter type), from numpy and zlib alone."""
    import struct
    import zlib
    data = path.read_bytes()
    pos, idat, w, h = 8, b"", 0, 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 16 and colour == 0, (depth, colour)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride, bpp = 2 * w, 2
    out = np.zeros((h, stride), dtype=np.int64)
    prev = np.zeros(stride, dtype=np.int64)
    for r in range(h):
        f = raw[r * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=r * (stride + 1) + 1).astype(np.int64)
        cur = np.zeros(stride, dtype=np.int64)
        for i in range(stride):
            a = cur[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 0:
                p = 0
            elif f == 1:
                p = a
            elif f == 2:
                p = b
            elif f == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[i] = (line[i] + p) & 0xFF
        out[r] = cur
        prev = cur
    return (out[:, 0::2] * 256 + out[:, 1::2]).astype(np.uint16)


def test_local_plane_follows_a_leaning_body(context, tmp_path):
    """A car whose body rolls with the yaw rate and pitches over bumps: with local_plane the
    tracker's roll and pitch follow the simulator's body (its plane.txt), within a few tenths of a
    degree, with a positive covariance; without it they stay zero."""
    ext = planarvo.Extrinsics(-1.0, 0.0, 0.9, 0.0, math.radians(40.0), math.pi)
    options = planarvo.SimOptions(camera=planarvo.Camera.simulator_default(320, 240, 60.0), seconds=6.0, fps=15.0,
                                  extrinsics=ext, motion=planarvo.MotionProfile.CAR, max_speed=3.0,
                                  min_turn_radius=6.0, lean=-0.07, bumps=math.radians(6.0), seed=3, supersampling=2)
    planarvo.simulate(context, tmp_path / "car", options)
    truth = np.loadtxt(tmp_path / "car" / "plane.txt")
    with planarvo.Dataset(tmp_path / "car") as ds:
        frames = list(ds.frames())
        camera = ds.info.camera
    with planarvo.Tracker(context, camera, ext, planarvo.TrackerOptions(local_plane=True)) as tracker:
        results = [tracker.track(f, t) for t, f in frames]
    with planarvo.Tracker(context, camera, ext) as rigid:
        plain = rigid.track(frames[1][1], frames[1][0])
    assert plain.roll == 0.0 and plain.pitch == 0.0
    est = np.array([[r.roll, r.pitch] for r in results])
    assert np.abs(truth[:, 2]).max() > math.radians(3.0)  # not vacuous: the body pitches
    err = est - truth[:, 1:3]
    assert math.sqrt(np.mean(err ** 2)) < math.radians(0.3)
    assert all(np.all(np.linalg.eigvalsh(r.attitude_covariance) > 0) for r in results)


def test_a_knocked_camera_is_reported_and_recalibrated(context, tmp_path):
    """The camera knocked by 2 degrees of pitch at 2 s: with local_plane the tracker reports the
    change once (a frame's mounting_change, and maybe its refinement), with the body's pitch
    stepped by about -2 degrees (a rear camera: its pitch turns the other way in the body's axes),
    and tracks on with the knocked mounting (the simulator's extrinsics_knocked.yaml) within 0.2
    degrees; REPORT keeps the mounting given. The wheel odometry goes with each frame."""
    ext = planarvo.Extrinsics(-1.0, 0.0, 0.9, 0.0, math.radians(40.0), math.pi)
    options = planarvo.SimOptions(camera=planarvo.Camera.simulator_default(320, 240, 60.0), seconds=4.0,
                                  extrinsics=ext, motion=planarvo.MotionProfile.CAR, max_speed=3.0,
                                  min_turn_radius=6.0, lean=-0.07, seed=5, supersampling=2, knock_time=2.0,
                                  knock_pitch=math.radians(2.0))
    planarvo.simulate(context, tmp_path / "car", options)
    knocked = planarvo.Extrinsics.load(tmp_path / "car" / "extrinsics_knocked.yaml")
    with planarvo.Dataset(tmp_path / "car") as ds:
        frames = list(ds.frames())
        odometry = [ds.frame_data(i).odometry for i in range(len(frames))]
        camera = ds.info.camera
    for response in (planarvo.MountingResponse.RECALIBRATE, planarvo.MountingResponse.REPORT):
        opts = planarvo.TrackerOptions(local_plane=True, on_mounting_change=response)
        with planarvo.Tracker(context, camera, ext, opts) as tracker:
            results = [tracker.track(f, t, odometry=o) for (t, f), o in zip(frames, odometry)]
        changes = [r.mounting_change for r in results if r.mounting_change is not None]
        assert 1 <= len([c for c in changes if not c.refinement]) <= 1
        first = changes[0]
        assert 2.0 <= first.time < 2.1 and first.sigma_pitch > 0
        assert abs(first.step_pitch + math.radians(2.0)) < math.radians(0.2)
        last = results[-1].mounting
        if response == planarvo.MountingResponse.RECALIBRATE:
            assert abs(last.pitch - knocked.pitch) < math.radians(0.2)
            assert abs(changes[-1].mounting.pitch - knocked.pitch) < math.radians(0.2)
        else:
            assert last.pitch == ext.pitch


def test_extrinsics_in_the_wrong_unit_are_refused_unless_accepted(context, tracked):
    """Angles in degrees (12.4 for 12.4 deg) are refused naming the value and the mistake; the
    option lets an unusual rig through."""
    info = tracked[0]
    e = info.extrinsics_gt
    degrees = planarvo.Extrinsics(e.x, e.y, e.z, 12.4, 17.6, -9.2)
    with pytest.raises(planarvo.Error) as err:
        planarvo.Tracker(context, info.camera, degrees)
    assert err.value.status == planarvo.Status.INVALID_ARGUMENT
    assert "roll = 12.4 rad is more than a turn: degrees by mistake?" in err.value.message
    with planarvo.Tracker(context, info.camera, degrees, planarvo.TrackerOptions(accept_unusual_extrinsics=True)):
        pass
    millimetres = planarvo.Extrinsics(e.x, e.y, e.z * 1000.0, e.roll, e.pitch, e.yaw)
    with pytest.raises(planarvo.Error, match="millimetres by mistake"):
        planarvo.Tracker(context, info.camera, millimetres)


def test_track_dataset_returns_the_trackers_results_as_arrays(context, drive, tracked):
    info, frames, _, results = tracked
    with planarvo.Dataset(drive) as ds:
        run = planarvo.track_dataset(context, ds, info.extrinsics_gt)
    assert len(run) == len(results) == run.poses.shape[0] and run.covariances.shape == (len(results), 3, 3)
    np.testing.assert_array_equal(run.times, [t for t, _ in frames])
    np.testing.assert_array_equal(run.poses, [r.pose.as_array() for r in results])
    np.testing.assert_array_equal(run.motions, [r.motion.as_array() for r in results])
    np.testing.assert_array_equal(run.covariances, [r.covariance for r in results])
    assert [planarvo.TrackStatus(s) for s in run.statuses] == [r.status for r in results]
    assert "%d frames" % len(results) in repr(run)
