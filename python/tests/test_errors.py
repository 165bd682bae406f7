"""Bad input: ValueError with the reason before any C call; failed calls raise planarvo.Error
with the status and the library's message; closed handles refuse use."""
import numpy as np
import pytest

import planarvo

CAM = planarvo.Camera(64, 48, 50.0, 50.0, 32.0, 24.0)


@pytest.fixture
def tracker(context):
    with planarvo.Tracker(context, CAM, planarvo.Extrinsics(z=0.2)) as t:
        yield t


@pytest.mark.parametrize("frame, reason", [
    (np.zeros((48, 64), dtype=np.uint16), "dtype"),
    (np.zeros((48, 64), dtype=np.float64), "dtype"),
    (np.zeros((48, 64, 4), dtype=np.uint8), "3 channels"),
    (np.zeros((48, 64, 3), dtype=np.float32), "uint8"),
    (np.zeros((2, 48, 64, 3), dtype=np.uint8), "shape"),
    (np.zeros(48 * 64, dtype=np.uint8), "shape"),
    (np.zeros((48, 128), dtype=np.uint8)[:, ::2], "contiguous"),
    (np.zeros((48, 64, 6), dtype=np.uint8)[:, :, ::2], "contiguous"),
    (np.zeros((64, 48), dtype=np.uint8).T, "contiguous"),
    (np.zeros((48, 64), dtype=np.uint8)[::-1], "stride"),
    (np.zeros((48, 63), dtype=np.uint8), "does not match"),
    (np.zeros((47, 64, 3), dtype=np.uint8), "does not match"),
    ([[0] * 64] * 48, "numpy array"),
])
def test_bad_frames_raise_value_error(tracker, frame, reason):
    with pytest.raises(ValueError, match=reason):
        tracker.track(frame, 0.0)


def test_bad_path_names_the_file(tmp_path):
    missing = tmp_path / "no-such-camera.yaml"
    with pytest.raises(planarvo.Error, match="no-such-camera.yaml") as e:
        planarvo.Camera.load(missing)
    assert e.value.status == planarvo.Status.INVALID_INPUT
    assert e.value.status_name == "PLANARVO_ERROR_INVALID_INPUT"
    with pytest.raises(planarvo.Error, match="no-such-dataset"):
        planarvo.Dataset(tmp_path / "no-such-dataset")


def test_no_device():
    with pytest.raises(planarvo.Error) as e:
        planarvo.Context(device="no-such-device-xyz")
    assert e.value.status == planarvo.Status.NO_DEVICE


def test_non_increasing_timestamps_are_an_error_not_a_crash(tracker):
    frame = np.random.default_rng(1).integers(0, 255, (48, 64), dtype=np.uint8)
    tracker.track(frame, 1.0)
    try:
        r = tracker.track(frame, 0.5)
        assert r.status in (planarvo.TrackStatus.DEGRADED, planarvo.TrackStatus.LOST) and r.reason
    except planarvo.Error as e:
        assert e.status == planarvo.Status.INVALID_ARGUMENT


def test_closed_handles(context):
    t = planarvo.Tracker(context, CAM, planarvo.Extrinsics(z=0.2))
    t.close()
    t.close()  # once only
    assert t.closed
    with pytest.raises(ValueError, match="closed"):
        t.track(np.zeros((48, 64), dtype=np.uint8), 0.0)


def test_other_bad_input(tmp_path):
    with pytest.raises(ValueError, match=r"\(6, 6\)"):
        planarvo.Extrinsics().save(tmp_path / "e.yaml", covariance=np.eye(3))
    with pytest.raises(ValueError, match="unknown parameter"):
        planarvo.Extrinsics().save(tmp_path / "e.yaml", estimated=["height"])
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        planarvo.write_tum(tmp_path / "t.txt", [0.0], [[0.0, 0.0]])
    with pytest.raises(ValueError, match="N rows"):
        planarvo.evaluate_motions(np.zeros((3, 3)), np.zeros((2, 3)), np.ones(3))
    with pytest.raises(ValueError, match="no motion pairs"):
        planarvo.calibrate([])


def test_closing_a_context_closes_its_trackers():
    ctx = planarvo.Context()
    t = planarvo.Tracker(ctx, CAM, planarvo.Extrinsics(z=0.2))
    ctx.close()
    assert t.closed
    with pytest.raises(ValueError, match="closed"):
        t.track(np.zeros((48, 64), dtype=np.uint8), 0.0)
    with pytest.raises(ValueError, match="closed"):
        planarvo.Tracker(ctx, CAM, planarvo.Extrinsics(z=0.2))


def test_error_survives_pickling_with_its_status_and_message(tmp_path):
    import pickle
    with pytest.raises(planarvo.Error) as info:
        planarvo.Camera.load(tmp_path / "missing.yaml")
    copy = pickle.loads(pickle.dumps(info.value))
    assert isinstance(copy, planarvo.Error)
    assert (copy.status, copy.message, str(copy)) == (info.value.status, info.value.message, str(info.value))
    assert "missing.yaml" in copy.message


def test_one_name_is_a_name_not_its_letters(context, tmp_path):
    one = context.export_kernels(tmp_path / "one", uses="track")
    listed = context.export_kernels(tmp_path / "listed", uses=["track"])
    assert one == listed > 0
    planarvo.Extrinsics(z=0.2).save(tmp_path / "e.yaml", estimated="x,yaw")
    assert "yaw" in (tmp_path / "e.yaml").read_text()


def test_a_callback_error_is_raised_once():
    import planarvo._native
    from planarvo._util import _Callback
    cb = _Callback(lambda *a: None, planarvo._native.PROGRESS_FN)
    cb.error = RuntimeError("from the callback")
    with pytest.raises(RuntimeError):
        cb.reraise()
    cb.reraise()  # nothing left to raise


def test_missing_extrinsics_are_a_value_error(context):
    with pytest.raises(ValueError, match="extrinsics"):
        planarvo.Tracker(context, CAM, None)


def test_a_float32_frame_with_unaligned_rows_is_a_value_error(tracker):
    from numpy.lib.stride_tricks import as_strided
    buf = np.zeros(258 * 48 + 4, dtype=np.uint8)
    frame = as_strided(buf[2:].view(np.uint8), shape=(48, 64 * 4), strides=(258, 1)).view(np.float32)
    with pytest.raises(ValueError, match="aligned"):
        tracker.track(frame, 0.0)


@pytest.mark.parametrize("value", [2**40, -2**31 - 1, 2.5, "3"])
def test_an_option_ctypes_would_truncate_is_a_value_error(context, value):
    # ctypes would store 2**40 in an int32 as 0 and refuse 2.5 with a TypeError; both are
    # a ValueError naming the option, before any C call.
    with pytest.raises(ValueError, match="levels"):
        planarvo.Tracker(context, CAM, planarvo.Extrinsics(z=0.2), planarvo.TrackerOptions(levels=value))


def test_an_option_in_range_is_passed_on(context):
    # numpy integers are integers: 3 levels from np.int64(3) (the tracker accepts 1..8).
    with planarvo.Tracker(context, CAM, planarvo.Extrinsics(z=0.2), planarvo.TrackerOptions(levels=np.int64(3))) as t:
        assert t.camera.width == 64


def test_errors_are_the_built_in_exceptions_they_mean(tmp_path, context):
    """A missing file is FileNotFoundError, a malformed one or a bad value ValueError, and each is
    still planarvo.Error with its status; the class survives pickling."""
    import pickle
    missing = tmp_path / "no-such-camera.yaml"
    with pytest.raises(FileNotFoundError) as e:
        planarvo.Camera.load(missing)
    assert isinstance(e.value, planarvo.MissingFileError) and isinstance(e.value, planarvo.Error)
    assert e.value.status == planarvo.Status.INVALID_INPUT and str(missing) in e.value.message
    with pytest.raises(FileNotFoundError):
        planarvo.Dataset(tmp_path / "no-such-drive")
    bad = tmp_path / "bad.yaml"
    bad.write_text("%YAML:1.0\n---\nx: [1, 2\n")
    with pytest.raises(ValueError) as e:
        planarvo.Extrinsics.load(bad)
    assert isinstance(e.value, planarvo.InvalidInputError) and e.value.status == planarvo.Status.INVALID_INPUT
    with pytest.raises(ValueError) as e:
        planarvo.Tracker(context, CAM, planarvo.Extrinsics(z=178.7))  # millimetres
    assert isinstance(e.value, planarvo.InvalidArgumentError) and "millimetres" in e.value.message
    again = pickle.loads(pickle.dumps(e.value))
    assert type(again) is planarvo.InvalidArgumentError and again.message == e.value.message


def test_unreadable_file_is_permission_error(tmp_path):
    import os
    if os.geteuid() == 0:
        pytest.skip("root reads every file")
    f = tmp_path / "camera.yaml"
    planarvo.Camera(64, 48, 50.0, 50.0, 32.0, 24.0).save(f)
    f.chmod(0)
    with pytest.raises(PermissionError):
        planarvo.Camera.load(f)


def test_enums_print_their_names():
    assert str(planarvo.Status.OK) == "Status.OK"
    assert str(planarvo.TrackStatus.LOST) == "TrackStatus.LOST"
    assert "%s" % planarvo.CalibrationMethod.NONHOLONOMIC == "CalibrationMethod.NONHOLONOMIC"
    assert planarvo.TrackStatus.LOST == int(planarvo.TrackStatus.LOST)  # still the C API's integers


@pytest.mark.parametrize("with_progress", [False, True])
def test_ctrl_c_is_a_prompt_keyboard_interrupt(context, tmp_path, capfd, with_progress):
    """SIGINT during a long call cancels it at its next progress report and raises
    KeyboardInterrupt (not Error(CANCELLED), nothing printed about an ignored exception), within
    0.2 s, with or without a progress callback; the context is usable afterwards."""
    import os
    import signal
    import threading
    import time
    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signals reach the main thread only")
    sent = []

    def interrupt():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    opts = planarvo.SimOptions(seconds=120.0, camera=planarvo.Camera(160, 120, 100.0, 100.0, 79.5, 59.5),
                               supersampling=1)
    timer = threading.Timer(1.0, interrupt)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            planarvo.simulate(context, tmp_path / "long", opts, progress=(lambda f, s: False) if with_progress else None)
        caught = time.monotonic()
    finally:
        timer.cancel()
    assert sent and caught - sent[0] < 0.2
    assert "Exception ignored" not in capfd.readouterr().err
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    planarvo.simulate(context, tmp_path / "after", planarvo.SimOptions(seconds=0.2, camera=opts.camera, supersampling=1))
    assert (tmp_path / "after" / "frames.txt").exists()
