// A reference decoder of recording.swrec (FORMAT.md), in plain JavaScript.
// `decompress(Uint8Array) -> Uint8Array` is a zstd decoder (fzstd's
// `decompress`). Check a file from the command line:
//   NODE_PATH=path/to/node_modules node swarm/record/swrec.js DIR/recording.swrec
'use strict';

function xxh32(b) {  // b: Uint8Array; seed 0
  const P1 = 2654435761, P2 = 2246822519, P3 = 3266489917, P4 = 668265263, P5 = 374761393;
  const rd = (i) => (b[i] | (b[i + 1] << 8) | (b[i + 2] << 16) | (b[i + 3] << 24)) >>> 0;
  const rotl = (x, r) => ((x << r) | (x >>> (32 - r))) >>> 0;
  const round = (acc, lane) => Math.imul(rotl((acc + Math.imul(lane, P2)) >>> 0, 13), P1) >>> 0;
  let i = 0, h;
  const n = b.length;
  if (n >= 16) {
    let v1 = (P1 + P2) >>> 0, v2 = P2, v3 = 0, v4 = (0 - P1) >>> 0;
    for (; i + 16 <= n; i += 16) {
      v1 = round(v1, rd(i)); v2 = round(v2, rd(i + 4));
      v3 = round(v3, rd(i + 8)); v4 = round(v4, rd(i + 12));
    }
    h = (rotl(v1, 1) + rotl(v2, 7) + rotl(v3, 12) + rotl(v4, 18)) >>> 0;
  } else h = P5;
  h = (h + n) >>> 0;
  for (; i + 4 <= n; i += 4) h = Math.imul(rotl((h + Math.imul(rd(i), P3)) >>> 0, 17), P4) >>> 0;
  for (; i < n; i++) h = Math.imul(rotl((h + Math.imul(b[i], P5)) >>> 0, 11), P1) >>> 0;
  h = Math.imul(h ^ (h >>> 15), P2) >>> 0;
  h = Math.imul(h ^ (h >>> 13), P3) >>> 0;
  return (h ^ (h >>> 16)) >>> 0;
}

const KIND = {1: 'header', 2: 'scene', 3: 'keyframe', 4: 'delta', 5: 'end'};

// Chunk headers of `bytes` (Uint8Array): {chunks, truncated, error}.
function scanChunks(bytes) {
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const chunks = [];
  let at = 0;
  while (at < bytes.length) {
    if (bytes.length - at < 24) return {chunks, truncated: true};
    if (bytes[at] !== 0x53 || bytes[at + 1] !== 0x57 || bytes[at + 2] !== 0x52 || bytes[at + 3] !== 0x43)
      return {chunks, error: `chunk ${chunks.length + 1} at byte ${at}: bad magic`};
    const c = {offset: at, kind: bytes[at + 4], step: dv.getUint32(at + 8, true),
               stored: dv.getUint32(at + 12, true), raw: dv.getUint32(at + 16, true),
               checksum: dv.getUint32(at + 20, true)};
    if (bytes.length - at - 24 < c.stored) return {chunks, truncated: true};
    c.payload = bytes.subarray(at + 24, at + 24 + c.stored);
    if (xxh32(c.payload) !== c.checksum)
      return {chunks, error: `chunk ${chunks.length + 1} at byte ${at}: checksum mismatch`};
    chunks.push(c);
    at += 24 + c.stored;
  }
  return {chunks, truncated: false};
}

// Applies one step record (keyframe or delta) to `state`
// ({pose: Int32Array(7 n) as x,y,z,qw,qx,qy,qz, color: Uint32Array(n),
//   reading: Uint16Array(n), paint: Map cell -> rgba, names: [], samples: []}).
function decodeStep(raw, keyframe, state) {
  const buf = raw.buffer.slice(raw.byteOffset, raw.byteOffset + raw.byteLength);
  const dv = new DataView(buf);
  let at = 0;
  const u32 = () => { const v = dv.getUint32(at, true); at += 4; return v; };
  const pad = (a) => { at = Math.ceil(at / a) * a; };
  const ids = (n) => { const out = new Uint32Array(n); let last = 0;
    for (let i = 0; i < n; i++) { last = (last + u32()) >>> 0; out[i] = last; } return out; };
  state.time = dv.getFloat64(0, true); at = 8;
  state.record = u32(); u32();
  let n = u32();
  const pid = ids(n);
  for (let f = 0; f < 3; f++) {
    const a = new Int32Array(buf, at, n); at += 4 * n;
    for (let i = 0; i < n; i++) {
      const k = 7 * pid[i] + f;
      state.pose[k] = keyframe ? a[i] : (state.pose[k] + a[i]) | 0;
    }
  }
  for (let f = 3; f < 7; f++) {
    for (let i = 0; i < n; i++) {
      const d = dv.getInt16(at + 2 * i, true), k = 7 * pid[i] + f;
      state.pose[k] = keyframe ? d : ((state.pose[k] + d) << 16) >> 16;
    }
    at += 2 * n;
  }
  pad(4);
  n = u32();
  const cid = ids(n);
  for (let i = 0; i < n; i++) state.color[cid[i]] = u32();
  n = u32();
  const rid = ids(n);
  for (let i = 0; i < n; i++) { state.reading[rid[i]] = dv.getUint16(at, true); at += 2; }
  pad(4);
  n = u32();
  if (keyframe) state.paint = new Map();
  const cells = ids(n);
  for (let i = 0; i < n; i++) state.paint.set(cells[i], u32());
  const first = u32(), count = u32();
  state.names.length = first;
  for (let i = 0; i < count; i++) {
    const len = dv.getUint16(at, true); at += 2;
    state.names.push(new TextDecoder().decode(new Uint8Array(buf, at, len))); at += len;
  }
  pad(4);
  n = u32();
  const name = new Uint32Array(buf, at, n); at += 4 * n;
  const robot = new Int32Array(buf, at, n); at += 4 * n;
  const step = new Uint32Array(buf, at, n); at += 4 * n;
  pad(8);
  const value = new Float64Array(buf, at, n); at += 8 * n;
  state.samples = [];
  for (let i = 0; i < n; i++)
    state.samples.push({name: state.names[name[i]], robot: robot[i], step: step[i], value: value[i]});
  if (at !== raw.length) throw new Error(`step record: ${raw.length - at} bytes left over`);
}

function decodeAll(bytes, decompress) {
  const scan = scanChunks(bytes);
  if (scan.error) throw new Error(scan.error);
  const text = (c) => JSON.parse(new TextDecoder().decode(decompress(c.payload)));
  let header = null, scene = null, state = null, ended = null;
  const steps = [];
  for (const c of scan.chunks) {
    const kind = KIND[c.kind];
    if (kind === 'header') header = text(c);
    else if (kind === 'scene') {
      scene = text(c);
      const n = scene.object_count;
      state = {pose: new Int32Array(7 * n), color: new Uint32Array(n), reading: new Uint16Array(n),
               paint: new Map(), names: header.metrics.slice(), samples: []};
    } else if (kind === 'keyframe' || kind === 'delta') {
      const raw = decompress(c.payload);
      if (raw.length !== c.raw) throw new Error(`chunk at ${c.offset}: raw size`);
      decodeStep(raw, kind === 'keyframe', state);
      steps.push({step: c.step, time: state.time, pose: state.pose.slice(),
                  samples: state.samples, paintCells: state.paint.size});
    } else if (kind === 'end') ended = text(c);
  }
  return {header, scene, steps, ended, truncated: scan.truncated};
}

if (typeof module !== 'undefined') module.exports = {xxh32, scanChunks, decodeStep, decodeAll};

if (typeof require !== 'undefined' && require.main === module) {
  const fs = require('fs');
  const {decompress} = require('fzstd');
  const r = decodeAll(new Uint8Array(fs.readFileSync(process.argv[2])), decompress);
  const last = r.steps[r.steps.length - 1];
  const out = {format: r.header.format, version: r.header.version, objects: r.scene.object_count,
               robots: r.scene.robots.length, steps: r.steps.length, last_step: last && last.step,
               ended: r.ended, truncated: r.truncated};
  // With an id: its frame pose at every step ("x y z qw qx qy qz" in metres and units).
  if (process.argv[3] !== undefined) {
    const id = Number(process.argv[3]);
    out.poses = r.steps.map((s) => [s.step, ...Array.from(s.pose.slice(7 * id, 7 * id + 7))]);
  }
  console.log(JSON.stringify(out));
}
