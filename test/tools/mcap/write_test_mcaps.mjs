#!/usr/bin/env node
// Writes the MCAP files that test planarvo's MCAP reader (test/unit/io_bag_mcap_test.cpp) with the
// official writer, @mcap/core's McapWriter, and CDR from @foxglove/cdr. Usage:
//   node write_test_mcaps.mjs OUT_DIR [--frames N]
// (N frames of messages, default 8; fuzz/seeds/mcap/ holds files of --frames 1.)
// For each NAME.mcap it writes NAME.json (every message's expected values; integers of 64 bits
// as decimal strings) and NAME.expected.txt (the same, one tab-separated line per record, for
// C++ to parse). Each file is read back with @mcap/core's stream reader as a check of the writer.
import { mkdir, writeFile } from "node:fs/promises";
import { join } from "node:path";

import { McapStreamReader } from "@mcap/core";
import { parse as parseMsg } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import lz4 from "@foxglove/wasm-lz4";
import zstd from "@foxglove/wasm-zstd";
import { PNG } from "pngjs";

import {
  McapWriter, MemoryWritable, NS, SCHEMAS, addChannel, compressor, encodeCameraInfo, encodeCompressedImage, encodeImage,
  encodeOdometry, encodeString, fnv1a,
} from "./ros2.mjs";

const BASE_NS = 1700000000123456789n;  // log times near 1.7e18 ns: a double would lose the last digits
let FRAMES = 8;

// A small deterministic generator, so that every file holds the same values.
function lcg(seed) {
  let s = seed >>> 0;
  return () => ((s = (Math.imul(s, 1664525) + 1013904223) >>> 0) / 2 ** 32);
}

function imageData(width, height, step, channels, seed) {
  const rnd = lcg(seed);
  const data = new Uint8Array(step * height);
  for (let i = 0; i < data.length; ++i) data[i] = Math.floor(rnd() * 256);
  // The row padding past width * channels is part of the data too.
  return data;
}

function png(width, height, seed) {
  const p = new PNG({ width, height });
  const rnd = lcg(seed);
  for (let i = 0; i < width * height; ++i) {
    const g = Math.floor(rnd() * 256);
    p.data.set([g, g, g, 255], i * 4);
  }
  return new Uint8Array(PNG.sync.write(p, { colorType: 0 }));
}

// The messages of every test file, in the order written: frame i has a mono8 and a bgr8 image, a
// PNG CompressedImage and a CameraInfo, all with one stamp and one log time (ties); two
// odometry messages on two channels of /odom whose log times are earlier than the images'
// written before them (out of order in the file); a std_msgs/msg/String; a JSON message on a
// topic of a type planarvo does not know.
function messages() {
  const out = [];
  for (let i = 0; i < FRAMES; ++i) {
    const stamp = BASE_NS + BigInt(i) * 100000000n + 17n;
    const log = stamp + 5000000n;
    out.push({ topic: "/camera/image_raw", logTime: log, kind: "Image", msg: {
      stampNs: stamp, frameId: "camera", height: 6, width: 20, encoding: "mono8", isBigendian: false, step: 24,
      data: imageData(20, 6, 24, 1, 100 + i) } });
    out.push({ topic: "/camera/image_color", logTime: log, kind: "Image", msg: {
      stampNs: stamp, frameId: "camera", height: 4, width: 10, encoding: "bgr8", isBigendian: false, step: 32,
      data: imageData(10, 4, 32, 3, 200 + i) } });
    out.push({ topic: "/camera/image_raw/compressed", logTime: log, kind: "CompressedImage", msg: {
      stampNs: stamp, frameId: "camera", format: "png", data: png(12, 8, 300 + i) } });
    out.push({ topic: "/camera/camera_info", logTime: log, kind: "CameraInfo", msg: {
      stampNs: stamp, frameId: "camera", height: 6, width: 20, distortionModel: "plumb_bob",
      d: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-5, -0.001 * i],
      k: [458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1],
      r: [1, 0, 0, 0, 1, 0, 0, 0, 1],
      p: [458.654, 0, 367.215, 0, 0, 457.296, 248.375, 0, 0, 0, 1, 0],
      binningX: 1, binningY: 2, roi: { xOffset: 3, yOffset: 4, height: 5, width: 6, doRectify: i % 2 === 1 } } });
    for (let k = 0; k < 2; ++k) {
      const ostamp = stamp - 30000000n + BigInt(k) * 50000000n;
      const rnd = lcg(400 + 2 * i + k);
      out.push({ topic: "/odom", channel: k, logTime: ostamp + 1000n, kind: "Odometry", msg: {
        stampNs: ostamp, frameId: "odom", childFrameId: "base_link",
        position: [0.1 * i + 0.01 * k, -0.25 * i, 0], orientation: [0, 0, Math.sin(0.05 * i), Math.cos(0.05 * i)],
        poseCovariance: Array.from({ length: 36 }, (_, j) => j + 0.5 + rnd()),
        linear: [1.5, 0, 0], angular: [0, 0, 0.25 + k],
        twistCovariance: Array.from({ length: 36 }, (_, j) => -(j + 1) * 1e-3 - rnd()) } });
    }
    out.push({ topic: "/chatter", logTime: log, kind: "Other", text: `frame ${i}` });
    out.push({ topic: "/diagnostics", logTime: log + 1n, kind: "Other", json: JSON.stringify({ frame: i, ok: true }) });
  }
  return out;
}

function serialise(m, bigEndian) {
  switch (m.kind) {
    case "Image": return encodeImage(m.msg, bigEndian);
    case "CompressedImage": return encodeCompressedImage(m.msg, bigEndian);
    case "CameraInfo": return encodeCameraInfo(m.msg, bigEndian);
    case "Odometry": return encodeOdometry(m.msg, bigEndian);
    default: return m.json !== undefined ? new TextEncoder().encode(m.json) : encodeString(m.text, bigEndian);
  }
}

// The message as @foxglove/rosmsg2-serialization should decode it from the bytes, by the .msg
// definition in the schema: a check, independent of the encoders, that the bytes are what the
// definition says.
function rosShape(m) {
  const x = m.msg;
  const xyz = ([a, b, c]) => ({ x: a, y: b, z: c });
  if (m.kind === "Other") return { data: m.text };
  const header = { stamp: { sec: Number(x.stampNs / NS), nanosec: Number(x.stampNs % NS) }, frame_id: x.frameId };
  if (m.kind === "Image") return { header, height: x.height, width: x.width, encoding: x.encoding,
    is_bigendian: x.isBigendian ? 1 : 0, step: x.step, data: x.data };
  if (m.kind === "CompressedImage") return { header, format: x.format, data: x.data };
  if (m.kind === "CameraInfo") return { header, height: x.height, width: x.width, distortion_model: x.distortionModel,
    d: x.d, k: x.k, r: x.r, p: x.p, binning_x: x.binningX, binning_y: x.binningY, roi: { x_offset: x.roi.xOffset,
      y_offset: x.roi.yOffset, height: x.roi.height, width: x.roi.width, do_rectify: x.roi.doRectify } };
  const [qx, qy, qz, qw] = x.orientation;
  return { header, child_frame_id: x.childFrameId,
    pose: { pose: { position: xyz(x.position), orientation: { x: qx, y: qy, z: qz, w: qw } }, covariance: x.poseCovariance },
    twist: { twist: { linear: xyz(x.linear), angular: xyz(x.angular) }, covariance: x.twistCovariance } };
}

const plain = (v) => JSON.stringify(v, (_, y) => (ArrayBuffer.isView(y) ? Array.from(y) : y));
const readers = new Map();

function checkAgainstDefinition(type, m, data) {
  if (!readers.has(type)) readers.set(type, new MessageReader(parseMsg(SCHEMAS[type], { ros2: true })));
  const got = plain(readers.get(type).readMessage(data));
  if (got !== plain(rosShape(m))) throw new Error(`${m.topic}: the CDR bytes decode to ${got}`);
}

const TYPES = {
  "/camera/image_raw": "sensor_msgs/msg/Image",
  "/camera/image_color": "sensor_msgs/msg/Image",
  "/camera/image_raw/compressed": "sensor_msgs/msg/CompressedImage",
  "/camera/camera_info": "sensor_msgs/msg/CameraInfo",
  "/odom": "nav_msgs/msg/Odometry",
  "/chatter": "std_msgs/msg/String",
  "/diagnostics": "example_msgs/msg/Status",
};

// Writes the messages; `variant` adds topics that cannot be indexed (a topic of two types, an
// Odometry encoded as JSON). Returns the file's bytes and the records written.
async function writeTestFile(options, { bigEndian = false, conflict = false } = {}) {
  const writable = new MemoryWritable();
  const w = new McapWriter({ writable, chunkSize: 2048, ...options });
  await w.start({ profile: "ros2", library: "planarvo write_test_mcaps.mjs" });
  const schemaIds = new Map();
  const channels = new Map();
  for (const [topic, type] of Object.entries(TYPES)) {
    if (topic === "/diagnostics") {
      channels.set(topic, await addChannel(w, schemaIds, topic, type, {
        messageEncoding: "json", schemaEncoding: "jsonschema", schemaText: '{"type":"object"}' }));
    } else {
      channels.set(topic, await addChannel(w, schemaIds, topic, type));
    }
  }
  channels.set("/odom#1", await addChannel(w, schemaIds, "/odom", TYPES["/odom"]));  // a second channel, one topic
  const written = [];
  for (const m of messages()) {
    const data = serialise(m, bigEndian);
    if (m.json === undefined) checkAgainstDefinition(TYPES[m.topic], m, data);
    const channelId = channels.get(m.channel === 1 ? "/odom#1" : m.topic);
    await w.addMessage({ channelId, sequence: written.length, logTime: m.logTime, publishTime: m.logTime, data });
    written.push({ ...m, data });
  }
  const extra = [];
  if (conflict) {
    const a = await addChannel(w, schemaIds, "/camera/image_raw", "sensor_msgs/msg/CompressedImage");
    const b = await addChannel(w, schemaIds, "/odom_json", "nav_msgs/msg/Odometry", { messageEncoding: "json" });
    const t = BASE_NS + 10n * NS;
    const ci = { topic: "/camera/image_raw", logTime: t, kind: "CompressedImage",
      msg: { stampNs: t, frameId: "camera", format: "jpeg", data: new Uint8Array([255, 216, 255, 217]) } };
    await w.addMessage({ channelId: a, sequence: 0, logTime: t, publishTime: t, data: serialise(ci, false) });
    await w.addMessage({ channelId: b, sequence: 0, logTime: t, publishTime: t, data: new TextEncoder().encode("{}") });
    extra.push({ name: "/camera/image_raw", type: "sensor_msgs/msg/Image", problem: "sensor_msgs/msg/CompressedImage" },
      { name: "/odom_json", type: "nav_msgs/msg/Odometry", problem: "json" });
  }
  await w.end();
  return { bytes: writable.bytes(), written, extra };
}

// The file offsets of the top-level records (spec "Records": opcode, uint64 length, content).
function records(bytes) {
  const out = [];
  for (let pos = 8; pos + 9 <= bytes.length;) {
    const opcode = bytes[pos];
    const length = Number(bytes.readBigUInt64LE(pos + 1));
    out.push({ opcode, pos, end: pos + 9 + length });
    if (opcode === 0x02) break;
    pos += 9 + length;
  }
  return out;
}

async function readBack(bytes) {
  await lz4.isLoaded;
  await zstd.isLoaded;
  const reader = new McapStreamReader({ validateCrcs: true, decompressHandlers: {
    lz4: (buffer, size) => lz4(buffer, Number(size)), zstd: (buffer, size) => zstd.decompress(buffer, Number(size)) } });
  reader.append(bytes);
  let n = 0;
  for (let r; (r = reader.nextRecord());) if (r.type === "Message") ++n;
  return n;
}

const fmt = (v) => (Array.isArray(v) ? v.map((x) => String(x)).join(",") : String(v));

// One message's expected values, for JSON and for the line file.
function expected(m) {
  const e = { topic: m.topic, log_time: m.logTime.toString(), kind: m.kind, raw_size: m.data.length,
    raw_fnv: fnv1a(m.data) };
  if (m.kind === "Other") return e;
  const msg = m.msg;
  Object.assign(e, { stamp_ns: msg.stampNs.toString(), frame_id: msg.frameId });
  if (m.kind === "Image") Object.assign(e, { height: msg.height, width: msg.width, encoding: msg.encoding,
    is_bigendian: msg.isBigendian ? 1 : 0, step: msg.step });
  if (m.kind === "CompressedImage") e.format = msg.format;
  if (m.kind === "Image" || m.kind === "CompressedImage") Object.assign(e, { data_size: msg.data.length,
    data_fnv: fnv1a(msg.data), data_first: msg.data[0], data_last: msg.data[msg.data.length - 1] });
  if (m.kind === "CameraInfo") Object.assign(e, { height: msg.height, width: msg.width,
    distortion_model: msg.distortionModel, d: msg.d, k: msg.k, r: msg.r, p: msg.p, binning_x: msg.binningX,
    binning_y: msg.binningY, roi: [msg.roi.xOffset, msg.roi.yOffset, msg.roi.height, msg.roi.width,
      msg.roi.doRectify ? 1 : 0] });
  if (m.kind === "Odometry") Object.assign(e, { child_frame_id: msg.childFrameId, position: msg.position,
    orientation: msg.orientation, pose_covariance: msg.poseCovariance, linear: msg.linear, angular: msg.angular,
    twist_covariance: msg.twistCovariance });
  return e;
}

function line(tag, fields) {
  return [tag, ...Object.entries(fields).map(([k, v]) => `${k}=${fmt(v)}`)].join("\t");
}

async function emit(dir, name, bytes, info) {
  await writeFile(join(dir, name + ".mcap"), bytes);
  const msgs = info.error ? [] : info.written.map(expected);
  const topics = new Map();
  for (const m of info.written) {
    const t = topics.get(m.topic) ?? { name: m.topic, type: TYPES[m.topic], count: 0, problem: "" };
    t.count += 1;
    topics.set(m.topic, t);
  }
  for (const x of info.extra ?? []) topics.set(x.name, { ...topics.get(x.name), name: x.name, type: x.type,
    count: (topics.get(x.name)?.count ?? 0) + 1, problem: x.problem });
  const file = { name: name + ".mcap", summary: info.summary ? 1 : 0, error: info.error ?? "none",
    same_as: info.sameAs ?? "" };
  await writeFile(join(dir, name + ".json"), JSON.stringify({ ...file, topics: [...topics.values()],
    messages: msgs }, null, 1) + "\n");
  const lines = ["# expected content of " + name + ".mcap, written by write_test_mcaps.mjs: tab-separated key=value",
    line("file", file), ...[...topics.values()].map((t) => line("topic", { ...t, problem: t.problem || "-" })),
    ...msgs.map((m) => line("message", m))];
  await writeFile(join(dir, name + ".expected.txt"), lines.join("\n") + "\n");
}

async function main() {
  const [dir, flag, frames] = process.argv.slice(2);
  if (flag === "--frames" && Number(frames) >= 1) FRAMES = Number(frames);
  if (!dir || (flag !== undefined && FRAMES !== Number(frames))) {
    console.error("usage: node write_test_mcaps.mjs OUT_DIR [--frames N]");
    process.exit(2);
  }
  await mkdir(dir, { recursive: true });
  const noSummary = { useStatistics: false, useSummaryOffsets: false, repeatSchemas: false, repeatChannels: false,
    useChunkIndex: false, useAttachmentIndex: false, useMetadataIndex: false };
  const files = [];
  const add = async (name, options, flags, extra = {}) => {
    const r = await writeTestFile(options, flags);
    files.push({ name, r, ...extra });
  };
  await add("chunked_none", {}, {}, { summary: true });
  await add("chunked_zstd", { compressChunk: await compressor("zstd") }, {}, { summary: true });
  await add("chunked_lz4", { compressChunk: await compressor("lz4") }, {}, { summary: true });
  await add("unchunked", { useChunks: false }, {}, { summary: true });
  await add("no_message_index", { useMessageIndex: false }, {}, { summary: true });
  await add("chunked_zstd_nosummary", { compressChunk: await compressor("zstd"), ...noSummary }, {},
    { summary: false, sameAs: "chunked_zstd" });
  await add("cdr_be", { compressChunk: await compressor("lz4") }, { bigEndian: true }, { summary: true });
  await add("type_conflict", {}, { conflict: true }, { summary: true });
  for (const f of files) {
    const n = await readBack(f.r.bytes);
    if (n !== f.r.written.length + (f.r.extra.length ? 2 : 0)) throw new Error(`${f.name}: read back ${n} messages`);
    await emit(dir, f.name, f.r.bytes, { written: f.r.written, extra: f.r.extra, summary: f.summary, sameAs: f.sameAs });
  }
  // Cut before the Data End record: the recording stopped between two records (no summary, no
  // footer); every message is still there.
  for (const base of ["chunked_none", "unchunked"]) {
    const f = files.find((x) => x.name === base);
    const dataEnd = records(f.r.bytes).find((r) => r.opcode === 0x0f);
    await emit(dir, base + "_cut", f.r.bytes.subarray(0, dataEnd.pos),
      { written: f.r.written, summary: false, sameAs: base });
  }
  // Cut inside a record: InvalidInput naming the byte.
  const zstdFile = files.find((x) => x.name === "chunked_zstd");
  const chunks = records(zstdFile.r.bytes).filter((r) => r.opcode === 0x06);
  await emit(dir, "truncated_mid_chunk", zstdFile.r.bytes.subarray(0, (chunks[1].pos + chunks[1].end) >> 1),
    { written: zstdFile.r.written, summary: false, error: "truncated" });
  const flat = files.find((x) => x.name === "unchunked");
  const lastMessage = records(flat.r.bytes).filter((r) => r.opcode === 0x05).at(-1);
  await emit(dir, "truncated_mid_message", flat.r.bytes.subarray(0, lastMessage.end - 3),
    { written: flat.r.written, summary: false, error: "truncated" });
  console.log(`write_test_mcaps: ${files.length + 4} files in ${dir}`);
}

await main();
