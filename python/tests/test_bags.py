"""A ROS 1 bag and an MCAP file as planarvo.Dataset: the simulated drive written by the
independent writers (Debian's python3-rosbag, the official MCAP TypeScript library; see
test/tools) holds the same frames, times, odometry and ground truth as the folder. Skipped when a
writer is missing (scripts/install-deps.sh installs both)."""
import os
import shutil
import subprocess

import numpy as np
import pytest

import planarvo

TOOLS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "test", "tools")


def _rosbag_writer():
    if subprocess.run(["/usr/bin/python3", "-c", "import rosbag, sensor_msgs.msg, nav_msgs.msg"],
                      capture_output=True).returncode != 0:
        pytest.skip("Debian's python3-rosbag is not installed (scripts/install-deps.sh)")
    return ["/usr/bin/python3", os.path.join(TOOLS, "rosbag", "dataset_to_rosbag.py")]


def _mcap_writer():
    if shutil.which("node") is None or not os.path.isdir(os.path.join(TOOLS, "mcap", "node_modules", "@mcap")):
        pytest.skip("node or test/tools/mcap/node_modules is missing (scripts/install-deps.sh)")
    return ["node", os.path.join(TOOLS, "mcap", "dataset_to_mcap.mjs")]


@pytest.mark.parametrize("writer, name, options", [
    (_rosbag_writer, "drive.bag", ["--compression", "lz4", "--encoding", "bgr8"]),
    (_mcap_writer, "drive.mcap", ["--compression", "zstd"]),
])
def test_a_bag_holds_the_folders_frames(drive, tmp_path, writer, name, options):
    path = tmp_path / name
    subprocess.run(writer() + [str(drive), str(path)] + options, check=True, capture_output=True)
    with planarvo.Dataset(drive) as folder, planarvo.Dataset(
            path, camera_info_topic="/camera/camera_info", odometry_topic="/odom",
            groundtruth_topic="/ground_truth") as bag:
        fi, bi = folder.info, bag.info
        assert bi.is_bag and not fi.is_bag
        assert bi.frame_count == fi.frame_count
        assert bi.camera == fi.camera
        # The converters stamp frame i at 1.7e9 s + t_i: the origin is the first frame's stamp
        # in integer ns, the times are seconds after it.
        assert bi.time_origin_ns == 1700000000000000000 + round(fi.first_timestamp * 1e9)
        for i in range(fi.frame_count):
            f, b = folder.frame_data(i), bag.frame_data(i)
            assert b.timestamp == pytest.approx(f.timestamp - fi.first_timestamp, abs=1e-9)
            np.testing.assert_allclose(np.asarray(b.odometry), np.asarray(f.odometry), atol=1e-9)
            np.testing.assert_allclose(np.asarray(b.groundtruth), np.asarray(f.groundtruth), atol=1e-9)
            np.testing.assert_array_equal(bag.frame(i), folder.frame(i))


def test_a_missing_topic_names_the_topics_there_are(drive, tmp_path):
    path = tmp_path / "drive.bag"
    subprocess.run(_rosbag_writer() + [str(drive), str(path)], check=True, capture_output=True)
    with planarvo.Dataset(drive) as folder:
        n = folder.info.frame_count
    assert sorted(planarvo.bag_topics(path)) == [("/camera/camera_info", "sensor_msgs/CameraInfo", n),
                                                 ("/camera/image_raw", "sensor_msgs/Image", n),
                                                 ("/ground_truth", "nav_msgs/Odometry", n),
                                                 ("/odom", "nav_msgs/Odometry", n)]
    with pytest.raises(planarvo.Error) as e:
        planarvo.Dataset(path, image_topic="/front/image_raw")
    assert e.value.status == planarvo.Status.INVALID_INPUT
    for topic in ("/camera/image_raw", "/camera/camera_info", "/odom", "/ground_truth"):
        assert topic in str(e.value)
    # The message names this call's keyword, not the planarvo tool's option.
    assert "image_topic=" in e.value.message and "--image-topic" not in e.value.message
    with pytest.raises(ValueError):
        planarvo.Dataset(path, image_topic=3)


def test_info_names_the_topic_of_each_stream(drive, tmp_path):
    """planarvo info on a bag: for each stream the topic it comes from (given, or the only one of
    its type), or the candidates and the option that picks one, on the line that said yes/no."""
    from conftest import cli_path
    cli = cli_path()
    if not cli:
        pytest.skip("the planarvo CLI was not found (set PLANARVO_CLI)")
    path = tmp_path / "drive.bag"
    subprocess.run(_rosbag_writer() + [str(drive), str(path)], check=True, capture_output=True)
    with planarvo.Dataset(drive) as folder:
        n = folder.info.frame_count

    def lines(*extra):
        out = subprocess.run([cli, "info", str(path), "--quiet", *extra], check=True, capture_output=True, text=True)
        return {l[2:13].strip(): l[14:] for l in out.stdout.splitlines() if l.startswith("  ") and len(l) > 14}

    got = lines()
    assert got["images"] == "/camera/image_raw (sensor_msgs/Image, %d messages), the only one" % n
    assert got["camera from"] == "/camera/camera_info (sensor_msgs/CameraInfo, %d messages), the only one" % n
    assert got["odometry"].startswith("not read: give --odom-topic (")
    assert "/odom (nav_msgs/Odometry, %d messages)" % n in got["odometry"]
    assert "/ground_truth (nav_msgs/Odometry, %d messages)" % n in got["odometry"]
    got = lines("--odom-topic", "/odom", "--groundtruth-topic", "/ground_truth")
    assert got["odometry"] == "/odom (nav_msgs/Odometry, %d messages)" % n
    assert got["groundtruth"] == "/ground_truth (nav_msgs/Odometry, %d messages)" % n


@pytest.mark.parametrize("writer, name", [(_rosbag_writer, "drive.bag"), (_mcap_writer, "drive.mcap")])
def test_the_plots_read_a_bags_topics(drive, tmp_path, writer, name):
    """plot track, calibration and outliers take track's bag options (issue 25): with them each
    reads from the bag what it reads from the folder, to the last bit of the library's numbers;
    without the odometry topic, the calibration figures are exit 2 naming the option."""
    pytest.importorskip("matplotlib")
    from planarvo.plot import _cli
    from planarvo.plot._calibration_data import prepare
    from planarvo.plot._io import read_dataset
    from planarvo.plot._outliers import track_frame
    bag = tmp_path / name
    subprocess.run(writer() + [str(drive), str(bag)], check=True, capture_output=True)
    topics = {"odometry_topic": "/odom", "groundtruth_topic": "/ground_truth"}
    flags = ["--odom-topic", "/odom", "--groundtruth-topic", "/ground_truth"]

    folder, series = read_dataset(str(drive)), read_dataset(str(bag), topics)
    np.testing.assert_allclose(series.times, folder.times - folder.times[0], atol=1e-9)
    np.testing.assert_allclose(series.odometry, folder.odometry, atol=1e-9)
    np.testing.assert_allclose(series.groundtruth, folder.groundtruth, atol=1e-9)
    bare = read_dataset(str(bag))
    assert bare.odometry is None and bare.groundtruth is None

    # plot track: the velocity figures need the reference the topics give.
    planarvo.write_tum(tmp_path / "t.txt", series.times + series.time_origin_s, series.groundtruth)  # as track writes
    for out, extra, expected in (("bare", [], {"trajectory.png"}),
                                 ("topics", flags, {"trajectory.png", "velocity.png", "velocity_hist.png"})):
        assert _cli.main(["track", str(bag), "--trajectory", str(tmp_path / "t.txt"),
                          "--out-dir", str(tmp_path / out)] + extra) == 0
        assert set(os.listdir(tmp_path / out)) == expected

    # plot calibration: the motion pairs tracked from the bag are the folder's, so is the result.
    extrinsics = os.path.join(drive, "extrinsics_gt.yaml")
    a = prepare(str(drive), None, extrinsics, None, 2, None)[0]
    b = prepare(str(bag), None, extrinsics, None, 2, None, {"odometry_topic": "/odom"})[0]
    assert len(a.pairs) == len(b.pairs) > 20
    np.testing.assert_allclose(b.whole.result.value, a.whole.result.value, atol=1e-9)
    assert _cli.main(["calibration", str(bag), "--extrinsics", extrinsics, "--windows", "0",
                      "--out-dir", str(tmp_path / "c0")]) == 2
    assert not (tmp_path / "c0" / "calibration_estimates.png").exists()
    assert _cli.main(["calibration", str(bag), "--extrinsics", extrinsics, "--windows", "0", "--odom-topic", "/odom",
                      "--out-dir", str(tmp_path / "c1")]) == 0
    assert (tmp_path / "c1" / "calibration_estimates.png").exists()

    # plot outliers: the same frame's residuals.
    fa = track_frame(str(drive), extrinsics, 12, 1)
    fb = track_frame(str(bag), extrinsics, 12, 1, {"camera_info_topic": "/camera/camera_info"})
    np.testing.assert_array_equal(fb.residuals.residual, fa.residuals.residual)
    assert _cli.main(["outliers", str(bag), "--extrinsics", extrinsics, "--frame", "12",
                      "--camera-info-topic", "/camera/camera_info", "--out-dir", str(tmp_path / "o")]) == 0
    # A bag option on a folder is bad input.
    assert _cli.main(["outliers", str(drive), "--extrinsics", extrinsics, "--frame", "12", "--odom-topic", "/odom",
                      "--out-dir", str(tmp_path / "o2")]) == 2
