#!/usr/bin/python3
"""Converts a planarvo data set folder into a ROS 1 bag with Debian's python3-rosbag.

    /usr/bin/python3 dataset_to_rosbag.py DATASET_DIR OUT.bag [--compression none|bz2|lz4]
        [--base-time-ns N] [--encoding mono8|bgr8|rgb8|png]

Reads DATASET_DIR/camera.yaml (image_width, image_height, camera_matrix and
distortion_coefficients `data: [...]` lists), frames.txt (`t path`, '#' comments), the images it
names (8-bit grey PNGs, decoded here with zlib: no OpenCV needed) and, when present,
odometry.txt and groundtruth.txt (TUM: `t x y z qx qy qz qw`). Writes:

    /camera/image_raw             sensor_msgs/Image, mono8 (bgr8 and rgb8 repeat the grey value in
                                  three channels), frame_id "camera"; or with --encoding png
    /camera/image_raw/compressed  sensor_msgs/CompressedImage, format "png", the PNG file's bytes
    /camera/camera_info           sensor_msgs/CameraInfo, plumb_bob, one per frame with its stamp
    /odom                         nav_msgs/Odometry from odometry.txt, frame "odom", child "base_link"
    /ground_truth                 nav_msgs/Odometry from groundtruth.txt, frame "world", child "base_link"

A header stamp is base_time_ns + t * 1e9 rounded to the nearest nanosecond, computed exactly from
t's decimal digits (default base 1700000000000000000); the message's receive (record) time is the
stamp + 5 ms. Messages are written in receive-time order.
"""
import argparse
import os
import re
import struct
import sys
import zlib
from fractions import Fraction

import genpy
import rosbag
from geometry_msgs.msg import Point, Pose, PoseWithCovariance, Quaternion, Twist, TwistWithCovariance, Vector3
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, CompressedImage, Image
from std_msgs.msg import Header

RECEIVE_DELAY_NS = 5_000_000


def fail(message):
    sys.exit('dataset_to_rosbag: ' + message)


def stamp_ns(text, base_ns, where):
    """base_ns + t * 1e9 to the nearest ns, t parsed exactly from its decimal string."""
    try:
        t = Fraction(text)
    except (ValueError, ZeroDivisionError):
        fail('%s: %r is not a time stamp' % (where, text))
    ns = base_ns + round(t * 10**9)
    if ns < 0 or ns // 10**9 >= 2**32:
        fail('%s: time %s + base %d ns is outside ROS 1 time' % (where, text, base_ns))
    return ns


def ros_time(ns):
    return genpy.Time(ns // 10**9, ns % 10**9)


def data_lines(path):
    """(line number, fields) of the non-blank, non-comment lines."""
    with open(path) as f:
        for number, line in enumerate(f, 1):
            text = line.strip()
            if text and not text.startswith('#'):
                yield number, text


def read_camera(path):
    text = open(path).read()

    def integer(key):
        m = re.search(r'^%s:\s*([0-9.]+)\s*$' % key, text, re.M)
        if not m:
            fail('%s: no %s' % (path, key))
        return int(float(m.group(1)))

    def matrix(key):
        m = re.search(r'^%s:.*?data:\s*\[([^\]]*)\]' % key, text, re.M | re.S)
        if not m:
            fail('%s: no %s data list' % (path, key))
        return [float(v) for v in m.group(1).replace(',', ' ').split()]

    k = matrix('camera_matrix')
    d = matrix('distortion_coefficients')
    if len(k) != 9 or len(d) not in (4, 5):
        fail('%s: camera_matrix needs 9 numbers and distortion_coefficients 4 or 5' % path)
    return integer('image_width'), integer('image_height'), k, (d + [0.0])[:5]


def decode_grey_png(path):
    """(width, height, rows as bytes) of an 8-bit grey, non-interlaced PNG."""
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        fail('%s: not a PNG file' % path)
    pos, idat, width = 8, b'', None
    while pos + 8 <= len(data):
        length, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b'IHDR':
            width, height, depth, colour, _, _, interlace = struct.unpack('>IIBBBBB', body)
            if depth != 8 or colour != 0 or interlace != 0:
                fail('%s: not an 8-bit grey non-interlaced PNG (depth %d, colour type %d)' % (path, depth, colour))
        elif kind == b'IDAT':
            idat += body
        pos += 12 + length
    if width is None:
        fail('%s: no IHDR chunk' % path)
    raw = zlib.decompress(idat)
    rows, prev = [], bytearray(width)
    for y in range(height):
        line = raw[y * (width + 1):(y + 1) * (width + 1)]
        kind, row = line[0], bytearray(line[1:])
        for x in range(width):  # PNG filters, bpp 1
            a = row[x - 1] if x else 0
            b, c = prev[x], (prev[x - 1] if x else 0)
            if kind == 1:
                row[x] = (row[x] + a) & 255
            elif kind == 2:
                row[x] = (row[x] + b) & 255
            elif kind == 3:
                row[x] = (row[x] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                row[x] = (row[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(row))
        prev = row
    return width, height, rows


def image_message(path, encoding, header, size):
    if encoding == 'png':
        return CompressedImage(header=header, format='png', data=open(path, 'rb').read())
    width, height, rows = decode_grey_png(path)
    if (width, height) != size:
        fail('%s: %dx%d, camera.yaml says %dx%d' % (path, width, height, size[0], size[1]))
    channels = 1 if encoding == 'mono8' else 3
    data = b''.join(bytes(v for v in row for _ in range(channels)) for row in rows)
    return Image(header=header, height=height, width=width, encoding=encoding, is_bigendian=0,
                 step=width * channels, data=data)


def odometry_messages(path, frame_id, base_ns):
    out = []
    for number, text in data_lines(path):
        fields = text.split()
        if len(fields) != 8:
            fail('%s:%d: not `t x y z qx qy qz qw`' % (path, number))
        ns = stamp_ns(fields[0], base_ns, '%s:%d' % (path, number))
        x, y, z, qx, qy, qz, qw = (float(v) for v in fields[1:])
        pose = Pose(position=Point(x, y, z), orientation=Quaternion(qx, qy, qz, qw))
        msg = Odometry(header=Header(seq=len(out), stamp=ros_time(ns), frame_id=frame_id), child_frame_id='base_link',
                       pose=PoseWithCovariance(pose=pose),
                       twist=TwistWithCovariance(twist=Twist(linear=Vector3(), angular=Vector3())))
        out.append((ns, msg))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('dataset')
    parser.add_argument('out')
    parser.add_argument('--compression', choices=('none', 'bz2', 'lz4'), default='none')
    parser.add_argument('--base-time-ns', type=int, default=1700000000000000000)
    parser.add_argument('--encoding', choices=('mono8', 'bgr8', 'rgb8', 'png'), default='mono8')
    args = parser.parse_args()
    width, height, k, d = read_camera(os.path.join(args.dataset, 'camera.yaml'))
    frames_path = os.path.join(args.dataset, 'frames.txt')
    image_topic = '/camera/image_raw/compressed' if args.encoding == 'png' else '/camera/image_raw'
    # (receive ns, order, topic, message): order keeps image, camera info, odometry, truth at equal times.
    out = []
    for seq, (number, text) in enumerate(data_lines(frames_path)):
        fields = text.split(None, 1)
        if len(fields) != 2:
            fail('%s:%d: not `t path`' % (frames_path, number))
        ns = stamp_ns(fields[0], args.base_time_ns, '%s:%d' % (frames_path, number))
        header = Header(seq=seq, stamp=ros_time(ns), frame_id='camera')
        image = image_message(os.path.join(args.dataset, fields[1].strip()), args.encoding, header, (width, height))
        info = CameraInfo(header=header, height=height, width=width, distortion_model='plumb_bob', D=d, K=k,
                          R=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                          P=[k[0], 0.0, k[2], 0.0, 0.0, k[4], k[5], 0.0, 0.0, 0.0, 1.0, 0.0])
        out.append((ns + RECEIVE_DELAY_NS, 0, image_topic, image))
        out.append((ns + RECEIVE_DELAY_NS, 1, '/camera/camera_info', info))
    for order, (name, topic, frame_id) in enumerate((('odometry.txt', '/odom', 'odom'),
                                                     ('groundtruth.txt', '/ground_truth', 'world')), 2):
        path = os.path.join(args.dataset, name)
        if os.path.exists(path):
            out += [(ns + RECEIVE_DELAY_NS, order, topic, msg) for ns, msg in odometry_messages(path, frame_id,
                                                                                              args.base_time_ns)]
    out.sort(key=lambda m: (m[0], m[1]))
    with rosbag.Bag(args.out, 'w', compression=args.compression) as bag:
        for receive_ns, _, topic, msg in out:
            bag.write(topic, msg, ros_time(receive_ns))
    print('dataset_to_rosbag: %s: %d messages' % (args.out, len(out)))


if __name__ == '__main__':
    main()
