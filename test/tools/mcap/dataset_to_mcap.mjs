#!/usr/bin/env node
// Converts a planarvo data set folder into an MCAP file as `ros2 bag record` would have written
// it (ROS 2 CDR, schemas as "ros2msg" text), with the official writer. Usage:
//   node dataset_to_mcap.mjs DATASET_DIR OUT.mcap [--compression none|zstd|lz4] [--no-chunks]
//        [--base-time-ns N] [--encoding mono8|bgr8|rgb8|png|jpeg]
// Reads camera.yaml (OpenCV YAML: image_width, image_height, camera_matrix, distortion_coefficients),
// frames.txt (`t path`, '#' comments), the images, and odometry.txt and groundtruth.txt (TUM:
// `t x y z qx qy qz qw`) when present. Writes
//   /camera/image_raw             sensor_msgs/msg/Image (mono8; bgr8/rgb8 repeat the grey value;
//                                 decoded from PNG), or with --encoding png|jpeg
//   /camera/image_raw/compressed  sensor_msgs/msg/CompressedImage (the image file's bytes)
//   /camera/camera_info           sensor_msgs/msg/CameraInfo, one per frame with its stamp
//   /odom                         nav_msgs/msg/Odometry from odometry.txt ("odom" -> "base_link")
//   /ground_truth                 nav_msgs/msg/Odometry from groundtruth.txt ("map" -> "base_link")
// Header stamp = base_time_ns + round(t * 1e9), computed exactly from t's decimal text; the log
// time (the recorder's receive time) is the stamp + 5 ms. Messages are written in log time order,
// each image read when it is written and the file written as it grows (a long data set is never
// held in memory).
import { readFile, rm } from "node:fs/promises";
import { extname, join } from "node:path";

import { PNG } from "pngjs";

import {
  FileWritable, McapWriter, addChannel, compressor, encodeCameraInfo, encodeCompressedImage, encodeImage,
  encodeOdometry,
} from "./ros2.mjs";

const RECEIVE_DELAY_NS = 5000000n;

function usage(message) {
  if (message) console.error(`dataset_to_mcap: ${message}`);
  console.error("usage: node dataset_to_mcap.mjs DATASET_DIR OUT.mcap [--compression none|zstd|lz4] [--no-chunks] " +
    "[--base-time-ns N] [--encoding mono8|bgr8|rgb8|png|jpeg]");
  process.exit(2);
}

function parseArgs(argv) {
  const o = { compression: "none", chunks: true, baseTimeNs: 1700000000000000000n, encoding: "mono8", positional: [] };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    const value = () => (i + 1 < argv.length ? argv[++i] : usage(`${a} needs a value`));
    if (a === "--compression") o.compression = value();
    else if (a === "--no-chunks") o.chunks = false;
    else if (a === "--base-time-ns") o.baseTimeNs = /^\d+$/.test(argv[i + 1] ?? "") ? BigInt(value()) : usage("--base-time-ns takes an integer");
    else if (a === "--encoding") o.encoding = value();
    else if (a.startsWith("--")) usage(`unknown option ${a}`);
    else o.positional.push(a);
  }
  if (o.positional.length !== 2) usage();
  if (!["none", "zstd", "lz4"].includes(o.compression)) usage(`--compression ${o.compression}`);
  if (!["mono8", "bgr8", "rgb8", "png", "jpeg"].includes(o.encoding)) usage(`--encoding ${o.encoding}`);
  return o;
}

// A decimal number of seconds ("12.3456789012", "-1.5", "1e-3") as integer nanoseconds, exactly,
// rounded half away from zero.
function secondsToNs(text, where) {
  const m = /^([+-]?)(\d*)(?:\.(\d*))?(?:[eE]([+-]?\d+))?$/.exec(text);
  if (!m || (m[2] === "" && (m[3] ?? "") === "")) throw new Error(`${where}: "${text}" is not a number of seconds`);
  const [, sign, whole, fraction = "", exponent = "0"] = m;
  const digits = BigInt((whole + fraction) || "0");
  const shift = 9 + Number(exponent) - fraction.length;  // ns = digits * 10^shift
  let ns;
  if (shift >= 0) ns = digits * 10n ** BigInt(shift);
  else {
    const div = 10n ** BigInt(-shift);
    ns = (digits + div / 2n) / div;
  }
  return sign === "-" ? -ns : ns;
}

// Data lines of a text file: [line number, fields], '#' comments and blank lines skipped.
async function dataLines(path) {
  const text = await readFile(path, "utf8");
  return text.split(/\r?\n/).map((l, i) => [i + 1, l.trim()]).filter(([, l]) => l && !l.startsWith("#"))
    .map(([n, l]) => [n, l.split(/\s+/)]);
}

// The few keys of an OpenCV FileStorage camera.yaml that a CameraInfo needs.
async function readCamera(dir) {
  const path = join(dir, "camera.yaml");
  const text = await readFile(path, "utf8");
  const integer = (key) => {
    const m = new RegExp(`^${key}:\\s*(\\d+)`, "m").exec(text);
    if (!m) throw new Error(`${path}: no ${key}`);
    return Number(m[1]);
  };
  const matrix = (key) => {
    const m = new RegExp(`^${key}:[\\s\\S]*?data:\\s*\\[([^\\]]*)\\]`, "m").exec(text);
    if (!m) throw new Error(`${path}: no ${key} data`);
    return m[1].split(",").map((s) => Number(s.trim()));
  };
  const k = matrix("camera_matrix");
  if (k.length !== 9 || k.some((v) => !Number.isFinite(v))) throw new Error(`${path}: camera_matrix is not 3x3`);
  let d = matrix("distortion_coefficients");
  if (d.some((v) => !Number.isFinite(v))) throw new Error(`${path}: distortion_coefficients are not numbers`);
  if (d.length === 4) d = [...d, 0];
  const model = d.length === 5 ? "plumb_bob" : d.length === 8 ? "rational_polynomial" : null;
  if (!model) throw new Error(`${path}: ${d.length} distortion coefficients (4, 5 or 8)`);
  return { width: integer("image_width"), height: integer("image_height"), k, d, model };
}

// A TUM file's poses as Odometry messages (zero covariance and twist).
async function readTum(path, base, frameId) {
  const out = [];
  for (const [n, f] of await dataLines(path)) {
    if (f.length !== 8) throw new Error(`${path}:${n}: ${f.length} fields, not 8 (t x y z qx qy qz qw)`);
    const v = f.slice(1).map(Number);
    const stampNs = base + secondsToNs(f[0], `${path}:${n}`);
    out.push({ stampNs, msg: { stampNs, frameId, childFrameId: "base_link", position: v.slice(0, 3),
      orientation: v.slice(3, 7), poseCovariance: new Array(36).fill(0), linear: [0, 0, 0], angular: [0, 0, 0],
      twistCovariance: new Array(36).fill(0) } });
  }
  return out;
}

async function exists(path) {
  try {
    await readFile(path);
    return true;
  } catch {
    return false;
  }
}

// One frame's image message in the asked encoding.
function imageMessage(bytes, file, stampNs, encoding) {
  const ext = extname(file).toLowerCase();
  if (encoding === "png" || encoding === "jpeg") {
    const isJpeg = ext === ".jpg" || ext === ".jpeg";
    if ((encoding === "png") !== (ext === ".png") || (encoding === "jpeg" && !isJpeg))
      throw new Error(`${file}: --encoding ${encoding} passes the image files' bytes on, and this is not a ${encoding} file`);
    return encodeCompressedImage({ stampNs, frameId: "camera", format: encoding, data: bytes });
  }
  if (ext !== ".png") throw new Error(`${file}: only PNG images can be decoded for --encoding ${encoding}`);
  const png = PNG.sync.read(Buffer.from(bytes));
  const channels = encoding === "mono8" ? 1 : 3;
  const data = new Uint8Array(png.width * png.height * channels);
  for (let i = 0; i < png.width * png.height; ++i) {
    const [r, g, b] = png.data.subarray(4 * i, 4 * i + 3);
    const grey = r === g && g === b ? r : Math.round(0.299 * r + 0.587 * g + 0.114 * b);
    data.fill(grey, i * channels, (i + 1) * channels);
  }
  return encodeImage({ stampNs, frameId: "camera", height: png.height, width: png.width, encoding,
    isBigendian: false, step: png.width * channels, data });
}

async function main() {
  const o = parseArgs(process.argv.slice(2));
  const [dir, out] = o.positional;
  const camera = await readCamera(dir);
  const [fx, , cx, , fy, cy] = camera.k;
  const pending = [];  // { topic, logTime, make: () => bytes }, sorted by log time before writing
  for (const [n, f] of await dataLines(join(dir, "frames.txt"))) {
    if (f.length < 2) throw new Error(`${join(dir, "frames.txt")}:${n}: no image path`);
    const stampNs = o.baseTimeNs + secondsToNs(f[0], `${join(dir, "frames.txt")}:${n}`);
    const file = join(dir, f.slice(1).join(" "));
    const topic = o.encoding === "png" || o.encoding === "jpeg" ? "/camera/image_raw/compressed" : "/camera/image_raw";
    pending.push({ topic, logTime: stampNs + RECEIVE_DELAY_NS,
      make: async () => imageMessage(new Uint8Array(await readFile(file)), file, stampNs, o.encoding) });
    pending.push({ topic: "/camera/camera_info", logTime: stampNs + RECEIVE_DELAY_NS, make: () => encodeCameraInfo({
      stampNs, frameId: "camera", height: camera.height, width: camera.width, distortionModel: camera.model,
      d: camera.d, k: camera.k, r: [1, 0, 0, 0, 1, 0, 0, 0, 1], p: [fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0],
      binningX: 0, binningY: 0, roi: { xOffset: 0, yOffset: 0, height: 0, width: 0, doRectify: false } }) });
  }
  for (const [file, topic, frameId] of [["odometry.txt", "/odom", "odom"], ["groundtruth.txt", "/ground_truth", "map"]]) {
    if (!(await exists(join(dir, file)))) continue;
    for (const p of await readTum(join(dir, file), o.baseTimeNs, frameId))
      pending.push({ topic, logTime: p.stampNs + RECEIVE_DELAY_NS, make: () => encodeOdometry(p.msg) });
  }
  pending.sort((a, b) => (a.logTime < b.logTime ? -1 : a.logTime > b.logTime ? 1 : 0));  // stable

  const writable = await FileWritable.open(out);
  try {
    await writeMessages(writable, pending, o);
  } catch (e) {
    await writable.close();
    await rm(out, { force: true });  // no half-written file
    throw e;
  }
  await writable.close();
}

async function writeMessages(writable, pending, o) {
  const w = new McapWriter({ writable, useChunks: o.chunks, compressChunk: await compressor(o.compression) });
  await w.start({ profile: "ros2", library: "planarvo dataset_to_mcap.mjs" });
  const types = { "/camera/image_raw": "sensor_msgs/msg/Image", "/camera/image_raw/compressed":
    "sensor_msgs/msg/CompressedImage", "/camera/camera_info": "sensor_msgs/msg/CameraInfo", "/odom":
    "nav_msgs/msg/Odometry", "/ground_truth": "nav_msgs/msg/Odometry" };
  const schemaIds = new Map();
  const channels = new Map();
  const counts = new Map();
  for (const m of pending) {
    if (!channels.has(m.topic)) channels.set(m.topic, await addChannel(w, schemaIds, m.topic, types[m.topic]));
    counts.set(m.topic, (counts.get(m.topic) ?? 0) + 1);
    await w.addMessage({ channelId: channels.get(m.topic), sequence: counts.get(m.topic) - 1, logTime: m.logTime,
      publishTime: m.logTime, data: await m.make() });
  }
  await w.end();
  console.log(`dataset_to_mcap: ${o.positional[1]}: ` + [...counts].map(([t, n]) => `${t} ${n}`).join(", "));
}

try {
  await main();
} catch (e) {
  console.error(`dataset_to_mcap: ${e.message}`);
  process.exit(1);
}
