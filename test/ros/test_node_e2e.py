"""End to end: planarvo_node in a real ROS 1 graph (ctest ros.node_e2e, ros/README.md).

A roscore on a free port, a 6 s drive simulated with the planarvo tool at 30 frames per second and
turned into a bag (test/tools/rosbag/dataset_to_rosbag.py), played into the node at its recorded
rate and twice as fast (60 images a second; one conversion instead of two, as the converter decodes
PNGs in Python at ~0.2 s a frame). The node must then have published one odometry message and one
transform per image (no frame dropped), with the same poses as `planarvo track` on the data set
folder (the same frames, stamps and options: equal to 1e-9), close to the ground truth, and
counts on ~counts that agree. bgr8 images of the first second: the same poses as on grey. The live
calibration from the images and /odom, then tracking with what it found. Then an image size that disagrees with the camera: every frame is
rejected and counted, nothing published, no crash.

Environment (ros/CMakeLists.txt sets it): PLANARVO_NODE, PLANARVO_CLI, PLANARVO_DATASET_TO_ROSBAG,
PLANARVO_CACHE_DIR; PLANARVO_NODE_SLOW=1 (sanitizer builds) allows longer waits.
"""
import math
import os
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest

SLOW = 4.0 if os.environ.get("PLANARVO_NODE_SLOW") == "1" else 1.0
BASE_NS = 1700000000 * 10**9  # the converter's default --base-time-ns
PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable


def required_env(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail("%s is not set (ctest sets it: ros/CMakeLists.txt)" % name)
    return value


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(what, condition, timeout):
    deadline = time.monotonic() + timeout * SLOW
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.05)
    pytest.fail("timed out after %.0f s waiting for %s" % (timeout * SLOW, what))


def stop(process, timeout=20):
    """SIGINT to a process this test started (its own session), then SIGKILL if it hangs."""
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGINT)
        try:
            process.wait(timeout * SLOW)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    return process.returncode


def yaw_of(q):
    x, y, z, w = q
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def relative(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return (c * dx + s * dy, -s * dx + c * dy, math.remainder(b[2] - a[2], 2 * math.pi))


def read_rows(path):
    with open(path) as f:
        return [[float(v) for v in line.split()] for line in f if line.strip() and not line.startswith("#")]


def read_frame_times(dataset):
    with open(os.path.join(dataset, "frames.txt")) as f:
        return [line.split()[0] for line in f if line.strip() and not line.startswith("#")]


def ns_of(decimal_seconds):
    whole, _, frac = decimal_seconds.partition(".")
    return int(whole) * 10**9 + int((frac + "000000000")[:9])


@pytest.fixture(scope="module")
def ros_env(tmp_path_factory):
    """A roscore on a free port; os.environ points ROS at it (for rospy in this process too)."""
    home = tmp_path_factory.mktemp("ros_home")
    port = free_port()
    os.environ["ROS_MASTER_URI"] = "http://localhost:%d" % port
    os.environ["ROS_HOME"] = str(home)
    os.environ["ROS_LOG_DIR"] = str(home / "log")
    os.environ.pop("ROS_NAMESPACE", None)
    log = open(home / "roscore.log", "w")
    core = subprocess.Popen(["roscore", "-p", str(port)], stdout=log, stderr=subprocess.STDOUT,
                            start_new_session=True)
    import rosgraph
    master = rosgraph.Master("/planarvo_node_e2e")

    def up():
        try:
            master.getPid()
            return True
        except Exception:  # not up yet
            return False

    wait_for("roscore on port %d" % port, up, 30)
    import rospy
    rospy.init_node("planarvo_node_e2e", anonymous=True, disable_signals=True)
    yield master
    rospy.signal_shutdown("done")
    stop(core)
    log.close()


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    """A simulated 6 s drive at 30 fps: (data set folder, its mono8 bag, the data set of its first
    second, that subset's bgr8 bag). The two conversions run side by side."""
    root = tmp_path_factory.mktemp("drive")
    dataset = str(root / "dataset")
    subprocess.run([required_env("PLANARVO_CLI"), "simulate", "--out", dataset, "--seconds", "6", "--fps", "30",
                    "--supersampling", "1", "--quiet"], check=True)
    subset = root / "subset"
    subset.mkdir()
    for name in ("camera.yaml", "extrinsics_gt.yaml", "groundtruth.txt", "odometry.txt", "images"):
        os.symlink(os.path.join(dataset, name), subset / name)
    with open(os.path.join(dataset, "frames.txt")) as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")][:30]
    (subset / "frames.txt").write_text("".join(lines))
    bag, colour_bag = str(root / "drive.bag"), str(root / "bgr8.bag")
    converter = required_env("PLANARVO_DATASET_TO_ROSBAG")
    jobs = [subprocess.Popen([PYTHON, converter, d, b, "--encoding", e], stdout=subprocess.DEVNULL)
            for d, b, e in ((dataset, bag, "mono8"), (str(subset), colour_bag, "bgr8"))]
    for job in jobs:
        assert job.wait() == 0, "dataset_to_rosbag.py failed"
    return dataset, bag, str(subset), colour_bag


def track_with_cli(dataset, extrinsics, trajectory):
    """planarvo track's poses (x, y, yaw) on the data set folder: the reference."""
    subprocess.run([required_env("PLANARVO_CLI"), "track", dataset, "--extrinsics", extrinsics, "-o", trajectory,
                    "--quiet"], check=True, stdout=subprocess.DEVNULL)
    return [(r[1], r[2], yaw_of(r[4:8])) for r in read_rows(trajectory)]


def pose_of(m):
    q = m.pose.pose.orientation
    return (m.pose.pose.position.x, m.pose.pose.position.y, yaw_of((q.x, q.y, q.z, q.w)))


class Listener:
    """Everything the node publishes: odometry, /tf, ~counts."""

    def __init__(self, node_name):
        import rospy
        from nav_msgs.msg import Odometry
        from std_msgs.msg import String
        from diagnostic_msgs.msg import DiagnosticArray
        from tf2_msgs.msg import TFMessage
        self.lock = threading.Lock()
        self.odometry, self.tf, self.counts, self.diagnostics = [], [], [], []
        self.subs = [
            rospy.Subscriber("/odometry", Odometry, self._add(self.odometry), queue_size=10000),
            rospy.Subscriber("/tf", TFMessage, self._add(self.tf), queue_size=10000),
            rospy.Subscriber("/%s/counts" % node_name, String, self._add(self.counts), queue_size=100),
            rospy.Subscriber("/diagnostics", DiagnosticArray, self._add(self.diagnostics), queue_size=100),
        ]
        self.node_name = node_name

    def _add(self, where):
        def callback(msg):
            with self.lock:
                where.append(msg)
        return callback

    def last_counts(self):
        import yaml
        with self.lock:
            return yaml.safe_load(self.counts[-1].data) if self.counts else {}

    def last_diagnostics(self):
        """The node's last frames status on /diagnostics: (level, message, {key: value})."""
        with self.lock:
            for array in reversed(self.diagnostics):
                for st in array.status:
                    if st.name == "/%s: frames" % self.node_name:
                        return st.level, st.message, {kv.key: kv.value for kv in st.values}
        return None

    def close(self):
        for s in self.subs:
            s.unregister()


def start_node(master, name, params, log_path):
    node = required_env("PLANARVO_NODE")
    args = [node, "__name:=" + name, "image:=/camera/image_raw", "camera_info:=/camera/camera_info"]
    args += ["_%s:=%s" % kv for kv in params.items()]
    log = open(log_path, "w")
    process = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)

    def subscribed():
        if process.poll() is not None:
            pytest.fail("planarvo_node exited with %s before subscribing:\n%s" % (process.returncode, open(log_path).read()))
        _, subscribers, _ = master.getSystemState()
        return any(topic == "/camera/image_raw" and "/" + name in nodes for topic, nodes in subscribers)

    wait_for("planarvo_node to subscribe to /camera/image_raw", subscribed, 120)  # kernels built first
    return process


def play(bag, *extra, topics=("/camera/image_raw", "/camera/camera_info")):
    subprocess.run(["rosbag", "play", "-q", "-d", "1", *extra, bag, "--topics", *topics], check=True,
                   stdout=subprocess.DEVNULL, timeout=120 * SLOW)


def image_stamps(bag):
    import rosbag
    with rosbag.Bag(bag) as b:
        return [m.header.stamp.to_nsec() for _, m, _ in b.read_messages(topics=["/camera/image_raw"])]


@pytest.mark.parametrize("fps", [30, 60])
def test_every_frame_tracked_as_the_cli_does(ros_env, drive, tmp_path, fps):
    """The 30 fps drive played at its rate, then twice as fast: 60 images a second."""
    dataset, bag = drive[:2]
    extrinsics = os.path.join(dataset, "extrinsics_gt.yaml")
    cli = track_with_cli(dataset, extrinsics, str(tmp_path / "cli.txt"))
    stamps = image_stamps(bag)
    times = read_frame_times(dataset)
    assert len(stamps) == len(times) == len(cli) == 180
    assert stamps == [BASE_NS + ns_of(t) for t in times]

    name = "planarvo_node_%d" % fps
    listener = Listener(name)
    node = start_node(ros_env, name, {"extrinsics": extrinsics}, tmp_path / "node.log")
    try:
        wait_for("the test's subscriber to connect to the node's odometry", lambda: listener.subs[0].get_num_connections() > 0, 30)
        started = time.monotonic()
        play(bag, "-r", str(fps // 30))
        played = time.monotonic() - started
        n = len(stamps)
        wait_for("%d odometry messages" % n, lambda: len(listener.odometry) >= n, 30)
        wait_for("~counts to show every frame", lambda: listener.last_counts().get("published") == n, 10)
    finally:
        rc = stop(node)
        listener.close()
    log = open(tmp_path / "node.log").read()
    print(log)
    assert rc == 0, log
    counts = listener.last_counts()
    print("fps %d: played in %.1f s; counts %s" % (fps, played, counts))

    # One odometry message and one transform per image, in order: nothing dropped.
    odometry = listener.odometry
    assert len(odometry) == n
    assert [m.header.stamp.to_nsec() for m in odometry] == stamps
    assert counts["received"] == n and counts["tracked"] == n and counts["published"] == n
    assert counts["dropped"] == 0 and counts["seq_gaps"] == 0 and counts["lost"] == 0
    transforms = [t for m in listener.tf for t in m.transforms if t.child_frame_id == "base_link"]
    assert len(transforms) == n
    for m, t in zip(odometry, transforms):
        assert m.header.frame_id == t.header.frame_id == "odom" and m.child_frame_id == "base_link"
        assert t.header.stamp == m.header.stamp
        assert t.transform.translation.x == m.pose.pose.position.x
        assert t.transform.translation.y == m.pose.pose.position.y
        assert t.transform.rotation == m.pose.pose.orientation

    # The same poses as the tool's.
    poses = [pose_of(m) for m in odometry]
    worst = max(max(abs(a - b) for a, b in zip(p, q)) for p, q in zip(poses, cli))
    print("fps %d: largest difference from planarvo track: %.3g" % (fps, worst))
    assert worst < 1e-9

    # Twist: the motion over the interval / its duration, in base_link; covariances as
    # robot_localization expects (planar: z, roll, pitch large).
    for k in range(1, n):
        dt = (stamps[k] - stamps[k - 1]) * 1e-9
        motion = relative(poses[k - 1], poses[k])
        twist = odometry[k].twist.twist
        assert abs(twist.linear.x - motion[0] / dt) < 1e-6 and abs(twist.linear.y - motion[1] / dt) < 1e-6
        assert abs(twist.angular.z - motion[2] / dt) < 1e-6
        for cov in (odometry[k].pose.covariance, odometry[k].twist.covariance):
            assert all(math.isfinite(c) for c in cov)
            assert cov[0] > 0 and cov[7] > 0 and cov[35] > 0
            assert cov[14] == cov[21] == cov[28] == 1e6
    assert odometry[-1].pose.covariance[0] > odometry[1].pose.covariance[0]  # it grows along the drive

    # Against the ground truth: per-frame motions and the end point (the tool gets RMS ~0.003 mm
    # and ~0.001 % on these drives).
    truth = [(r[1], r[2], yaw_of(r[4:8])) for r in read_rows(os.path.join(dataset, "groundtruth.txt"))]
    assert len(truth) == n
    errors, distance = [], 0.0
    for k in range(1, n):
        e, t = relative(poses[k - 1], poses[k]), relative(truth[k - 1], truth[k])
        errors.append(math.hypot(e[0] - t[0], e[1] - t[1]))
        distance += math.hypot(t[0], t[1])
    rms = math.sqrt(sum(e * e for e in errors) / len(errors))
    end_truth = relative(truth[0], truth[-1])
    end_error = math.hypot(poses[-1][0] - end_truth[0], poses[-1][1] - end_truth[1])
    print("fps %d: per-frame translation error RMS %.4f mm, max %.4f mm; end point %.3f mm over %.3f m (%.4f %%)"
          % (fps, rms * 1e3, max(errors) * 1e3, end_error * 1e3, distance, 100 * end_error / distance))
    assert rms < 0.05e-3 and max(errors) < 0.2e-3
    assert distance > 0.3 and end_error < 1e-3 * distance


def test_colour_images(ros_env, drive, tmp_path):
    """bgr8 images (the grey value in three channels) of the drive's first second: the library
    converts them to grey, so the poses are the tool's on the grey images."""
    _, _, subset, bag = drive
    extrinsics = os.path.join(subset, "extrinsics_gt.yaml")
    cli = track_with_cli(subset, extrinsics, str(tmp_path / "cli.txt"))
    name = "planarvo_node_bgr8"
    listener = Listener(name)
    node = start_node(ros_env, name, {"extrinsics": extrinsics}, tmp_path / "node.log")
    try:
        # The log is line-buffered into a file (as under a service manager): there while it runs.
        assert "planarvo_node: ready" in (tmp_path / "node.log").read_text()
        wait_for("the test's subscriber to connect", lambda: listener.subs[0].get_num_connections() > 0, 30)
        play(bag)
        wait_for("30 odometry messages", lambda: len(listener.odometry) >= 30, 30)
    finally:
        rc = stop(node)
        listener.close()
    assert rc == 0
    assert len(listener.odometry) == len(cli) == 30
    # The counts on /diagnostics as well (what rqt_runtime_monitor shows): the same numbers.
    level, message, values = listener.last_diagnostics()
    assert level == 0 and "tracked 30" in message
    assert int(values["received"]) == int(values["tracked"]) == 30 and int(values["dropped"]) == 0
    assert max(max(abs(a - b) for a, b in zip(pose_of(m), q)) for m, q in zip(listener.odometry, cli)) < 1e-9


def test_live_calibration_then_tracking(ros_env, drive, tmp_path):
    """No extrinsics, the drive at twice its rate: the first 120 frames calibrate them against /odom (written to the file), the
    rest are tracked with them; every frame is accounted for."""
    dataset, bag = drive[:2]
    output = tmp_path / "calibrated.yaml"
    name = "planarvo_node_calibrate"
    listener = Listener(name)
    node = start_node(ros_env, name, {"calibrate": "true", "calibration_output": str(output),
                                      "calibration_frames": "120"}, tmp_path / "node.log")
    n = len(image_stamps(bag))
    try:
        play(bag, "-r", "2", topics=("/camera/image_raw", "/camera/camera_info", "/odom"))
        wait_for("~counts to account for every frame",
                 lambda: listener.last_counts().get("not_tracked", 0) + listener.last_counts().get("tracked", 0) == n,
                 30)
    finally:
        rc = stop(node)
        listener.close()
    log = open(tmp_path / "node.log").read()
    counts = listener.last_counts()
    print(log, counts)
    assert rc == 0, log
    assert counts["received"] == n and counts["dropped"] == 0 and counts["calibration_frames"] == 120
    assert 120 <= counts["not_tracked"] < n and counts["published"] == counts["tracked"] == len(listener.odometry)
    assert counts["lost"] == 0

    def read_extrinsics(path):  # the six top-level numbers (the file's matrices carry OpenCV tags)
        with open(path) as f:
            return {k: float(v) for k, _, v in (line.partition(": ") for line in f)
                    if k in ("x", "y", "z", "roll", "pitch", "yaw")}

    got, truth = read_extrinsics(output), read_extrinsics(os.path.join(dataset, "extrinsics_gt.yaml"))
    print("calibrated", {k: got[k] for k in ("x", "y", "z", "roll", "pitch", "yaw")})
    for k in ("x", "y", "z"):
        assert abs(got[k] - truth[k]) < 3e-3, k
    for k in ("roll", "pitch", "yaw"):
        assert abs(got[k] - truth[k]) < math.radians(0.2), k
    # The calibrated line gives each value with its standard deviation, as the file's covariance.
    import re
    line = next(l for l in log.splitlines() if "planarvo_node: calibrated:" in l)
    m = re.search(r"x (\S+) \+- (\S+), y \S+ \+- \S+, z (\S+) \+- (\S+) m", line)
    assert m, line
    assert abs(float(m.group(1)) - got["x"]) < 1e-4 and abs(float(m.group(3)) - got["z"]) < 1e-4
    assert 0 < float(m.group(2)) < 0.01 and 0 < float(m.group(4)) < 0.01, line


def test_image_size_not_the_cameras_is_counted_not_tracked(ros_env, drive, tmp_path):
    """~camera says 320x240, the images are 640x480: each frame is rejected with an error naming
    both sizes and counted; no odometry, no crash, and the node still stops cleanly."""
    dataset, bag = drive[:2]
    camera = tmp_path / "camera_320.yaml"
    with open(os.path.join(dataset, "camera.yaml")) as f:
        text = f.read()
    camera.write_text(text.replace("image_width: 640", "image_width: 320").replace("image_height: 480",
                                                                                   "image_height: 240"))
    name = "planarvo_node_bad_size"
    listener = Listener(name)
    node = start_node(ros_env, name, {"extrinsics": os.path.join(dataset, "extrinsics_gt.yaml"),
                                      "camera": str(camera)}, tmp_path / "node.log")
    try:
        play(bag, "-u", "1")  # the first second
        wait_for("~counts to show the frames rejected",
                 lambda: listener.last_counts().get("rejected", 0) > 0 and
                 listener.last_counts()["rejected"] == listener.last_counts()["received"], 10)
        time.sleep(0.5)
    finally:
        rc = stop(node)
        listener.close()
    log = open(tmp_path / "node.log").read()
    counts = listener.last_counts()
    print(log, counts)
    assert rc == 0
    assert counts["received"] >= 25 and counts["rejected"] == counts["received"] and counts["published"] == 0
    assert counts["dropped"] == counts["rejected"]
    assert not listener.odometry
    assert "the image is 640x480 but the camera (%s) is 320x240" % camera in log


def test_a_misspelt_parameter_is_fatal_naming_the_nearest(ros_env, tmp_path):
    """~publish_tfs (for ~publish_tf) stops the node at once with a FATAL naming both, instead of
    being ignored; ~force (an unusual rig) is a parameter it knows."""
    node = required_env("PLANARVO_NODE")
    log = tmp_path / "node.log"
    with open(log, "w") as f:
        p = subprocess.run([node, "__name:=planarvo_node_misspelt", "_publish_tfs:=false"], stdout=f,
                           stderr=subprocess.STDOUT, timeout=60 * SLOW)
    text = log.read_text()
    assert p.returncode != 0, text
    assert "unknown parameter ~publish_tfs" in text and "did you mean ~publish_tf?" in text, text


def test_a_wrong_image_topic_is_warned_within_5_s_naming_the_published_ones(ros_env, drive, tmp_path):
    """Subscribed to a topic nobody publishes while the drive plays on /camera/image_raw: a WARN
    naming the topic subscribed and the image topics that are published, within 5 s of starting."""
    dataset, bag = drive[:2]
    node = required_env("PLANARVO_NODE")
    log_path = tmp_path / "node.log"
    log = open(log_path, "w")
    player = subprocess.Popen(["rosbag", "play", "-q", "-l", bag, "--topics", "/camera/image_raw"],
                              stdout=subprocess.DEVNULL, start_new_session=True)
    process = subprocess.Popen([node, "__name:=planarvo_node_wrong_topic", "image:=/wrong/image_raw",
                                "_extrinsics:=" + os.path.join(dataset, "extrinsics_gt.yaml")],
                               stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        wait_for("the node to be ready", lambda: "planarvo_node: ready" in log_path.read_text(), 120)
        ready = time.monotonic()
        wait_for("the WARN", lambda: "no image on /wrong/image_raw" in log_path.read_text(), 10)
        warned = time.monotonic()
    finally:
        stop(process)
        stop(player)
    line = next(l for l in log_path.read_text().splitlines() if "no image on /wrong/image_raw" in l)
    assert "/camera/image_raw (sensor_msgs/Image)" in line, line
    assert warned - ready < 5.0 * SLOW, warned - ready


def test_live_calibration_reports_its_progress_every_5_s(ros_env, drive, tmp_path):
    """The drive at half its rate (12 s) into a calibration of 170 frames: while it takes frames, an
    INFO every 5 s with the frames fed of those needed, how many had odometry, and the odometry's
    motion so far, each figure consistent with the one before and with the bag's own odometry."""
    dataset, bag = drive[:2]
    name = "planarvo_node_progress"
    log_path = tmp_path / "node.log"
    node = start_node(ros_env, name, {"calibrate": "true", "calibration_output": str(tmp_path / "c.yaml"),
                                      "calibration_frames": "170"}, log_path)
    try:
        play(bag, "-r", "0.5", topics=("/camera/image_raw", "/camera/camera_info", "/odom"))
        wait_for("the calibration", lambda: (tmp_path / "c.yaml").exists(), 60)
    finally:
        rc = stop(node)
    log = log_path.read_text()
    assert rc == 0, log
    import re
    pattern = re.compile(r"\[(\d+\.\d+)\]: planarvo_node: calibration: (\d+) of 170 frames \((\d+) with odometry\); "
                         r"odometry so far (\S+) m, (\S+) deg turned")
    lines = [m.groups() for m in map(pattern.search, log.splitlines()) if m]
    assert len(lines) >= 1, log
    # The bag's odometry path: its length and its absolute turns (odometry.txt, TUM: t x y z qx qy qz qw).
    poses = []
    with open(os.path.join(dataset, "odometry.txt")) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                v = [float(x) for x in line.split()]
                poses.append((v[1], v[2], 2 * math.atan2(v[6], v[7])))
    length = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(poses, poses[1:]))
    turned = sum(abs(math.remainder(b[2] - a[2], 2 * math.pi)) for a, b in zip(poses, poses[1:]))
    print(lines, length, math.degrees(turned))
    previous = None
    for stamp, fed, with_odometry, metres, degrees in lines:
        stamp, fed, with_odometry, metres, degrees = float(stamp), int(fed), int(with_odometry), float(metres), float(degrees)
        assert 0 < fed < 170 and 0 <= with_odometry <= fed
        assert 0 <= metres <= length + 1e-3 and 0 <= degrees <= math.degrees(turned) + 0.05
        if previous:
            assert stamp - previous[0] >= 5.0 - 0.01  # every 5 s, no more often
            assert fed > previous[1] and metres >= previous[2] and degrees >= previous[3]
        previous = (stamp, fed, metres, degrees)
    assert previous[2] > 0, "the odometry played, so it moved"
