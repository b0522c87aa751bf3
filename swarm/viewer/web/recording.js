// Reads recording.swrec (swarm/record/FORMAT.md): chunks, the run's header,
// the scene, and the step records, applied to a State to show any step.
import { decompress } from 'fzstd';

const KIND_HEADER = 1, KIND_SCENE = 2, KIND_KEYFRAME = 3, KIND_DELTA = 4, KIND_END = 5, KIND_LINKS = 6;
const SUPPORTED_MAJOR = 1;
export const NO_DETECTION = 65535;

// XXH32, seed 0 (FORMAT.md).
function xxh32(b) {
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

const utf8 = new TextDecoder();

function inflate(stored, rawSize, offset) {
  let raw;
  try {
    raw = decompress(stored, new Uint8Array(rawSize));
  } catch (e) {
    throw new Error(`recording: the chunk at byte ${offset} does not decompress (${e.message})`);
  }
  if (raw.length !== rawSize)
    throw new Error(`recording: the chunk at byte ${offset} decompresses to ${raw.length} bytes, not ${rawSize}`);
  return raw;
}

// What an object of a format 1.0 scene is drawn as (1.1 says it: `visual`).
function visualOf1_0(o) {
  if (o.type === 'shape') return o.shape || 'cylinder';
  if (o.type === 'led') return 'light';
  if (o.type === 'proximity_sensor') return 'ray';
  return 'none';
}

// The scene chunk's objects as flat arrays by recording id; each object's
// `visual` (box, cylinder, sphere, capsule, mesh, light, ray or none) as
// FORMAT.md 1.1 has it, also for a 1.0 scene. `declaredColors`: rays carry
// their colour in the step records (1.1).
function expandScene(json) {
  const count = json.object_count;
  const objects = new Array(count);
  const robotOf = new Int32Array(count).fill(-1);
  const rootOf = new Int32Array(count).fill(-1);  // the robot root's id; -1: a world pose
  for (const robot of json.robots) {
    const template = json.templates[robot.template];
    template.objects.forEach((o, k) => {
      const id = robot.first + k;
      objects[id] = { ...o, id, name: k === 0 ? robot.name : `${robot.name}/${o.name}`,
        parent: o.parent >= 0 ? robot.first + o.parent : -1, robot: robot.index, templateObject: k,
        template: robot.template };
      robotOf[id] = robot.index;
      rootOf[id] = k === 0 ? -1 : robot.first;
    });
  }
  for (const o of json.objects || []) objects[o.id] = { ...o, robot: -1, templateObject: -1 };
  for (let id = 0; id < count; ++id)
    if (!objects[id]) objects[id] = { id, type: 'frame', name: '', parent: -1, robot: -1 };
  let declaredColors = false;
  for (const o of objects) {
    if (o.visual !== undefined) declaredColors = true;
    else o.visual = visualOf1_0(o);
  }
  const robots = json.robots.map((r) => ({ ...r }));
  const robotByIndex = new Map(robots.map((r) => [r.index, r]));
  // Mesh assets (once each, however many objects use them): vertices in
  // the shape's frame, triangles, per-triangle colours or none.
  const meshes = (json.meshes || []).map((m) => ({ file: m.file,
    vertices: Float32Array.from(m.vertices || []), triangles: Uint32Array.from(m.triangles || []),
    colors: Float32Array.from(m.colors || []) }));
  return { count, objects, robotOf, rootOf, robots, robotByIndex, declaredColors, meshes };
}

// Where each section of a step record starts (FORMAT.md "Step records").
function sections(u8) {
  const dv = new DataView(u8.buffer, u8.byteOffset, u8.byteLength);
  const align = (o, a) => (o + a - 1) & ~(a - 1);
  const s = { dv, time: dv.getFloat64(0, true), index: dv.getUint32(8, true) };
  let o = 16;
  s.poseN = dv.getUint32(o, true); o += 4;
  s.poseIds = o; o += 4 * s.poseN;
  s.poseXyz = o; o += 12 * s.poseN;
  s.poseQ = o; o = align(o + 8 * s.poseN, 4);
  s.colorN = dv.getUint32(o, true); o += 4;
  s.colorIds = o; o += 4 * s.colorN;
  s.colorRgba = o; o += 4 * s.colorN;
  s.proxN = dv.getUint32(o, true); o += 4;
  s.proxIds = o; o += 4 * s.proxN;
  s.proxValues = o; o = align(o + 2 * s.proxN, 4);
  s.paintN = dv.getUint32(o, true); o += 4;
  s.paintCells = o; o += 4 * s.paintN;
  s.paintRgba = o; o += 4 * s.paintN;
  s.firstNameId = dv.getUint32(o, true);
  const nameCount = dv.getUint32(o + 4, true); o += 8;
  s.names = [];
  for (let i = 0; i < nameCount; ++i) {
    const length = dv.getUint16(o, true);
    s.names.push(utf8.decode(u8.subarray(o + 2, o + 2 + length)));
    o += 2 + length;
  }
  o = align(o, 4);
  s.sampleN = dv.getUint32(o, true); o += 4;
  s.sampleName = o; o += 4 * s.sampleN;
  s.sampleRobot = o; o += 4 * s.sampleN;
  s.sampleStep = o; o = align(o + 4 * s.sampleN, 8);
  s.sampleValue = o; o += 8 * s.sampleN;
  if (o > u8.byteLength) throw new Error(`recording: step record ${s.index} is shorter than its sections`);
  return s;
}

// The state of every recorded object at one step record.
export class State {
  constructor(scene, header) {
    const n = scene.count;
    this.xyz = new Int32Array(3 * n);      // position integers
    this.q = new Int16Array(4 * n);        // quaternion integers w, x, y, z
    this.q.fill(0);
    for (let i = 0; i < n; ++i) this.q[4 * i] = 32767;
    this.rgba = new Uint8Array(4 * n);     // colours; a: on
    this.prox = new Uint16Array(n).fill(NO_DETECTION);
    const paint = header.paint;
    this.paint = paint ? new Uint8Array(4 * paint.width * paint.height) : null;
    this.paintBackground = paint ? (paint.background || [1, 1, 1]).map((c) => Math.round(c * 255)) : null;
    scene.objects.forEach((o, id) => {
      if (!o.color) return;
      this.rgba.set([o.color[0] * 255, o.color[1] * 255, o.color[2] * 255, o.on === false ? 0 : 1], 4 * id);
    });
    this.clearPaint();
    this.record = -1;       // the step record shown
    this.links = null;      // its links [from, to, ...] (format 1.2), or null
    this.changedPaint = true;
  }
  clearPaint() {
    if (!this.paint) return;
    const [r, g, b] = this.paintBackground;
    for (let i = 0; i < this.paint.length; i += 4) {
      this.paint[i] = r; this.paint[i + 1] = g; this.paint[i + 2] = b; this.paint[i + 3] = 255;
    }
    this.changedPaint = true;
  }
  // Applies one decoded step record (a keyframe replaces, a delta adds).
  apply(u8, keyframe) {
    const s = sections(u8);
    const dv = s.dv;
    // Typed views (the sections are aligned for them; `decode` gives a
    // buffer of its own).
    const buffer = u8.buffer, base = u8.byteOffset, n = s.poseN;
    const ids = new Uint32Array(buffer, base + s.poseIds, n);
    const xyz = new Int32Array(buffer, base + s.poseXyz, 3 * n);
    const q = new Int16Array(buffer, base + s.poseQ, 4 * n);
    const X = this.xyz, Q = this.q;
    let id = 0;
    for (let i = 0; i < n; ++i) {
      id += ids[i];
      if (keyframe) {
        X[3 * id] = xyz[i]; X[3 * id + 1] = xyz[n + i]; X[3 * id + 2] = xyz[2 * n + i];
        Q[4 * id] = q[i]; Q[4 * id + 1] = q[n + i]; Q[4 * id + 2] = q[2 * n + i]; Q[4 * id + 3] = q[3 * n + i];
      } else {
        X[3 * id] += xyz[i]; X[3 * id + 1] += xyz[n + i]; X[3 * id + 2] += xyz[2 * n + i];
        Q[4 * id] += q[i]; Q[4 * id + 1] += q[n + i]; Q[4 * id + 2] += q[2 * n + i]; Q[4 * id + 3] += q[3 * n + i];
      }
    }
    const colorIds = new Uint32Array(buffer, base + s.colorIds, s.colorN);
    id = 0;
    for (let i = 0; i < s.colorN; ++i) {
      id += colorIds[i];
      for (let c = 0; c < 4; ++c) this.rgba[4 * id + c] = u8[s.colorRgba + 4 * i + c];
    }
    const proxIds = new Uint32Array(buffer, base + s.proxIds, s.proxN);
    const proxValues = new Uint16Array(buffer, base + s.proxValues, s.proxN);
    id = 0;
    for (let i = 0; i < s.proxN; ++i) {
      id += proxIds[i];
      this.prox[id] = proxValues[i];
    }
    if (this.paint) {
      if (keyframe) this.clearPaint();
      let cell = 0;
      for (let i = 0; i < s.paintN; ++i) {
        cell += dv.getUint32(s.paintCells + 4 * i, true);
        if (4 * cell + 3 < this.paint.length)
          for (let c = 0; c < 4; ++c) this.paint[4 * cell + c] = u8[s.paintRgba + 4 * i + c];
      }
      if (s.paintN > 0) this.changedPaint = true;
    }
    return s;
  }
}

// A recording being read: whole chunks so far, more appended as they come.
export class Recording {
  constructor() {
    this.header = null;
    this.scenes = [];       // {firstRecord, scene}
    this.records = [];      // {step, kind, stored (Uint8Array), rawSize, offset, scene}
    this.keyframes = [];    // indices into records
    this.ended = null;      // the end chunk's JSON
    this.bytesRead = 0;     // file bytes consumed (whole chunks)
    this.pending = new Uint8Array(0);
    this.metricNames = [];  // by name id
    this.metricSeries = new Map();  // name id -> {steps: [], sum: [], count: []} robots' mean or swarm value
    this.metricsDone = 0;   // records whose metrics were read
  }

  // Adds `bytes` (the file's next bytes); returns how many new step records.
  append(bytes) {
    let buf = bytes;
    if (this.pending.length) {
      buf = new Uint8Array(this.pending.length + bytes.length);
      buf.set(this.pending);
      buf.set(bytes, this.pending.length);
    }
    const before = this.records.length;
    let o = 0;
    while (o + 24 <= buf.length) {
      const dv = new DataView(buf.buffer, buf.byteOffset + o, 24);
      const offset = this.bytesRead;
      if (buf[o] !== 0x53 || buf[o + 1] !== 0x57 || buf[o + 2] !== 0x52 || buf[o + 3] !== 0x43)
        throw new Error(`recording: no chunk at byte ${offset} (corrupt file)`);
      const kind = dv.getUint8(4), step = dv.getUint32(8, true);
      const storedSize = dv.getUint32(12, true), rawSize = dv.getUint32(16, true);
      const checksum = dv.getUint32(20, true);
      if (o + 24 + storedSize > buf.length) break;  // a chunk still being written
      const stored = buf.subarray(o + 24, o + 24 + storedSize);
      if (xxh32(stored) !== checksum)
        throw new Error(`recording: the chunk at byte ${offset} has a wrong checksum (corrupt file)`);
      this.addChunk(kind, step, stored, rawSize, offset);
      o += 24 + storedSize;
      this.bytesRead += 24 + storedSize;
    }
    this.pending = buf.slice(o);
    return this.records.length - before;
  }

  addChunk(kind, step, stored, rawSize, offset) {
    if (!this.header && kind !== KIND_HEADER)
      throw new Error('recording: the file does not start with a header chunk (not a swarmsim recording)');
    if (kind === KIND_HEADER) {
      const header = JSON.parse(utf8.decode(inflate(stored, rawSize, offset)));
      if (header.format !== 'swarmsim-recording')
        throw new Error(`recording: format '${header.format}', expected 'swarmsim-recording'`);
      const [major, minor] = header.version;
      if (major > SUPPORTED_MAJOR)
        throw new Error(`recording: format version ${major}.${minor} is newer than this viewer's ${SUPPORTED_MAJOR}.x: view it with a newer swarmsim`);
      this.header = header;
      this.metricNames = [...(header.metrics || [])];
    } else if (kind === KIND_SCENE) {
      const json = JSON.parse(utf8.decode(inflate(stored, rawSize, offset)));
      this.scenes.push({ firstRecord: this.records.length, scene: expandScene(json) });
    } else if (kind === KIND_KEYFRAME || kind === KIND_DELTA) {
      if (!this.scenes.length) throw new Error(`recording: a step record before the scene (byte ${offset})`);
      if (kind === KIND_KEYFRAME) this.keyframes.push(this.records.length);
      else if (!this.keyframes.length) throw new Error(`recording: a delta before any keyframe (byte ${offset})`);
      // Kept compressed: decoded when shown (a 10,000-robot run stays small in memory).
      this.records.push({ step, kind, stored: stored.slice(), rawSize, offset,
        scene: this.scenes.length - 1 });
    } else if (kind === KIND_END) {
      this.ended = JSON.parse(utf8.decode(inflate(stored, rawSize, offset)));
    } else if (kind === KIND_LINKS) {
      // Format 1.2: the links of the step record right before it.
      const last = this.records[this.records.length - 1];
      if (last && last.step === step) last.links = { stored: stored.slice(), rawSize, offset };
    }
  }

  // The links of step record `index` (FORMAT.md "Links chunk") as a
  // Uint32Array [from0, to0, from1, to1, ...], or null without a links chunk.
  linksOf(index) {
    const l = this.records[index]?.links;
    if (!l) return null;
    const raw = inflate(l.stored, l.rawSize, l.offset);
    const dv = new DataView(raw.buffer, raw.byteOffset, raw.byteLength);
    const n = raw.byteLength >= 8 ? dv.getUint32(4, true) : 0;
    if (raw.byteLength !== 8 + 8 * n)
      throw new Error(`recording: the links chunk at byte ${l.offset} is ${raw.byteLength} bytes, not ${8 + 8 * n}`);
    const out = new Uint32Array(2 * n);
    let from = 0;
    for (let i = 0; i < n; ++i) {
      from += dv.getUint32(8 + 4 * i, true);
      out[2 * i] = from;
      out[2 * i + 1] = dv.getUint32(8 + 4 * n + 4 * i, true);
    }
    return out;
  }

  decode(index) {
    const r = this.records[index];
    let raw = inflate(r.stored, r.rawSize, r.offset);
    if (raw.byteOffset % 8) raw = raw.slice();
    return raw;
  }

  sceneOf(index) { return this.scenes[this.records[index].scene].scene; }
  timeOf(index) { return this.records[index].step * this.header.dt; }

  // Brings `state` to step record `index` (from where it is, or from the
  // last keyframe at or before it). Returns the last record's sections.
  seek(state, index) {
    let k = 0;
    for (let lo = 0, hi = this.keyframes.length - 1; lo <= hi;) {
      const mid = (lo + hi) >> 1;
      if (this.keyframes[mid] <= index) { k = this.keyframes[mid]; lo = mid + 1; } else hi = mid - 1;
    }
    let from = state.record >= k && state.record <= index ? state.record + 1 : k;
    let last = null;
    for (let i = from; i <= index; ++i) {
      last = state.apply(this.decode(i), this.records[i].kind === KIND_KEYFRAME);
      state.record = i;
    }
    state.links = this.linksOf(index);
    return last;
  }

  // Reads the metrics of up to `budget` more records into metricSeries
  // (done in slices so the page stays responsive); false when all are read.
  readMetrics(budget) {
    const end = Math.min(this.records.length, this.metricsDone + budget);
    for (let i = this.metricsDone; i < end; ++i) {
      const s = sections(this.decode(i));
      s.names.forEach((name, k) => { this.metricNames[s.firstNameId + k] = name; });
      const dv = s.dv;
      for (let j = 0; j < s.sampleN; ++j) {
        const nameId = dv.getUint32(s.sampleName + 4 * j, true);
        const robot = dv.getInt32(s.sampleRobot + 4 * j, true);
        const step = dv.getUint32(s.sampleStep + 4 * j, true);
        const value = dv.getFloat64(s.sampleValue + 8 * j, true);
        let series = this.metricSeries.get(nameId);
        if (!series) this.metricSeries.set(nameId, series = { steps: [], sum: [], count: [], swarm: robot < 0 });
        const n = series.steps.length;
        if (n && series.steps[n - 1] === step) { series.sum[n - 1] += value; series.count[n - 1] += 1; }
        else { series.steps.push(step); series.sum.push(value); series.count.push(1); }
      }
    }
    this.metricsDone = end;
    return end < this.records.length;
  }

  // The last value of each metric of robot `robotIndex` (-1: the swarm's)
  // at or before step record `index`: [{name, value, step}]. Reads back from
  // `index` until 50 records bring no new metric (or the start).
  lastMetrics(robotIndex, index) {
    const found = new Map();
    for (let i = index, quiet = 0; i >= 0 && quiet < 50; --i, ++quiet) {
      const s = sections(this.decode(i));
      s.names.forEach((name, k) => { this.metricNames[s.firstNameId + k] = name; });
      const dv = s.dv;
      for (let j = s.sampleN - 1; j >= 0; --j) {
        const nameId = dv.getUint32(s.sampleName + 4 * j, true);
        if (dv.getInt32(s.sampleRobot + 4 * j, true) !== robotIndex || found.has(nameId)) continue;
        found.set(nameId, { value: dv.getFloat64(s.sampleValue + 8 * j, true),
          step: dv.getUint32(s.sampleStep + 4 * j, true) });
        quiet = 0;
      }
    }
    return [...found].sort((a, b) => a[0] - b[0])
      .map(([id, v]) => ({ name: this.metricNames[id] ?? `#${id}`, ...v }));
  }
}
