// ROS 2 messages for MCAP files written with the official writer (@mcap/core) and serialised with
// @foxglove/cdr: the schemas as rosbag2 stores them (encoding "ros2msg", the .msg text with its
// dependencies), CDR encoders for the four message types planarvo reads, and small helpers
// shared by write_test_mcaps.mjs and dataset_to_mcap.mjs.
import { open, writeFile } from "node:fs/promises";

import { CdrWriter, EncapsulationKind } from "@foxglove/cdr";
import lz4js from "lz4js";
import { McapWriter } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";

const SEP = "================================================================================\n";
const TIME = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
const HEADER = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n";

// ROS 2 Humble/Jazzy definitions (comments dropped), as `ros2 bag record` stores them.
export const SCHEMAS = {
  "sensor_msgs/msg/Image":
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\n" +
    "uint8[] data\n" + SEP + HEADER + SEP + TIME,
  "sensor_msgs/msg/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data\n" + SEP + HEADER + SEP + TIME,
  "sensor_msgs/msg/CameraInfo":
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\nfloat64[] d\nfloat64[9] k\n" +
    "float64[9] r\nfloat64[12] p\nuint32 binning_x\nuint32 binning_y\nRegionOfInterest roi\n" + SEP + HEADER + SEP +
    TIME + SEP + "MSG: sensor_msgs/RegionOfInterest\nuint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\n" +
    "bool do_rectify\n",
  "nav_msgs/msg/Odometry":
    "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n" +
    "geometry_msgs/TwistWithCovariance twist\n" + SEP + HEADER + SEP + TIME + SEP +
    "MSG: geometry_msgs/PoseWithCovariance\nPose pose\nfloat64[36] covariance\n" + SEP +
    "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation\n" + SEP +
    "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n" + SEP +
    "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n" + SEP +
    "MSG: geometry_msgs/TwistWithCovariance\nTwist twist\nfloat64[36] covariance\n" + SEP +
    "MSG: geometry_msgs/Twist\nVector3 linear\nVector3 angular\n" + SEP +
    "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n",
  "std_msgs/msg/String": "string data\n",
};

export const NS = 1000000000n;

function writer(bigEndian) {
  return new CdrWriter({ kind: bigEndian ? EncapsulationKind.CDR_BE : EncapsulationKind.CDR_LE });
}

// std_msgs/msg/Header from an integer nanosecond stamp (BigInt).
function header(w, stampNs, frameId) {
  w.int32(Number(stampNs / NS));
  w.uint32(Number(stampNs % NS));
  w.string(frameId);
}

export function encodeImage(m, bigEndian = false) {
  const w = writer(bigEndian);
  header(w, m.stampNs, m.frameId);
  w.uint32(m.height).uint32(m.width).string(m.encoding).uint8(m.isBigendian ? 1 : 0).uint32(m.step);
  w.uint8Array(m.data, true);
  return w.data;
}

export function encodeCompressedImage(m, bigEndian = false) {
  const w = writer(bigEndian);
  header(w, m.stampNs, m.frameId);
  w.string(m.format).uint8Array(m.data, true);
  return w.data;
}

export function encodeCameraInfo(m, bigEndian = false) {
  const w = writer(bigEndian);
  header(w, m.stampNs, m.frameId);
  w.uint32(m.height).uint32(m.width).string(m.distortionModel).float64Array(m.d, true);
  w.float64Array(m.k, false).float64Array(m.r, false).float64Array(m.p, false);
  w.uint32(m.binningX).uint32(m.binningY);
  const r = m.roi;
  w.uint32(r.xOffset).uint32(r.yOffset).uint32(r.height).uint32(r.width).uint8(r.doRectify ? 1 : 0);
  return w.data;
}

export function encodeOdometry(m, bigEndian = false) {
  const w = writer(bigEndian);
  header(w, m.stampNs, m.frameId);
  w.string(m.childFrameId);
  for (const v of [...m.position, ...m.orientation]) w.float64(v);
  w.float64Array(m.poseCovariance, false);
  for (const v of [...m.linear, ...m.angular]) w.float64(v);
  w.float64Array(m.twistCovariance, false);
  return w.data;
}

export function encodeString(text, bigEndian = false) {
  return writer(bigEndian).string(text).data;
}

// Chunk compressors for McapWriter's compressChunk: zstd (@foxglove/wasm-zstd) and the LZ4 frame
// format (lz4js), the two the MCAP registry names.
export async function compressor(name) {
  if (name === "none") return undefined;
  if (name === "zstd") {
    await zstd.isLoaded;
    return (data) => ({ compression: "zstd", compressedData: new Uint8Array(zstd.compress(data, 3)) });
  }
  if (name === "lz4") return (data) => ({ compression: "lz4", compressedData: new Uint8Array(lz4js.compress(data)) });
  throw new Error(`unknown compression ${name} (none, zstd, lz4)`);
}

// An IWritable that keeps the file in memory.
export class MemoryWritable {
  constructor() {
    this.parts = [];
    this.size = 0n;
  }
  position() {
    return this.size;
  }
  async write(buffer) {
    this.parts.push(Buffer.from(buffer));
    this.size += BigInt(buffer.byteLength);
  }
  bytes() {
    return Buffer.concat(this.parts);
  }
}

// An IWritable that writes to a file as it goes.
export class FileWritable {
  static async open(path) {
    const w = new FileWritable();
    w.handle = await open(path, "w");
    w.size = 0n;
    return w;
  }
  position() {
    return this.size;
  }
  async write(buffer) {
    let done = 0;
    while (done < buffer.byteLength) done += (await this.handle.write(buffer, done, buffer.byteLength - done)).bytesWritten;
    this.size += BigInt(buffer.byteLength);
  }
  async close() {
    await this.handle.close();
  }
}

// Registers a schema (once per name) and a channel; returns the channel id.
export async function addChannel(w, schemaIds, topic, type, { messageEncoding = "cdr", schemaEncoding = "ros2msg",
  schemaText = SCHEMAS[type] } = {}) {
  if (!schemaIds.has(type)) {
    const id = await w.registerSchema({ name: type, encoding: schemaEncoding, data: new TextEncoder().encode(schemaText) });
    schemaIds.set(type, id);
  }
  return w.registerChannel({ topic, schemaId: schemaIds.get(type), messageEncoding, metadata: new Map() });
}

export async function writeMcap(path, writable) {
  await writeFile(path, writable.bytes());
}

export { McapWriter };

// FNV-1a, 32 bits: a checksum of message bytes that C++ recomputes in a line.
export function fnv1a(bytes) {
  let h = 0x811c9dc5;
  for (const b of bytes) h = Math.imul(h ^ b, 0x01000193) >>> 0;
  return h >>> 0;
}
