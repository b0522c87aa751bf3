// The viewer page: loads the recording (from `swarmsim view`'s server,
// following a run in progress, or embedded in an exported file), plays it
// in the 3D view, and exposes window.swarmsimViewer for tests.
import { Recording, State } from './recording.js';
import { View3D, DEFAULT_MESH_BUDGET, SOFTWARE_MESH_BUDGET, softwareRenderer, triangleText } from './view3d.js';
import { drawPlot } from './plot.js';

const $ = (id) => document.getElementById(id);
const POLL_MS = 1000;

const viewer = {
  recording: new Recording(),
  state: null,
  view: null,
  record: 0,          // the step record shown
  position: 0,        // playback position in records (fractional while playing)
  playing: false,
  speed: 1,
  selected: -1,       // robot index
  metric: null,       // name id plotted
  live: false,        // following a growing file
  frameTimes: [],     // requestAnimationFrame timestamps while measuring
  sceneIndex: -1,
};

// The triangle budget of meshes (view3d.js): the page's `mesh_budget` URL
// parameter (2500000, 2.5M, 500k; 0: every mesh as its box), else
// `swarmsim view --mesh-budget N` (written into the page), else the default
// (a software renderer's is smaller). A value that is not a count is named
// in the status line and ignored.
function readMeshBudget() {
  const text = new URLSearchParams(window.location.search).get('mesh_budget');
  const fallback = Number.isInteger(window.swarmsimMeshBudget) && window.swarmsimMeshBudget >= 0
    ? window.swarmsimMeshBudget : softwareRenderer() ? SOFTWARE_MESH_BUDGET : DEFAULT_MESH_BUDGET;
  if (text === null) return fallback;
  const m = /^\s*(\d+(?:\.\d+)?(?:e\d+)?)\s*([kKmM]?)\s*$/.exec(text);
  if (!m) {
    viewer.budgetWarning = `mesh_budget '${text}' is not a triangle count (such as 2000000, 2M or 500k): using ${triangleText(fallback)}`;
    return fallback;
  }
  return Math.round(Number(m[1]) * ({ k: 1e3, m: 1e6 }[m[2].toLowerCase()] ?? 1));
}

function showError(message) {
  $('error').textContent = message;
  viewer.error = message;
}

function setStatus() {
  const r = viewer.recording;
  const parts = [`${r.header.world}`, `${viewer.state ? viewer.sceneInfo.robots.length : 0} robots`,
    `${r.records.length} steps recorded`];
  if (viewer.view?.bodiesOnly) parts.push('large swarm: bodies and LEDs only');
  if (viewer.view?.software) parts.push('software renderer');
  const mesh = viewer.view?.meshInfo;
  if (mesh?.triangles > mesh?.budget) {
    // Past the budget: simplified, or boxes where simplifying leaves too little.
    const how = mesh.asBoxes ? 'meshes as boxes'
      : `meshes simplified${mesh.boxes ? ` (${mesh.boxes} as boxes)` : ''} to ${triangleText(mesh.drawnTriangles)}`;
    parts.push(`${how}: ${triangleText(mesh.triangles)} triangles > budget ${triangleText(mesh.budget)} (?mesh_budget=N)`);
  } else if (mesh?.triangles) parts.push(`meshes: ${triangleText(mesh.triangles)} triangles`);
  if (viewer.budgetWarning) parts.push(viewer.budgetWarning);
  if (r.ended) parts.push(r.ended.status === 'ok' ? 'run complete' : `run ${r.ended.status}`);
  else if (viewer.live) parts.push('live: following the run');
  else parts.push('recording ends early (truncated)');
  $('status').textContent = parts.join(' · ');
}

// Shows step record `index` (clamped).
function show(index) {
  const r = viewer.recording;
  index = Math.max(0, Math.min(r.records.length - 1, index));
  const sceneIndex = r.records[index].scene;
  if (sceneIndex !== viewer.sceneIndex) {
    // A new scene (robots copied or removed): new state, new drawables.
    viewer.sceneIndex = sceneIndex;
    viewer.sceneInfo = r.scenes[sceneIndex].scene;
    viewer.state = new State(viewer.sceneInfo, r.header);
    viewer.view.build(r.header, viewer.sceneInfo, viewer.state);
    fillFollow();
  }
  r.seek(viewer.state, index);
  viewer.record = index;
  viewer.view.update();
  const step = r.records[index].step;
  $('timeline').max = String(r.records.length - 1);
  $('timeline').value = String(index);
  $('time').textContent = `step ${step} · ${(step * r.header.dt).toFixed(2)} s`;
  if (viewer.selected >= 0) showInfo(viewer.selected);
  plot();
}

function fillFollow() {
  const select = $('follow');
  const keep = select.value;
  select.length = 1;
  for (const robot of viewer.sceneInfo.robots.slice(0, 2000)) select.add(new Option(robot.name, String(robot.index)));
  select.value = keep;
}

function fillMetrics() {
  const select = $('metric');
  const names = viewer.recording.metricNames;
  if (select.length === names.length) return;
  const keep = select.value;
  select.length = 0;
  names.forEach((name, id) => select.add(new Option(name, String(id))));
  if (keep) select.value = keep;
  if (viewer.metric === null && names.length) viewer.metric = 0;
}

function plot() {
  const r = viewer.recording;
  const series = viewer.metric === null ? null : r.metricSeries.get(viewer.metric);
  const step = r.records[viewer.record]?.step;
  drawPlot($('plot'), series, step, r.metricNames.length ? 'reading metrics...' : 'no metric recorded');
  if (series) {
    let i = series.steps.length - 1;
    while (i > 0 && series.steps[i] > step) --i;
    const v = series.sum[i] / series.count[i];
    $('metric-value').textContent = `${series.swarm ? '' : 'mean over robots '}${v.toPrecision(5)} at step ${series.steps[i]}`;
  } else $('metric-value').textContent = '';
}

function escapeHtml(text) {
  return String(text).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]);
}

function showInfo(index) {
  viewer.selected = index;
  const robot = viewer.sceneInfo?.robotByIndex.get(index);
  if (!robot) { $('info').innerHTML = ''; return; }
  const rows = Object.entries(robot.parameters || {}).map(([k, v]) =>
    `<tr><td>${escapeHtml(k)}</td><td>${escapeHtml(JSON.stringify(v))}</td></tr>`).join('');
  const metrics = viewer.recording.lastMetrics(index, viewer.record).map((m) =>
    `<tr><td>${escapeHtml(m.name)}</td><td>${m.value.toPrecision(5)} <small>(step ${m.step})</small></td></tr>`).join('');
  $('info').innerHTML = `<h3 id="info-name">${escapeHtml(robot.name)}</h3>` +
    `<div>model ${escapeHtml(robot.model)} · robot ${robot.index}</div>` +
    (rows ? `<b>parameters</b><table>${rows}</table>` : '') +
    (metrics ? `<b>last metrics</b><table>${metrics}</table>` : '');
}

function setPlaying(on) {
  viewer.playing = on;
  $('play').innerHTML = on ? '&#10074;&#10074;' : '&#9654;';
  if (on && viewer.record >= viewer.recording.records.length - 1 && !viewer.live) viewer.position = 0;
  else viewer.position = viewer.record;
}

// One animation frame: advance playback, draw if anything changed.
let lastFrame = null;
function frame(now) {
  requestAnimationFrame(frame);
  if (viewer.measuring) viewer.frameTimes.push(now);
  const r = viewer.recording;
  if (viewer.playing && r.records.length) {
    const dt = lastFrame === null ? 0 : Math.min(0.25, (now - lastFrame) / 1000);
    const perRecord = r.header.dt * (r.header.record_every || 1);
    viewer.position += dt * viewer.speed / perRecord;
    const last = r.records.length - 1;
    if (viewer.position >= last) {
      viewer.position = last;
      if (r.ended || !viewer.live) setPlaying(false);
    }
    if (Math.floor(viewer.position) !== viewer.record) show(Math.floor(viewer.position));
  }
  lastFrame = now;
  if (viewer.view.dirty || viewer.playing || viewer.measuring) viewer.view.render();
}

// Reads the metrics a few records at a time, between frames.
function readMetricsSlowly() {
  const more = viewer.recording.readMetrics(20);
  fillMetrics();
  plot();
  if (more) setTimeout(readMetricsSlowly, 0);
  else viewer.metricsRead = true;
}

function wireControls() {
  $('play').onclick = () => setPlaying(!viewer.playing);
  $('step').onclick = () => { setPlaying(false); show(viewer.record + 1); };
  $('step-back').onclick = () => { setPlaying(false); show(viewer.record - 1); };
  $('timeline').oninput = (e) => { viewer.position = Number(e.target.value); show(viewer.position); };
  $('speed').onchange = (e) => { viewer.speed = Number(e.target.value); };
  $('metric').onchange = (e) => { viewer.metric = Number(e.target.value); plot(); };
  $('follow').onchange = (e) => {
    viewer.view.followRobot = e.target.value === '' ? -1 : Number(e.target.value);
    viewer.view.update();
  };
  for (const what of ['rays', 'leds', 'trails', 'paint', 'links']) {
    const box = $(`show-${what}`);
    viewer.view.show[what] = box.checked;
    box.onchange = () => viewer.view.setShow(what, box.checked);
  }
  window.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT' && e.target.type !== 'range') return;
    if (e.key === ' ') { setPlaying(!viewer.playing); e.preventDefault(); }
    else if (e.key === '.') { setPlaying(false); show(viewer.record + 1); }
    else if (e.key === ',') { setPlaying(false); show(viewer.record - 1); }
  });
  // A click (not a drag) on a robot shows what it is.
  const canvas = viewer.view.renderer.domElement;
  let down = null;
  canvas.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
  canvas.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
    const robot = viewer.view.pick(e.clientX, e.clientY);
    if (robot >= 0) showInfo(robot);
    else { viewer.selected = -1; $('info').innerHTML = ''; }
  });
}

function base64Bytes(text) {
  const binary = atob(text.replace(/\s+/g, ''));
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

// Fetches the file from the recording's end on (the server answers at most
// 64 MB at a time); true when bytes came.
async function fetchMore() {
  let any = false;
  for (;;) {
    const from = viewer.recording.bytesRead + viewer.recording.pending.length;
    const response = await fetch(`recording.swrec?from=${from}`, { cache: 'no-store' });
    if (!response.ok) throw new Error(`the server answered ${response.status} for recording.swrec`);
    const bytes = new Uint8Array(await response.arrayBuffer());
    if (bytes.length) { viewer.recording.append(bytes); any = true; }
    const size = Number(response.headers.get('X-Swarmsim-Size'));
    if (!bytes.length || from + bytes.length >= size) return any;
  }
}

async function poll() {
  try {
    const r = viewer.recording;
    const before = r.records.length;
    await fetchMore();
    if (!viewer.started) {
      if (r.records.length) start();
      else $('status').textContent = 'waiting for the run to record its first step...';
    } else if (r.records.length > before) {
      // Following: stay on the newest step unless the user went back.
      const wasAtEnd = viewer.record >= before - 1;
      if (wasAtEnd && !viewer.playing) show(r.records.length - 1);
      else show(viewer.record);
      fillMetrics();
      if (viewer.metricsRead) { viewer.metricsRead = false; readMetricsSlowly(); }
    }
    if (viewer.started) setStatus();
    if (!r.ended) setTimeout(poll, POLL_MS);
    else viewer.live = false;
  } catch (e) {
    showError(`swarmsim view: ${e.message}`);
  }
}

// The first whole step is here: draw it and start the clock.
function start() {
  const r = viewer.recording;
  viewer.started = true;
  const robots = r.scenes[r.scenes.length - 1].scene.robots.length;
  viewer.view = new View3D($('view'), robots > 2000, { meshBudget: readMeshBudget() });
  wireControls();
  show(viewer.live ? r.records.length - 1 : 0);
  viewer.view.frame(false);
  fillMetrics();
  setStatus();
  requestAnimationFrame(frame);
  viewer.loadMs = performance.now();
  viewer.ready = true;
  readMetricsSlowly();
}

async function main() {
  const embedded = document.getElementById('swarmsim-recording');
  if (embedded) viewer.recording.append(base64Bytes(embedded.textContent));
  else await fetchMore();
  const r = viewer.recording;
  viewer.live = !embedded && !r.ended;
  if (r.records.length) start();
  else if (!viewer.live) throw new Error('the recording has no whole step');
  if (viewer.live) setTimeout(poll, viewer.started ? POLL_MS : 200);
}

// The test hook: read state, set the time, project world points to pixels.
window.swarmsimViewer = {
  get ready() { return !!viewer.ready; },
  get error() { return viewer.error || null; },
  get loadMs() { return viewer.loadMs; },
  get recordCount() { return viewer.recording.records.length; },
  get record() { return viewer.record; },
  get step() { return viewer.recording.records[viewer.record]?.step; },
  get live() { return viewer.live; },
  get ended() { return !!viewer.recording.ended; },
  get robotCount() { return viewer.sceneInfo?.robots.length || 0; },
  get view() { return viewer.view; },
  get status() { return $('status').textContent; },
  // The meshes drawn (view3d.js meshGroups) and their count against the budget.
  meshes() { return { groups: viewer.view.meshGroups(), ...viewer.view.meshInfo }; },
  get metricsRead() { return !!viewer.metricsRead; },  // for measurements
  setRecord(i) { setPlaying(false); show(i); viewer.view.render(); return viewer.record; },
  // World position [x, y, z] of robot `index` at the record shown.
  robotPosition(index) {
    const robot = viewer.sceneInfo.robotByIndex.get(index), P = viewer.view.worldPos;
    return [P[3 * robot.first], P[3 * robot.first + 1], P[3 * robot.first + 2]];
  },
  project(x, y, z) { viewer.view.render(); return viewer.view.project(x, y, z); },
  topDown() { viewer.view.frame(true); viewer.view.render(); },
  play(speed) { if (speed) viewer.speed = speed; setPlaying(true); },
  pause() { setPlaying(false); },
  selectedName() { return document.getElementById('info-name')?.textContent || null; },
  metricNames() { return [...viewer.recording.metricNames]; },
  // Frames per second over `ms` of playing, from requestAnimationFrame timestamps.
  measureFps(ms) {
    return new Promise((resolve) => {
      viewer.frameTimes = [];
      viewer.measuring = true;
      setTimeout(() => {
        viewer.measuring = false;
        const t = viewer.frameTimes;
        resolve(t.length > 1 ? (t.length - 1) * 1000 / (t[t.length - 1] - t[0]) : 0);
      }, ms);
    });
  },
};

main().catch((e) => showError(`swarmsim view: ${e.message}`));
