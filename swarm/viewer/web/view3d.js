// The 3D view (three.js): the floor, the paint layer, every recorded object
// as its type declares it (FORMAT.md: `visual`): solids and lights as
// instances (one InstancedMesh per kind and size; a mesh asset's geometry
// once, instanced over every object that uses it), rays as line segments;
// trails; camera with orbit/pan; picking robots.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { NO_DETECTION } from './recording.js';

// Triangles of meshes (each copy counted) above which meshes are simplified
// (or drawn as their bounding boxes): 1 M on a GPU, 100 k on a software
// renderer (SwiftShader, llvmpipe: headless Chromium, a machine without a
// GPU), which draws a few million triangles a second; the page's
// `mesh_budget` URL parameter changes it.
export const DEFAULT_MESH_BUDGET = 1e6;
export const SOFTWARE_MESH_BUDGET = 1e5;

// Whether WebGL draws in software here (its unmasked renderer's name says
// so): such a renderer gets no antialiasing and the smaller mesh budget.
let software = null;
export function softwareRenderer() {
  if (software !== null) return software;
  software = false;
  try {
    const gl = document.createElement('canvas').getContext('webgl2') || document.createElement('canvas').getContext('webgl');
    const info = gl?.getExtension('WEBGL_debug_renderer_info');
    const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
    software = /swiftshader|llvmpipe|softpipe|software/i.test(name);
    gl?.getExtension('WEBGL_lose_context')?.loseContext();
  } catch (e) {
    software = false;
  }
  return software;
}

// "2.7 M", "135 k", "624": a triangle count for the status line.
export function triangleText(n) {
  if (n >= 1e6) return `${(n / 1e6).toFixed(n >= 1e7 ? 0 : 1).replace(/\.0$/, '')} M`;
  if (n >= 1e4) return `${Math.round(n / 1e3)} k`;
  return String(n);
}

// A mesh asset's bounds in its frame: {lo: [x, y, z], hi: [x, y, z]}.
function boundsOf(asset) {
  const v = asset.vertices, lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < v.length; i += 3)
    for (let k = 0; k < 3; ++k) { lo[k] = Math.min(lo[k], v[i + k]); hi[k] = Math.max(hi[k], v[i + k]); }
  return { lo, hi };
}

// Whether object `o` names an embedded mesh asset that can be drawn: its
// triangles name its vertices (the recording's reader in C++ checks this too).
function assetOf(o, meshes) {
  if (o.visual !== 'mesh' || !Number.isInteger(o.mesh) || !meshes || o.mesh < 0 || o.mesh >= meshes.length) return null;
  const asset = meshes[o.mesh];
  if (asset.checked === undefined) {
    const n = asset.vertices.length / 3;
    asset.checked = asset.triangles.length > 0 && asset.triangles.length % 3 === 0 &&
      asset.vertices.length % 3 === 0 && asset.triangles.every((i) => i < n);
  }
  return asset.checked ? asset : null;
}

// The fewest triangles a simplified mesh keeps; below, it is drawn as its box.
const MIN_SIMPLIFIED = 12;

// Mesh asset `asset` simplified to at most `target` triangles by vertex
// clustering (Rossignac and Borrel 1993): its bounding box cut into R x R x R
// cells, the vertices of a cell merged into their mean, triangles left with
// fewer than three corners dropped; the finest R (256, 181, 128, ... 2: each
// about halves the triangles) that keeps at most `target`. Its silhouette stays within a cell of the original's.
// Returns an asset ({vertices, triangles, colors, file}), or null when even
// R = 2 keeps more, or fewer than MIN_SIMPLIFIED.
function simplify(asset, target) {
  const v = asset.vertices, tri = asset.triangles, c = asset.colors, n = tri.length / 3;
  const ownColors = c.length === tri.length;
  const { lo, hi } = boundsOf(asset);
  for (let R = 256; R >= 2; R = R === 3 ? 2 : Math.round(R / Math.SQRT2)) {
    const scale = [0, 1, 2].map((k) => R / Math.max(hi[k] - lo[k], 1e-9));
    const cellOf = new Map(), remap = new Uint32Array(v.length / 3), sums = [];
    for (let i = 0; i < v.length / 3; ++i) {
      let key = 0;
      for (let k = 0; k < 3; ++k) key = key * (R + 1) + Math.min(R - 1, Math.floor((v[3 * i + k] - lo[k]) * scale[k]));
      let cell = cellOf.get(key);
      if (cell === undefined) { cell = cellOf.size; cellOf.set(key, cell); sums.push(0, 0, 0, 0); }
      remap[i] = cell;
      sums[4 * cell] += v[3 * i]; sums[4 * cell + 1] += v[3 * i + 1]; sums[4 * cell + 2] += v[3 * i + 2]; ++sums[4 * cell + 3];
    }
    const kept = [];
    for (let t = 0; t < n; ++t) {
      const a = remap[tri[3 * t]], b = remap[tri[3 * t + 1]], d = remap[tri[3 * t + 2]];
      if (a !== b && b !== d && a !== d) kept.push(t);
      if (kept.length > target) break;
    }
    if (kept.length > target) continue;
    if (kept.length < MIN_SIMPLIFIED) return null;
    const vertices = new Float32Array(3 * cellOf.size);
    for (let cell = 0; cell < cellOf.size; ++cell)
      for (let k = 0; k < 3; ++k) vertices[3 * cell + k] = sums[4 * cell + k] / sums[4 * cell + 3];
    const triangles = new Uint32Array(3 * kept.length), colors = new Float32Array(ownColors ? 3 * kept.length : 0);
    kept.forEach((t, j) => {
      for (let k = 0; k < 3; ++k) {
        triangles[3 * j + k] = remap[tri[3 * t + k]];
        if (ownColors) colors[3 * j + k] = c[3 * t + k];
      }
    });
    return { file: asset.file, vertices, triangles, colors };
  }
  return null;
}

// The largest number of triangles c such that the meshes, each kept whole
// if it has at most c and cut to c otherwise, fit `budget`:
// sum of copies x min(triangles, c) <= budget. `assets`: [triangles, copies].
function capFor(assets, budget) {
  assets.sort((a, b) => a[0] - b[0]);
  let whole = 0, copiesLeft = assets.reduce((n, [, k]) => n + k, 0);
  for (const [n, k] of assets) {
    // Every asset from here on is cut to c <= n: the rest of the budget shared.
    const c = Math.floor((budget - whole) / copiesLeft);
    if (c < n) return Math.max(0, c);
    whole += n * k;
    copiesLeft -= k;
  }
  return Infinity;
}

// Whether `o` is drawn in its mesh's own per-triangle colours (FORMAT.md
// `mesh_colors`) rather than its recorded colour.
function ownColorsOf(o, asset) {
  return !!o.mesh_colors && asset.colors.length === asset.triangles.length;
}

// A mesh asset as one indexed BufferGeometry (the welded vertices shared,
// flat-shaded by its material). In its own colours: its triangles sorted by
// colour into groups, one material each (a file has few materials), so the
// geometry stays indexed. Returns {geometry, colors: [THREE.Color per group] | null}.
function meshGeometryOf(asset, ownColors) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(asset.vertices, 3));
  const small = asset.vertices.length / 3 <= 65536;
  const tri = asset.triangles, n = tri.length / 3;
  if (!ownColors) {
    geometry.setIndex(new THREE.BufferAttribute(small ? Uint16Array.from(tri) : tri, 1));
    return { geometry, colors: null };
  }
  const c = asset.colors, byte = (v) => Math.round(Math.min(1, Math.max(0, v)) * 255);
  const keys = new Uint32Array(n), first = new Map();
  for (let t = 0; t < n; ++t) {
    const key = (byte(c[3 * t]) << 16) | (byte(c[3 * t + 1]) << 8) | byte(c[3 * t + 2]);
    keys[t] = key;
    const e = first.get(key);
    if (e) ++e.count; else first.set(key, { count: 1, start: 0, at: 0, t });
  }
  const index = small ? new Uint16Array(3 * n) : new Uint32Array(3 * n);
  const colors = [];
  let start = 0;
  for (const e of first.values()) {
    e.start = e.at = start;
    geometry.addGroup(3 * start, 3 * e.count, colors.length);
    colors.push(new THREE.Color().setRGB(c[3 * e.t], c[3 * e.t + 1], c[3 * e.t + 2], THREE.SRGBColorSpace));
    start += e.count;
  }
  for (let t = 0; t < n; ++t) {
    const e = first.get(keys[t]);
    index.set(tri.subarray(3 * t, 3 * t + 3), 3 * e.at++);
  }
  geometry.setIndex(new THREE.BufferAttribute(index, 1));
  return { geometry, colors };
}

// Fewer triangles per round shape when there are many of them (a software
// renderer draws 10,000 robots at 30 frames/s only so), or when it is
// smaller than a centimetre (an imported robot's mass carriers).
function geometryOf(o, many) {
  const [a, b, c] = o.size || [0.05, 0.05, 0.05];
  const round = many ? 8 : a < 0.01 ? 6 : 24;
  switch (o.visual) {
    case 'box': case 'mesh': return new THREE.BoxGeometry(Math.max(a, 1e-4), Math.max(b, 1e-4), Math.max(c, 1e-4));
    case 'sphere': return new THREE.SphereGeometry(Math.max(a, 1e-4), round, round * 3 / 4);
    case 'capsule': return new THREE.CapsuleGeometry(Math.max(a, 1e-4), Math.max(c - 2 * a, 0), 4, round).rotateX(Math.PI / 2);
    case 'cylinder': default:
      return new THREE.CylinderGeometry(Math.max(a, 1e-4), Math.max(a, 1e-4), Math.max(c, 1e-4), round).rotateX(Math.PI / 2);
  }
}

const SOLIDS = new Set(['box', 'cylinder', 'sphere', 'capsule', 'mesh']);

// Above this many instances of a kind, the cheaper geometry.
const MANY = 1000;

export class View3D {
  // `large`: a scene of thousands of robots (no antialiasing, 1 pixel per CSS
  // pixel; nor on a software renderer). `options.meshBudget`: triangles of
  // meshes drawn in full (above: simplified, or boxes).
  constructor(container, large, options = {}) {
    this.software = softwareRenderer();
    this.meshBudget = options.meshBudget ?? (this.software ? SOFTWARE_MESH_BUDGET : DEFAULT_MESH_BUDGET);
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: !large && !this.software, powerPreference: 'high-performance' });
    this.renderer.setPixelRatio(large ? 1 : window.devicePixelRatio || 1);
    this.large = large;
    container.prepend(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x1d2127);
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.01, 1000);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = false;
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(3, -4, 10);
    this.scene.add(sun);
    this.world = new THREE.Group();
    this.scene.add(this.world);
    this.show = { rays: false, leds: true, trails: false, paint: true, links: true };
    this.linkCount = 0;     // lines drawn for the links shown (tests read them)
    this.mutualLinks = 0;   // of which between objects linked both ways
    this.followRobot = -1;
    this.dirty = true;
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
    this.controls.addEventListener('change', () => { this.dirty = true; });
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth), h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, true);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  // Builds the drawables of a scene (again when the scene changes).
  build(header, scene, state) {
    for (const child of [...this.world.children]) {
      this.world.remove(child);
      child.traverse((c) => {
        c.geometry?.dispose();
        for (const m of [c.material || []].flat()) { m.map?.dispose(); m.dispose(); }
      });
    }
    this.header = header;
    this.sceneInfo = scene;
    this.state = state;
    const unit = header.position_unit;
    // World poses of every object: position (3 n) and quaternion x, y, z, w (4 n).
    this.worldPos = new Float64Array(3 * scene.count);
    this.worldQuat = new Float64Array(4 * scene.count);
    this.unit = unit;

    // The floor and the paint layer.
    const floor = header.floor || { min: [-5, -5], max: [5, 5] };
    const fw = floor.max[0] - floor.min[0], fh = floor.max[1] - floor.min[1];
    const floorMesh = new THREE.Mesh(new THREE.PlaneGeometry(fw, fh),
      new THREE.MeshLambertMaterial({ color: 0xb9bdc4 }));
    floorMesh.position.set((floor.min[0] + floor.max[0]) / 2, (floor.min[1] + floor.max[1]) / 2, -0.001);
    this.world.add(floorMesh);
    const grid = new THREE.GridHelper(Math.max(fw, fh), Math.round(Math.max(fw, fh)), 0x8a8f99, 0x9ea3ab);
    grid.rotateX(Math.PI / 2);
    grid.position.copy(floorMesh.position).setZ(0);
    this.world.add(grid);
    this.paintMesh = null;
    if (header.paint && state.paint) {
      const p = header.paint;
      this.paintTexture = new THREE.DataTexture(state.paint, p.width, p.height, THREE.RGBAFormat);
      this.paintTexture.magFilter = THREE.NearestFilter;
      this.paintTexture.colorSpace = THREE.SRGBColorSpace;
      this.paintTexture.needsUpdate = true;
      const pw = p.max[0] - p.min[0], ph = p.max[1] - p.min[1];
      this.paintMesh = new THREE.Mesh(new THREE.PlaneGeometry(pw, ph),
        new THREE.MeshBasicMaterial({ map: this.paintTexture, side: THREE.DoubleSide, transparent: true, opacity: 0.85 }));
      // Row 0 is the +y edge: mirror v.
      this.paintMesh.scale.y = -1;
      this.paintMesh.position.set((p.min[0] + p.max[0]) / 2, (p.min[1] + p.max[1]) / 2, 0.0005);
      this.world.add(this.paintMesh);
    }
    // The map's boxes.
    for (const b of header.environment?.boxes || []) {
      const m = new THREE.Mesh(new THREE.BoxGeometry(b[3] - b[0], b[4] - b[1], b[5] - b[2]),
        new THREE.MeshLambertMaterial({ color: 0x8d8d8d }));
      m.position.set((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2);
      this.world.add(m);
    }

    // Solids and lights, instanced by kind and size. A swarm of thousands is
    // drawn as its robots' bodies (root solids) and lights only.
    const groups = new Map();
    const sensors = [];
    this.bodiesOnly = this.large;
    this.rayColors = scene.declaredColors;
    // Meshes (the scene's embedded assets): their triangles, each copy
    // counted; past the budget every mesh is drawn as its bounding box.
    // A swarm of thousands draws its bodies as discs whatever they are.
    const meshes = this.large ? [] : scene.meshes || [];
    let meshTriangles = 0;
    const copies = new Map();  // asset index -> objects drawing it
    for (const o of scene.objects) {
      const asset = assetOf(o, meshes);
      if (!asset) continue;
      meshTriangles += asset.triangles.length / 3;
      copies.set(o.mesh, (copies.get(o.mesh) || 0) + 1);
    }
    // Past the budget, no asset keeps more than `cap` triangles: the largest
    // cap with which the copies fit the budget (meshes smaller than it stay
    // whole, larger ones are simplified to it); one that would keep fewer
    // than MIN_SIMPLIFIED is drawn as its box (a budget of 0: every mesh).
    const over = meshTriangles > this.meshBudget;
    const cap = over ? capFor([...copies].map(([i, k]) => [meshes[i].triangles.length / 3, k]), this.meshBudget) : Infinity;
    const drawnAssets = new Map();  // asset index -> the asset drawn, or null (its box)
    const drawnOf = (o, asset) => {
      if (asset.triangles.length / 3 <= cap) return asset;
      if (!drawnAssets.has(o.mesh)) drawnAssets.set(o.mesh, cap < MIN_SIMPLIFIED ? null : simplify(asset, cap));
      return drawnAssets.get(o.mesh);
    };
    for (const o of scene.objects) {
      if (o.visual === 'ray') { sensors.push(o.id); continue; }
      const solid = SOLIDS.has(o.visual);
      let key, asset = null, ownColors = false;
      if (solid && this.bodiesOnly && o.robot >= 0 && o.templateObject !== 0) continue;
      let drawn = null;
      if (solid && (asset = assetOf(o, meshes))) {
        drawn = drawnOf(o, asset);
        ownColors = !!drawn && ownColorsOf(o, asset);
        key = `${drawn ? 'm' : 'b'}|${o.mesh}|${ownColors ? 1 : 0}`;
      } else if (solid) key = `s|${o.visual}|${(o.size || []).join(',')}`;
      else if (o.visual === 'light') key = `l|${o.radius}`;
      else continue;
      let g = groups.get(key);
      if (!g) groups.set(key, g = { key, led: o.visual === 'light', sample: o, ids: [], asset, drawn, ownColors });
      g.ids.push(o.id);
    }
    // The objects whose world pose is needed: drawn ones and robot roots
    // (sensors too while rays are shown), in id order (roots first).
    const drawn = new Uint8Array(scene.count);
    for (const g of groups.values()) for (const id of g.ids) drawn[id] = 1;
    for (const r of scene.robots) drawn[r.first] = 1;
    for (let id = 0; id < scene.count; ++id) if (scene.rootOf[id] < 0) drawn[id] = 1;
    // What the meshes cost as drawn (the status line shows it).
    let drawnTriangles = 0, boxes = 0, simplified = 0;
    for (const g of groups.values()) {
      if (!g.asset) continue;
      if (!g.drawn) boxes += g.ids.length;
      else {
        drawnTriangles += g.ids.length * g.drawn.triangles.length / 3;
        if (g.drawn !== g.asset) simplified += g.ids.length;
      }
    }
    this.meshInfo = { triangles: meshTriangles, budget: this.meshBudget, drawnTriangles, boxes, simplified,
      asBoxes: boxes > 0 && simplified === 0 && drawnTriangles === 0 };
    this.drawnIds = Uint32Array.from(drawn.reduce((list, on, id) => (on && list.push(id), list), []));
    this.drawnAndSensorIds = Uint32Array.from([...this.drawnIds, ...sensors].sort((a, b) => a - b));
    this.groups = [];
    for (const g of groups.values()) {
      const mesh = this.large ? this.pointsOf(g) : this.instancesOf(g);
      mesh.frustumCulled = false;
      mesh.userData.ids = Int32Array.from(g.ids);
      mesh.userData.led = g.led;
      this.world.add(mesh);
      this.groups.push(mesh);
    }
    // Proximity rays: one segment per sensor.
    this.sensorIds = Int32Array.from(sensors);
    const rayGeometry = new THREE.BufferGeometry();
    rayGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6 * sensors.length), 3));
    rayGeometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(6 * sensors.length), 3));
    this.rays = new THREE.LineSegments(rayGeometry, new THREE.LineBasicMaterial({ vertexColors: true }));
    this.rays.frustumCulled = false;
    this.rays.visible = this.show.rays;
    this.world.add(this.rays);
    // Trails of the robots' roots.
    this.robotRoots = Int32Array.from(scene.robots.map((r) => r.first));
    // The last 200 positions of each robot (40 in a swarm of thousands).
    this.trailLength = this.large ? 40 : 200;
    this.trailPoints = new Float32Array(3 * this.trailLength * this.robotRoots.length);
    this.trailCount = 0;
    this.trailHead = 0;
    this.trailRecord = -1;
    const trailGeometry = new THREE.BufferGeometry();
    trailGeometry.setAttribute('position', new THREE.BufferAttribute(
      new Float32Array(6 * (this.trailLength - 1) * this.robotRoots.length), 3));
    this.trails = new THREE.LineSegments(trailGeometry, new THREE.LineBasicMaterial({ color: 0xffd34d }));
    this.trails.frustumCulled = false;
    this.trails.visible = this.show.trails;
    this.world.add(this.trails);
    // Links (format 1.2: range-and-bearing boards that heard each other):
    // one segment per pair, grown as needed.
    this.links = new THREE.LineSegments(new THREE.BufferGeometry(),
      new THREE.LineBasicMaterial({ vertexColors: true }));
    this.links.frustumCulled = false;
    this.linkCapacity = 0;
    this.world.add(this.links);
    this.update();
  }

  // The world position of recorded object `id` from the state's integers.
  worldPoint(id, out, o) {
    const { xyz, q } = this.state, unit = this.unit;
    const px = xyz[3 * id] * unit, py = xyz[3 * id + 1] * unit, pz = xyz[3 * id + 2] * unit;
    const r = this.sceneInfo.rootOf[id];
    if (r < 0) { out[o] = px; out[o + 1] = py; out[o + 2] = pz; return; }
    let rw = q[4 * r], rx = q[4 * r + 1], ry = q[4 * r + 2], rz = q[4 * r + 3];
    const norm = Math.hypot(rw, rx, ry, rz) || 1;
    rw /= norm; rx /= norm; ry /= norm; rz /= norm;
    const tx = 2 * (ry * pz - rz * py), ty = 2 * (rz * px - rx * pz), tz = 2 * (rx * py - ry * px);
    out[o] = xyz[3 * r] * unit + px + rw * tx + (ry * tz - rz * ty);
    out[o + 1] = xyz[3 * r + 1] * unit + py + rw * ty + (rz * tx - rx * tz);
    out[o + 2] = xyz[3 * r + 2] * unit + pz + rw * tz + (rx * ty - ry * tx);
  }

  // A line per linked pair: bright where both heard each other, dim where
  // one heard the other only.
  updateLinks() {
    const links = this.state.links;
    this.linkCount = 0;
    this.mutualLinks = 0;
    this.links.visible = this.show.links && !!links;
    if (!this.links.visible) return;
    const n = links.length / 2;
    // Where each object's links start (links are sorted by their first id).
    const start = new Map();
    for (let i = n - 1; i >= 0; --i) start.set(links[2 * i], i);
    const heard = (a, b) => {
      for (let i = start.get(a) ?? n; i < n && links[2 * i] === a; ++i) if (links[2 * i + 1] === b) return true;
      return false;
    };
    if (this.linkCapacity < Math.max(n, 1)) {
      this.linkCapacity = Math.max(n, 2 * this.linkCapacity, 16);
      const g = this.links.geometry;
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6 * this.linkCapacity), 3));
      g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(6 * this.linkCapacity), 3));
    }
    const pos = this.links.geometry.attributes.position.array, col = this.links.geometry.attributes.color.array;
    let k = 0;
    for (let i = 0; i < n; ++i) {
      const a = links[2 * i], b = links[2 * i + 1];
      const mutual = heard(b, a);
      if (mutual && a > b) continue;  // drawn once, from the lower id
      this.worldPoint(a, pos, 6 * k);
      this.worldPoint(b, pos, 6 * k + 3);
      const c = mutual ? [0.3, 0.9, 1] : [0.1, 0.35, 0.45];
      col.set([...c, ...c], 6 * k);
      if (mutual) ++this.mutualLinks;
      ++k;
    }
    this.linkCount = k;
    this.links.geometry.setDrawRange(0, 2 * k);
    this.links.geometry.attributes.position.needsUpdate = true;
    this.links.geometry.attributes.color.needsUpdate = true;
  }

  // One InstancedMesh for the objects of group `g` (same kind and size, or
  // the same mesh asset: its geometry once for all of them).
  instancesOf(g) {
    const many = g.ids.length > MANY;
    let geometry, material, colors = null;
    if (g.drawn) {
      ({ geometry, colors } = meshGeometryOf(g.drawn, g.ownColors));
      material = colors ? colors.map((color) => new THREE.MeshLambertMaterial({ color, flatShading: true }))
        : new THREE.MeshLambertMaterial({ color: 0xffffff, flatShading: true });
    } else {
      if (g.asset) {
        // Past the budget: the box that holds the mesh, where it is in the object's frame.
        const { lo, hi } = boundsOf(g.asset);
        geometry = new THREE.BoxGeometry(Math.max(hi[0] - lo[0], 1e-4), Math.max(hi[1] - lo[1], 1e-4),
          Math.max(hi[2] - lo[2], 1e-4)).translate((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
      } else if (g.led) geometry = new THREE.SphereGeometry(Math.max(g.sample.radius || 0.01, 1e-4), many ? 6 : 10, many ? 4 : 8);
      else geometry = geometryOf(g.sample, many);
      material = g.led ? new THREE.MeshBasicMaterial({ color: 0xffffff })
        : new THREE.MeshLambertMaterial({ color: 0xffffff });
    }
    const mesh = new THREE.InstancedMesh(geometry, material, g.ids.length);
    mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
    mesh.setColorAt(0, new THREE.Color(1, 1, 1));
    mesh.instanceColor.array.fill(1);
    if (g.asset) {
      mesh.userData.mesh = { asset: g.sample.mesh, file: g.asset.file, asBox: !g.drawn,
        simplified: !!g.drawn && g.drawn !== g.asset, fileTriangles: g.asset.triangles.length / 3,
        triangles: g.drawn ? g.drawn.triangles.length / 3 : 0, colors: colors && colors.map((c) => c.getHex(THREE.SRGBColorSpace)) };
      mesh.userData.ownColors = !!colors;
    }
    return mesh;
  }

  // What the meshes are drawn as, for tests and the status line: per group,
  // the asset, its file, the triangles drawn per copy (0: drawn as a box),
  // its own colours (sRGB 0xRRGGBB per material) or null, and each copy's
  // recorded colour (sRGB 0xRRGGBB, as drawn).
  meshGroups() {
    return this.groups.filter((g) => g.userData.mesh).map((g) => ({ ...g.userData.mesh,
      instances: g.count, geometryTriangles: (g.geometry.index ? g.geometry.index.count : g.geometry.attributes.position.count) / 3,
      instanceColors: Array.from({ length: g.count }, (_, j) => new THREE.Color().fromArray(g.instanceColor.array, 3 * j).getHex(THREE.SRGBColorSpace)) }));
  }

  // A swarm of thousands: each object a disc of its size seen from any side
  // (one point each; software renderers draw 10,000 instanced meshes slowly).
  pointsOf(g) {
    const o = g.sample, n = g.ids.length;
    const [a, b] = o.size || [0.05, 0.05];
    const diameter = g.led ? 2 * (o.radius || 0.01) : o.visual === 'box' || o.visual === 'mesh' ? Math.hypot(a, b) : 2 * a;
    if (!View3D.disc) {
      const canvas = document.createElement('canvas');
      canvas.width = canvas.height = 64;
      const c = canvas.getContext('2d');
      c.fillStyle = '#fff';
      c.beginPath();
      c.arc(32, 32, 30, 0, 2 * Math.PI);
      c.fill();
      View3D.disc = new THREE.CanvasTexture(canvas);
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * n), 3).setUsage(THREE.DynamicDrawUsage));
    geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * n), 3).setUsage(THREE.DynamicDrawUsage));
    const points = new THREE.Points(geometry, new THREE.PointsMaterial({
      size: Math.max(diameter, 1e-3), sizeAttenuation: true, vertexColors: true, map: View3D.disc, alphaTest: 0.5 }));
    points.userData.points = true;
    points.userData.radius = diameter / 2;
    return points;
  }

  // The camera looking at the whole floor from above (`topDown`) or slanted.
  frame(topDown) {
    const floor = this.header.floor || { min: [-5, -5], max: [5, 5] };
    const cx = (floor.min[0] + floor.max[0]) / 2, cy = (floor.min[1] + floor.max[1]) / 2;
    const size = Math.max(floor.max[0] - floor.min[0], floor.max[1] - floor.min[1]);
    const distance = size / 2 / Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 1.1;
    this.controls.target.set(cx, cy, 0);
    if (topDown) this.camera.position.set(cx, cy - distance * 1e-4, distance);
    else this.camera.position.set(cx, cy - distance * 0.75, distance * 0.75);
    this.camera.near = distance / 1000;
    this.camera.far = distance * 10;
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.dirty = true;
  }

  // World poses from the state's integers: X_WO = X_WR X_RO for robots' parts.
  computeWorldPoses() {
    const { xyz, q } = this.state, unit = this.unit, qs = 1 / 32767;
    const P = this.worldPos, Q = this.worldQuat, roots = this.sceneInfo.rootOf;
    const ids = this.show.rays ? this.drawnAndSensorIds : this.drawnIds;
    for (let k = 0; k < ids.length; ++k) {
      const i = ids[k];
      let px = xyz[3 * i] * unit, py = xyz[3 * i + 1] * unit, pz = xyz[3 * i + 2] * unit;
      let qw = q[4 * i] * qs, qx = q[4 * i + 1] * qs, qy = q[4 * i + 2] * qs, qz = q[4 * i + 3] * qs;
      const norm = Math.hypot(qw, qx, qy, qz) || 1;
      qw /= norm; qx /= norm; qy /= norm; qz /= norm;
      const r = roots[i];
      if (r >= 0) {
        // Rotate p by the root's quaternion, add its position; compose rotations.
        const rx = Q[4 * r], ry = Q[4 * r + 1], rz = Q[4 * r + 2], rw = Q[4 * r + 3];
        const tx = 2 * (ry * pz - rz * py), ty = 2 * (rz * px - rx * pz), tz = 2 * (rx * py - ry * px);
        const wx = px + rw * tx + (ry * tz - rz * ty);
        const wy = py + rw * ty + (rz * tx - rx * tz);
        const wz = pz + rw * tz + (rx * ty - ry * tx);
        px = P[3 * r] + wx; py = P[3 * r + 1] + wy; pz = P[3 * r + 2] + wz;
        const nw = rw * qw - rx * qx - ry * qy - rz * qz;
        const nx = rw * qx + rx * qw + ry * qz - rz * qy;
        const ny = rw * qy - rx * qz + ry * qw + rz * qx;
        const nz = rw * qz + rx * qy - ry * qx + rz * qw;
        qw = nw; qx = nx; qy = ny; qz = nz;
      }
      P[3 * i] = px; P[3 * i + 1] = py; P[3 * i + 2] = pz;
      Q[4 * i] = qx; Q[4 * i + 1] = qy; Q[4 * i + 2] = qz; Q[4 * i + 3] = qw;
    }
  }

  // Pushes the state into the instances, rays, paint and trails.
  update() {
    this.computeWorldPoses();
    const P = this.worldPos, Q = this.worldQuat, rgba = this.state.rgba;
    for (const mesh of this.groups) {
      if (mesh.userData.points) { this.updatePoints(mesh); continue; }
      const ids = mesh.userData.ids, m = mesh.instanceMatrix.array, c = mesh.instanceColor.array;
      const led = mesh.userData.led, showLeds = this.show.leds, own = mesh.userData.ownColors;
      for (let j = 0; j < ids.length; ++j) {
        const id = ids[j];
        const x = Q[4 * id], y = Q[4 * id + 1], z = Q[4 * id + 2], w = Q[4 * id + 3];
        const s = led && (!showLeds) ? 0 : 1;
        const o = 16 * j;
        m[o] = (1 - 2 * (y * y + z * z)) * s; m[o + 1] = 2 * (x * y + z * w) * s; m[o + 2] = 2 * (x * z - y * w) * s; m[o + 3] = 0;
        m[o + 4] = 2 * (x * y - z * w) * s; m[o + 5] = (1 - 2 * (x * x + z * z)) * s; m[o + 6] = 2 * (y * z + x * w) * s; m[o + 7] = 0;
        m[o + 8] = 2 * (x * z + y * w) * s; m[o + 9] = 2 * (y * z - x * w) * s; m[o + 10] = (1 - 2 * (x * x + y * y)) * s; m[o + 11] = 0;
        m[o + 12] = P[3 * id]; m[o + 13] = P[3 * id + 1]; m[o + 14] = P[3 * id + 2]; m[o + 15] = 1;
        // sRGB bytes to the linear colours three works in; an LED that is off
        // is dim; a mesh in its own colours keeps them (white instances).
        if (own) continue;
        const dim = led && rgba[4 * id + 3] === 0 ? 0.12 : 1;
        for (let k = 0; k < 3; ++k) {
          const v = rgba[4 * id + k] / 255;
          c[3 * j + k] = dim * (v <= 0.04045 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4));
        }
      }
      mesh.instanceMatrix.needsUpdate = true;
      mesh.instanceColor.needsUpdate = true;
    }
    if (this.show.rays) this.updateRays();
    if (this.paintMesh) {
      this.paintMesh.visible = this.show.paint;
      if (this.state.changedPaint) { this.paintTexture.needsUpdate = true; this.state.changedPaint = false; }
    }
    this.updateTrails();
    this.updateLinks();
    if (this.followRobot >= 0) this.follow();
    this.dirty = true;
  }

  updatePoints(points) {
    const ids = points.userData.ids, led = points.userData.led, P = this.worldPos, rgba = this.state.rgba;
    const pos = points.geometry.attributes.position.array, c = points.geometry.attributes.color.array;
    points.visible = !led || this.show.leds;
    for (let j = 0; j < ids.length; ++j) {
      const id = ids[j];
      // LEDs a little above the bodies, so they show from above.
      pos[3 * j] = P[3 * id]; pos[3 * j + 1] = P[3 * id + 1]; pos[3 * j + 2] = P[3 * id + 2] + (led ? 0.05 : 0);
      const dim = led && rgba[4 * id + 3] === 0 ? 0.12 : 1;
      for (let k = 0; k < 3; ++k) {
        const v = rgba[4 * id + k] / 255;
        c[3 * j + k] = dim * (v <= 0.04045 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4));
      }
    }
    points.geometry.attributes.position.needsUpdate = true;
    points.geometry.attributes.color.needsUpdate = true;
  }

  updateRays() {
    const objects = this.sceneInfo.objects, P = this.worldPos, Q = this.worldQuat, prox = this.state.prox;
    const rgba = this.state.rgba, srgb = (v) => (v <= 0.04045 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4));
    const pos = this.rays.geometry.attributes.position.array, col = this.rays.geometry.attributes.color.array;
    for (let j = 0; j < this.sensorIds.length; ++j) {
      const id = this.sensorIds[j], range = objects[id].range || 0;
      const reading = prox[id];
      const length = reading === NO_DETECTION ? range : reading / 65534 * range;
      // The sensor's +z axis in the world.
      const x = Q[4 * id], y = Q[4 * id + 1], z = Q[4 * id + 2], w = Q[4 * id + 3];
      const dx = 2 * (x * z + y * w), dy = 2 * (y * z - x * w), dz = 1 - 2 * (x * x + y * y);
      pos.set([P[3 * id], P[3 * id + 1], P[3 * id + 2],
        P[3 * id] + dx * length, P[3 * id + 1] + dy * length, P[3 * id + 2] + dz * length], 6 * j);
      if (this.rayColors) {
        // Its colour as its type declares it (format 1.1), linear as three works.
        const r = srgb(rgba[4 * id] / 255), g = srgb(rgba[4 * id + 1] / 255), b = srgb(rgba[4 * id + 2] / 255);
        col.set([r, g, b, r, g, b], 6 * j);
      } else {
        // Format 1.0: red while it detects something, else blue.
        const hit = reading !== NO_DETECTION;
        col.set(hit ? [1, 0.2, 0.2, 1, 0.2, 0.2] : [0.3, 0.8, 1, 0.3, 0.8, 1], 6 * j);
      }
    }
    this.rays.geometry.attributes.position.needsUpdate = true;
    this.rays.geometry.attributes.color.needsUpdate = true;
  }

  // Trails: the last trailLength positions of every robot, reset on a jump.
  updateTrails() {
    const record = this.state.record, roots = this.robotRoots, P = this.worldPos;
    if (record !== this.trailRecord + 1) { this.trailCount = 0; this.trailHead = 0; }
    this.trailRecord = record;
    const t = this.trailPoints, L = this.trailLength;
    for (let r = 0; r < roots.length; ++r) {
      const o = 3 * (r * L + this.trailHead);
      t[o] = P[3 * roots[r]]; t[o + 1] = P[3 * roots[r] + 1]; t[o + 2] = P[3 * roots[r] + 2] + 0.002;
    }
    this.trailHead = (this.trailHead + 1) % L;
    this.trailCount = Math.min(this.trailCount + 1, L);
    if (!this.show.trails) return;
    const out = this.trails.geometry.attributes.position.array;
    let k = 0;
    for (let r = 0; r < roots.length; ++r) {
      for (let i = 0; i + 1 < this.trailCount; ++i) {
        const a = (this.trailHead - this.trailCount + i + 2 * L) % L, b = (a + 1) % L;
        const oa = 3 * (r * L + a), ob = 3 * (r * L + b);
        out[k++] = t[oa]; out[k++] = t[oa + 1]; out[k++] = t[oa + 2];
        out[k++] = t[ob]; out[k++] = t[ob + 1]; out[k++] = t[ob + 2];
      }
    }
    this.trails.geometry.setDrawRange(0, k / 3);
    this.trails.geometry.attributes.position.needsUpdate = true;
  }

  setShow(what, on) {
    this.show[what] = on;
    if (what === 'rays') this.rays.visible = on;
    if (what === 'trails') this.trails.visible = on;
    if (this.state) this.update();
  }

  // Keeps the camera's target on robot `index`, the view's offset unchanged.
  follow() {
    const robot = this.sceneInfo.robotByIndex.get(this.followRobot);
    if (!robot) return;
    const id = robot.first, P = this.worldPos;
    const target = new THREE.Vector3(P[3 * id], P[3 * id + 1], P[3 * id + 2]);
    const offset = this.camera.position.clone().sub(this.controls.target);
    this.controls.target.copy(target);
    this.camera.position.copy(target).add(offset);
    this.controls.update();
  }

  // The robot index under the canvas pixel (x, y), or -1.
  pick(x, y) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2((x - rect.left) / rect.width * 2 - 1, -((y - rect.top) / rect.height) * 2 + 1);
    const raycaster = new THREE.Raycaster();
    raycaster.setFromCamera(ndc, this.camera);
    const pickable = this.groups.filter((g) => !g.userData.led);
    for (const mesh of pickable) {
      if (mesh.userData.points) {
        mesh.geometry.computeBoundingSphere();
        raycaster.params.Points.threshold = mesh.userData.radius;
      } else mesh.computeBoundingSphere();
    }
    const hits = raycaster.intersectObjects(pickable, false);
    for (const hit of hits) {
      const id = hit.object.userData.ids[hit.object.userData.points ? hit.index : hit.instanceId];
      const robot = this.sceneInfo.robotOf[id];
      if (robot >= 0) return robot;
    }
    return -1;
  }

  // Page pixel of world point (x, y, z).
  project(x, y, z) {
    const v = new THREE.Vector3(x, y, z).project(this.camera);
    const rect = this.renderer.domElement.getBoundingClientRect();
    return { x: rect.left + (v.x + 1) / 2 * rect.width, y: rect.top + (1 - v.y) / 2 * rect.height };
  }

  render() {
    this.controls.update();
    this.renderer.render(this.scene, this.camera);
    this.dirty = false;
  }
}
