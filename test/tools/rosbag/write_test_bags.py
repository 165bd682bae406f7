#!/usr/bin/python3
"""Writes small ROS 1 bags with Debian's python3-rosbag (the official writer, independent of
planarvo's reader) and, beside each, a sidecar of what it holds (BAG.expected), for
test/unit/io_bag_rosbag1_test.cpp.

    /usr/bin/python3 write_test_bags.py OUT_DIR
    /usr/bin/python3 write_test_bags.py --seeds OUT_DIR   # fuzz/seeds/rosbag1: 2 frames, no sidecars

Sidecar (one record per line, fields separated by one space, no field contains a space):
    topic NAME TYPE MD5SUM COUNT
    msg TOPIC RECEIVE_NS RAW_LEN RAW_FNV1A KIND FIELDS...    (in index order: by receive time,
                                                               ties in file order)
    error BYTE                                               (the bag is truncated inside the
                                                               chunk at BYTE: reading it fails)
RAW_FNV1A is the 64-bit FNV-1a of the message's serialised bytes (hex). KIND and FIELDS:
    image STAMP_NS FRAME_ID HEIGHT WIDTH ENCODING IS_BIGENDIAN STEP DATA_LEN DATA_FNV1A
    compressed STAMP_NS FRAME_ID FORMAT DATA_LEN DATA_FNV1A
    camera_info STAMP_NS FRAME_ID HEIGHT WIDTH MODEL N_D D... K(9) R(9) P(12) BINNING_X BINNING_Y
                ROI_X ROI_Y ROI_H ROI_W DO_RECTIFY
    odometry STAMP_NS FRAME_ID CHILD_FRAME_ID POSITION(3) ORIENTATION(4) POSE_COV(36) LINEAR(3)
             ANGULAR(3) TWIST_COV(36)
    other
Floats are Python's repr (shortest round trip: strtod gives the same double).

Bags (every one with the same messages unless said):
    none_small.bag   uncompressed, chunk_threshold 2 KiB (several chunks)
    none_large.bag   uncompressed, one chunk
    bz2_small.bag    bz2, several chunks
    lz4_small.bag    lz4 (roslz4: LZ4 frames), several chunks
    lz4_large.bag    lz4, one chunk
    none_small_unindexed.bag, lz4_small_unindexed.bag: the *_small bags as a recorder killed
        after its last chunk leaves them: the file cut where the index section began (index_pos)
        and the bag header's index_pos, conn_count and chunk_count set to 0 (what rosbag writes
        when it starts a bag; the header is rewritten only on close).
    none_truncated.bag, lz4_truncated.bag: the *_small bags cut in the middle of their second
        chunk's data (index_pos still points past the end).
    none_killed.bag  a copy taken while the writer is inside a chunk (never closed): index_pos 0,
        the last chunk's lengths still 0 as rosbag writes them until the chunk is complete.
    conflict.bag     /odom recorded twice: nav_msgs/Odometry and, on a second connection, std_msgs/String
    md5_mismatch.bag /camera/image_raw as sensor_msgs/Image with another definition's md5sum
"""
import io
import os
import random
import sys

import genpy
import rosbag
from geometry_msgs.msg import Point, Pose, PoseWithCovariance, Quaternion, Twist, TwistWithCovariance, Vector3
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, RegionOfInterest
from std_msgs.msg import Header, String

BASE_NS = 1700000000 * 10**9 + 123456789


def fnv1a(data):
    h = 0xcbf29ce484222325
    for b in data:
        h = ((h ^ b) * 0x100000001b3) & 0xffffffffffffffff
    return '%016x' % h


def to_time(ns):
    return genpy.Time(ns // 10**9, ns % 10**9)


def header(stamp_ns, frame_id, seq):
    return Header(seq=seq, stamp=to_time(stamp_ns), frame_id=frame_id)


def serialize(msg):
    buf = io.BytesIO()
    msg.serialize(buf)
    return buf.getvalue()


def floats(values):
    return ' '.join(repr(float(v)) for v in values)


def describe(msg):
    """KIND FIELDS... for the sidecar."""
    if isinstance(msg, Image):
        return 'image %d %s %d %d %s %d %d %d %s' % (
            msg.header.stamp.to_nsec(), msg.header.frame_id, msg.height, msg.width, msg.encoding,
            msg.is_bigendian, msg.step, len(msg.data), fnv1a(msg.data))
    if isinstance(msg, CompressedImage):
        return 'compressed %d %s %s %d %s' % (
            msg.header.stamp.to_nsec(), msg.header.frame_id, msg.format, len(msg.data), fnv1a(msg.data))
    if isinstance(msg, CameraInfo):
        roi = msg.roi
        return 'camera_info %d %s %d %d %s %d %s %s %s %s %d %d %d %d %d %d %d' % (
            msg.header.stamp.to_nsec(), msg.header.frame_id, msg.height, msg.width, msg.distortion_model,
            len(msg.D), floats(msg.D), floats(msg.K), floats(msg.R), floats(msg.P), msg.binning_x,
            msg.binning_y, roi.x_offset, roi.y_offset, roi.height, roi.width, int(roi.do_rectify))
    if isinstance(msg, Odometry):
        p, t = msg.pose, msg.twist
        return 'odometry %d %s %s %s %s %s %s %s %s' % (
            msg.header.stamp.to_nsec(), msg.header.frame_id, msg.child_frame_id,
            floats([p.pose.position.x, p.pose.position.y, p.pose.position.z]),
            floats([p.pose.orientation.x, p.pose.orientation.y, p.pose.orientation.z, p.pose.orientation.w]),
            floats(p.covariance), floats([t.twist.linear.x, t.twist.linear.y, t.twist.linear.z]),
            floats([t.twist.angular.x, t.twist.angular.y, t.twist.angular.z]), floats(t.covariance))
    return 'other'


def image(rng, stamp_ns, seq, encoding):
    channels = 3 if encoding == 'bgr8' else 1
    width, height = (10, 6) if channels == 3 else (16, 12)
    step = width * channels + 2 + seq % 3  # rows padded past width * channels
    data = bytes(rng.randrange(256) for _ in range(step * height))
    return Image(header=header(stamp_ns, 'camera_optical', seq), height=height, width=width,
                 encoding=encoding, is_bigendian=0, step=step, data=data)


def compressed(rng, stamp_ns, seq):
    data = b'\x89PNG\r\n\x1a\n' + bytes(rng.randrange(256) for _ in range(40 + seq))
    return CompressedImage(header=header(stamp_ns, 'camera_optical', seq), format='png', data=data)


def camera_info(stamp_ns, seq):
    return CameraInfo(
        header=header(stamp_ns, 'camera_optical', seq), height=12, width=16, distortion_model='plumb_bob',
        D=[-0.28 - seq * 1e-3, 0.07, 1.5e-4, -2.5e-4, 0.0123456789],
        K=[458.654, 0.0, 367.215, 0.0, 457.296, 248.375, 0.0, 0.0, 1.0],
        R=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        P=[458.654, 0.0, 367.215, 0.1, 0.0, 457.296, 248.375, 0.2, 0.0, 0.0, 1.0, 0.3],
        binning_x=1, binning_y=2, roi=RegionOfInterest(x_offset=3, y_offset=4, height=5, width=6, do_rectify=True))


def odometry(stamp_ns, seq, frame_id):
    cov = [seq + k / 100.0 + 1e-9 for k in range(36)]
    return Odometry(
        header=header(stamp_ns, frame_id, seq), child_frame_id='base_link',
        pose=PoseWithCovariance(
            pose=Pose(position=Point(0.1 * seq, -0.2 * seq, 0.003),
                      orientation=Quaternion(0.01, -0.02, 0.3 + seq * 1e-3, 0.95)),
            covariance=cov),
        twist=TwistWithCovariance(twist=Twist(linear=Vector3(1.5, 0.0, -0.01), angular=Vector3(0.0, 0.02, 0.3)),
                                  covariance=[-c for c in cov]))


def messages(frames=12):
    """(topic, receive_ns, msg) in the order they are written."""
    rng = random.Random(20261125)
    out = []
    for i in range(frames):
        t = BASE_NS + i * 100_000_000          # receive times, 10 Hz
        stamp = t - 7_654_321 - i * 1000       # header stamps differ from receive times
        # The image and its camera info share a receive time (ties keep file order).
        out.append(('/camera/image_raw', t, image(rng, stamp, i, 'mono8')))
        out.append(('/camera/camera_info', t, camera_info(stamp, i)))
        out.append(('/camera/color/image_raw', t + 1000, image(rng, stamp, i, 'bgr8')))
        out.append(('/camera/image_raw/compressed', t + 2000, compressed(rng, stamp, i)))
        out.append(('/chatter', t + 3000, String(data='hello %d' % i)))
        out.append(('/odom', t + 40_000_000, odometry(stamp + 40_000_000, i, 'odom')))
        if i == 5:  # one message received before the previous ones (written late)
            out.append(('/ground_truth', t - 150_000_000, odometry(stamp - 150_000_000, 99, 'world')))
    return out


def write_bag(path, compression, chunk_threshold, msgs, tweak=None, definitions=True):
    """definitions=False: the connection headers carry an empty message_definition (the reader
    does not need it; the fuzz seeds stay small)."""
    bag = rosbag.Bag(path, 'w', compression=compression, chunk_threshold=chunk_threshold)
    try:
        for topic, t, msg in msgs:
            if definitions:
                bag.write(topic, msg, to_time(t))
            else:
                bag.write(topic, (msg._type, serialize(msg), msg._md5sum, type(msg)), to_time(t), raw=True,
                          connection_header={'topic': topic, 'type': msg._type, 'md5sum': msg._md5sum,
                                             'message_definition': ''})
        if tweak:
            tweak(bag)
    finally:
        bag.close()


def write_sidecar(path, msgs, topics, error_byte=None):
    order = sorted(range(len(msgs)), key=lambda k: msgs[k][1])  # stable: ties in file order
    with open(path, 'w') as f:
        for name, (type_, md5, count) in sorted(topics.items()):
            f.write('topic %s %s %s %d\n' % (name, type_, md5, count))
        for k in order:
            topic, t, msg = msgs[k]
            raw = serialize(msg)
            f.write('msg %s %d %d %s %s\n' % (topic, t, len(raw), fnv1a(raw), describe(msg)))
        if error_byte is not None:
            f.write('error %d\n' % error_byte)


def topics_of(msgs):
    topics = {}
    for topic, _, msg in msgs:
        type_, md5, count = topics.get(topic, (msg._type, msg._md5sum, 0))
        topics[topic] = (type_, md5, count + 1)
    return topics


def bag_header(path):
    """(offset of the bag header record's header, index_pos, chunk positions) of a closed bag."""
    with rosbag.Bag(path) as bag:
        chunks = [c.pos for c in bag._chunks]
        return bag._file_header_pos, bag._index_data_pos, chunks


def unindexed_copy(src, dst):
    """src as a killed recorder leaves it: cut at index_pos, header fields zeroed in place."""
    _, index_pos, _ = bag_header(src)
    with open(src, 'rb') as f:
        data = bytearray(f.read()[:index_pos])
    for name, width in ((b'index_pos=', 8), (b'conn_count=', 4), (b'chunk_count=', 4)):
        at = data.index(name, 0, 4096 + 13) + len(name)
        data[at:at + width] = bytes(width)
    with open(dst, 'wb') as f:
        f.write(data)


def truncated_copy(src, dst):
    """src cut in the middle of its second chunk's data; returns that chunk's offset."""
    _, _, chunks = bag_header(src)
    with open(src, 'rb') as f:
        data = f.read()
    cut = (chunks[1] + chunks[2]) // 2
    with open(dst, 'wb') as f:
        f.write(data[:cut])
    return chunks[1]


def write_seeds(out):
    """Small bags (< 20 KB) for the fuzz target: the first two frames, each compression, and the
    unindexed form."""
    os.makedirs(out, exist_ok=True)
    msgs = messages(frames=2)
    for compression in ('none', 'bz2', 'lz4'):
        path = os.path.join(out, compression + '.bag')
        write_bag(path, compression, 1024, msgs, definitions=False)
        unindexed_copy(path, os.path.join(out, compression + '_unindexed.bag'))


def main():
    if len(sys.argv) == 3 and sys.argv[1] == '--seeds':
        write_seeds(sys.argv[2])
        return
    if len(sys.argv) != 2:
        sys.exit('usage: write_test_bags.py [--seeds] OUT_DIR')
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    msgs = messages()
    topics = topics_of(msgs)
    for name, compression, threshold in (('none_small', 'none', 2048), ('none_large', 'none', 768 * 1024),
                                         ('bz2_small', 'bz2', 2048), ('lz4_small', 'lz4', 2048),
                                         ('lz4_large', 'lz4', 768 * 1024)):
        path = os.path.join(out, name + '.bag')
        write_bag(path, compression, threshold, msgs)
        write_sidecar(path + '.expected', msgs, topics)
    for name in ('none_small', 'lz4_small'):
        src = os.path.join(out, name + '.bag')
        unindexed_copy(src, os.path.join(out, name + '_unindexed.bag'))
        write_sidecar(os.path.join(out, name + '_unindexed.bag.expected'), msgs, topics)
        dst = os.path.join(out, name.replace('_small', '_truncated') + '.bag')
        write_sidecar(dst + '.expected', msgs, topics, error_byte=truncated_copy(src, dst))

    # A recording killed inside its third chunk: copy the file while the writer is still open.
    bag = rosbag.Bag(os.path.join(out, 'none_killed.bag.tmp'), 'w', chunk_threshold=2048)
    written = 0
    while written < 18 or not bag._chunk_open:  # stop inside a chunk, after at least 3 frames
        topic, t, msg = msgs[written]
        bag.write(topic, msg, to_time(t))
        written += 1
    bag._file.flush()
    with open(os.path.join(out, 'none_killed.bag.tmp'), 'rb') as f:
        killed = f.read()
    open_chunk = bag._curr_chunk_info.pos
    bag.close()
    os.remove(os.path.join(out, 'none_killed.bag.tmp'))
    with open(os.path.join(out, 'none_killed.bag'), 'wb') as f:
        f.write(killed)
    write_sidecar(os.path.join(out, 'none_killed.bag.expected'), msgs[:written], topics_of(msgs[:written]),
                  open_chunk)

    # /odom on a second connection with another type: the writer keeps one connection per topic,
    # so forget it before writing the String.
    def second_odom(bag):
        del bag._topic_connections['/odom']
        bag.write('/odom', String(data='not odometry'), to_time(BASE_NS + 5 * 10**9))
    conflict = [m for m in msgs if m[0] in ('/odom', '/chatter')]
    write_bag(os.path.join(out, 'conflict.bag'), 'none', 768 * 1024, conflict, second_odom)

    # An Image under its name but recorded with another definition's md5sum.
    other_md5 = '0123456789abcdef0123456789abcdef'
    with rosbag.Bag(os.path.join(out, 'md5_mismatch.bag'), 'w') as bag:
        for topic, t, msg in msgs:
            if topic == '/camera/image_raw':
                bag.write(topic, (msg._type, serialize(msg), other_md5, Image), to_time(t), raw=True,
                          connection_header={'topic': topic, 'type': msg._type, 'md5sum': other_md5,
                                             'message_definition': msg._full_text})
            elif topic == '/odom':
                bag.write(topic, msg, to_time(t))


if __name__ == '__main__':
    main()
