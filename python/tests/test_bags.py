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
