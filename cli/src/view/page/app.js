// trilux view: the page. Modes, pointer handling, the HUD; drawing is in
// gl.js, the camera in camera.js, the socket in net.js, the frames in
// protocol.js.
import { Renderer } from './gl.js';
import { Camera, normalize, cross, dot } from './camera.js';
import { Connection } from './net.js';
import { parseFrame, SURFACE, FINAL, ENVIRONMENT_UPLOAD } from './protocol.js';

const $ = (id) => document.getElementById(id);
const canvas = $('view'), overlay = $('overlay'), brush = $('brush');
const state = {
  mode: 'orbit', hello: null, status: null, camera: null, eta: 1.3, white: 1,
  // The server's default light (`view::builtin::DEFAULT_LIGHT`), replaced
  // by the lights hello carries.
  lightDir: [-0.351, 0.746, 0.565], pending: new Map(), errors: [], probes: [], exports: [],
  radianceFrames: 0, surfaceFrames: 0, answered: [], lastRadianceFinal: false, firstFrameAt: null,
  // The exposure's white: the server's first estimate (surface vertices),
  // then measured from the covered pixels as the CLI's PNGs are exposed.
  whiteFrom: 'vertices', covered: 0, measureWanted: false,
  // Environment maps: the server's stored name → the picked file's name.
  envNames: {}, uploadName: null,
};
window.trilux = state;

let renderer;
try { renderer = new Renderer(canvas); } catch (e) { $('status').textContent = String(e); throw e; }
state.renderer = renderer;

// On a new connection, edits sent on the old one get no answer: the
// hello's status shows what the server has.
const conn = new Connection('view', parseFrame, onText, onFrame, (s) => {
  $('status').textContent = s;
  if (s === 'connected') { state.pending.clear(); conn.send('hello'); }
});
state.conn = conn;
// The id of the drag in progress (a paint stroke, a light or piece drag):
// its many messages carry it, and the server undoes them as one step.
// Random, so that ids from before a reload never meet the new ones.
let gesture = null;
const GESTURE_OPS = new Set(['paint', 'lights', 'move']);
function send(op, fields) {
  if (gesture !== null && GESTURE_OPS.has(op)) fields = { ...fields, gesture };
  const seq = conn.send(op, fields);
  if (seq === null) { $('status').textContent = 'not connected to trilux view: that edit was not sent'; return null; }
  state.pending.set(seq, performance.now());
  return seq;
}

function onText(m) {
  if (m.type === 'hello') {
    state.hello = m; state.eta = m.eta; state.white = m.white;
    if (!state.camera) {
      state.camera = new Camera(m.bounds[0], m.bounds[1]);
      // A replayed session starts from the camera it was saved with.
      if (m.source && Array.isArray(m.source.view)) state.camera.lookFrom(m.source.view);
    }
    state.camera.bounds = m.bounds;
    const sel = $('material');
    if (!sel.options.length) for (const name of m.materials) sel.add(new Option(name, name, name === 'ketchup', name === 'ketchup'));
    const d = m.lights.find((l) => l.kind === 'dir');
    if (d) state.lightDir = d.dir;
    drawLight();
  } else if (m.type === 'status') {
    state.status = m;
    // The edits answered, in order (a refinement's status follows its edit's).
    if (m.edit !== 'refine' && m.edit !== 'hello') state.answered.push(m.edit);
    for (const s of m.seqs) state.pending.delete(s);
    if (m.offsets) m.offsets.forEach((o, k) => { if (renderer.pieces[k]) renderer.pieces[k].offset = o; });
    renderer.dropPiecesFrom(m.pieces);
    showStatus(m);
    showHistory(m.history);
    // The server's light after an undo, a redo or another tab's edit; the
    // page's own while it still has edits in flight (a drag's earlier
    // steps must not pull the light back).
    const dl = (m.lights || []).find((l) => l.kind === 'dir');
    if (dl && state.pending.size === 0 && !(drag && drag.kind === 'light')) { state.lightDir = dl.dir; drawLight(); }
    const env = (m.lights || []).find((l) => l.kind === 'env');
    state.environment = env ? env.file : null;
    // The server stores an upload under a name of its own (its content's
    // hash); the user recognises the name of the file they picked.
    if (env && state.uploadName && !state.envNames[env.file]) { state.envNames[env.file] = state.uploadName; state.uploadName = null; }
    $('envname').textContent = env ? `Environment: ${state.envNames[env.file] || env.file}` : 'No environment map';
  } else if (m.type === 'error') {
    state.errors.push(m);
    if (m.seq != null) state.pending.delete(m.seq);
    // A refused upload must not lend its name to the next environment.
    state.uploadName = null;
    if (m.exists && confirm(`${m.message}\nReplace it?`)) exportFile(state.lastExport, true);
    // Declining to replace a file is the user's choice, not an error; and
    // "op" (the edit itself, e.g. nothing to undo) names no field a user
    // set on the page.
    else if (m.exists) $('status').textContent = `not written (kept the existing file): ${m.message}`;
    else if (m.field === 'op') $('status').textContent = m.message;
    else $('status').textContent = `error in ${m.field}: ${m.message}`;
  } else if (m.type === 'probe') {
    state.probes.push(m);
    state.pending.delete(m.seq);
    const r = m.radiance.map((x) => x.toExponential(2)).join(', ');
    $('probe').textContent = `Probe: ${m.material}, radiance ${r}`;
  } else if (m.type === 'export') {
    state.exports.push(m);
    state.pending.delete(m.seq);
    $('status').textContent = `written ${m.path}`;
  }
}

function onFrame(f) {
  if (f.kind === SURFACE) {
    renderer.setSurface(f.piece, f.positions, f.normals, f.indices);
    state.surfaceFrames++;
  } else {
    if (renderer.setRadiance(f.piece, f.radiance)) {
      state.radianceFrames++;
      state.lastRadianceFinal = (f.flags & FINAL) !== 0;
      // Re-expose on a settled result (not on every coarse frame of a drag).
      if (state.firstFrameAt === null || state.lastRadianceFinal) state.measureWanted = true;
      if (state.firstFrameAt === null) state.firstFrameAt = performance.now();
    }
  }
  if (state.status && state.status.offsets) state.status.offsets.forEach((o, k) => { if (renderer.pieces[k]) renderer.pieces[k].offset = o; });
}

// The HUD names what happened in words, not the protocol's op names; a
// coarse solve is the edit's first result (a refinement follows).
const EDIT_LABELS = {
  hello: 'loaded', refine: 'refined', cut: 'cut', fracture: 'fractured', paint: 'painted',
  material: 'material filled', lights: 'relit', move: 'moved', recombine: 'recombined',
  undo: 'undone', redo: 'redone',
};
function statusText(m) {
  const solves = m.solves.map((s) => `${s.levels} levels, ${s.iterations.join('/')} iterations`).join('; ');
  const tets = m.tets.reduce((a, b) => a + b, 0);
  const label = EDIT_LABELS[m.edit] || m.edit;
  return `${label}${m.coarse ? ' (first result)' : ''}: ${m.wall_ms.toFixed(0)} ms wall, ${m.cpu_ms.toFixed(0)} ms CPU` +
    (solves ? `; solve ${solves}` : '') + ` | ${tets} tets, ${m.pieces} piece${m.pieces > 1 ? 's' : ''}`;
}
function showStatus(m) { $('status').textContent = statusText(m); }

function showHistory(h) {
  const ol = $('history');
  ol.innerHTML = '';
  for (const n of h.done) { const li = document.createElement('li'); li.textContent = n; ol.append(li); }
  for (const n of h.redo.slice().reverse()) { const li = document.createElement('li'); li.textContent = n; li.className = 'redo'; ol.append(li); }
}

// The busy indicator: an edit unanswered for more than 1 s.
setInterval(() => {
  let oldest = Infinity;
  for (const t of state.pending.values()) oldest = Math.min(oldest, t);
  const s = (performance.now() - oldest) / 1000;
  $('busy').textContent = s > 10 ? `working… ${s.toFixed(0)} s` : s > 1 ? 'working…' : '';
}, 250);

function frame() {
  if (state.camera) {
    const ld = normalize(state.lightDir);
    const opts = {
      eta: state.eta, exposure: 1,
      lightDir: ld, lightRgb: [+$('intensity').value, +$('intensity').value, +$('intensity').value],
      specular: $('specular').checked,
    };
    if (state.measureWanted && $('autoexp').checked) {
      const m = renderer.measureWhite(state.camera, opts);
      if (m) { state.white = m.white; state.covered = m.covered; state.whiteFrom = 'pixels'; }
    }
    state.measureWanted = false;
    opts.exposure = Math.pow(2, +$('ev').value) / state.white;
    renderer.draw(state.camera, opts);
  }
  requestAnimationFrame(frame);
}
const reexpose = () => { state.measureWanted = true; };
// The exposure slider's value beside its label, as photographers read it.
function showEv() {
  const v = +$('ev').value;
  $('evval').textContent = `${v < 0 ? '−' : '+'}${Math.abs(v).toFixed(Number.isInteger(v * 2) ? 1 : 2)} EV`;
}
$('ev').addEventListener('input', showEv);
showEv();
requestAnimationFrame(frame);

// Modes.
function setMode(mode) {
  state.mode = mode;
  for (const b of document.querySelectorAll('#modes button')) b.classList.toggle('on', b.dataset.mode === mode);
  for (const s of document.querySelectorAll('#panel section[data-for]')) s.classList.toggle('shown', s.dataset.for === mode);
  brush.style.display = 'none';
  overlay.innerHTML = '';
  if (mode === 'plane') drawPlane();
  if (mode === 'light') drawLight();
}

// Where the directional light is, in light mode: a sun at the point of
// the view a drag to it would put the light (filled in front of the
// object, hollow behind it), joined to the centre. Without it a user
// drags blind: a translucent object's shading changes only softly.
function drawLight() {
  if (state.mode !== 'light' || !state.camera) return;
  const [w, h] = size();
  const ld = normalize(state.lightDir);
  const { f, r, u } = state.camera.basis();
  const x = (dot(ld, r) + 1) / 2 * w, y = (1 - dot(ld, u)) / 2 * h;
  const fill = dot(ld, f) <= 0 ? '#fc6' : 'none';
  overlay.innerHTML = `<line x1="${w / 2}" y1="${h / 2}" x2="${x}" y2="${y}" stroke="#fc6" stroke-width="1" stroke-dasharray="4 4"/>` +
    `<circle id="sun" cx="${x}" cy="${y}" r="9" fill="${fill}" stroke="#fc6" stroke-width="2"/>`;
}
for (const b of document.querySelectorAll('#modes button')) b.onclick = () => setMode(b.dataset.mode);
setMode('orbit');

const size = () => [canvas.clientWidth, canvas.clientHeight];
function hit(x, y) {
  if (!state.camera) return null;
  const [w, h] = size();
  const { o, d } = state.camera.ray(x, y, w, h);
  return renderer.pick(o, d);
}
const objectSize = () => state.camera ? state.camera.radius * 2 : 1;
const sigma = () => +$('radius').value * objectSize();

function lights() {
  const I = +$('intensity').value;
  const out = [{ kind: 'dir', dir: normalize(state.lightDir), rgb: [I, I, I] }];
  if ($('point').checked && state.camera) {
    const d = 2 * state.camera.radius;
    const unit = state.hello ? state.hello.unit_mm : 1;
    const p = state.camera.target.map((t, i) => t + normalize(state.lightDir)[i] * d);
    const q = I * Math.pow(d * unit, 2);
    out.push({ kind: 'point', pos: p, rgb: [q, q, q] });
  }
  return out;
}

// Pointer handling: one pointer orbits/edits, two pan and pinch-zoom.
const pointers = new Map();
let drag = null, lastSend = 0, pinch = null;
function svgLine(points, color) {
  overlay.innerHTML = `<polyline points="${points.map((p) => p.join(',')).join(' ')}" fill="none" stroke="${color}" stroke-width="2"/>`;
}

canvas.addEventListener('pointerdown', (e) => {
  canvas.setPointerCapture(e.pointerId);
  pointers.set(e.pointerId, [e.clientX, e.clientY]);
  if (pointers.size === 2) { const [a, b] = [...pointers.values()]; pinch = { d: Math.hypot(a[0] - b[0], a[1] - b[1]), c: [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2] }; drag = null; gesture = null; return; }
  const orbit = state.mode === 'orbit' || e.button === 1 || e.altKey || e.button === 2 || e.shiftKey && state.mode === 'orbit';
  drag = { x: e.clientX, y: e.clientY, kind: orbit ? (e.button === 2 || e.shiftKey ? 'pan' : 'orbit') : state.mode, points: [[e.clientX, e.clientY]] };
  gesture = ['paint', 'light', 'move'].includes(drag.kind) ? Math.floor(Math.random() * 2 ** 52) : null;
  if (drag.kind === 'paint') paintAt(e.clientX, e.clientY, true);
  if (drag.kind === 'move') { const h = hit(e.clientX, e.clientY); drag.piece = h ? h.piece : null; drag.start = h ? [...renderer.pieces[h.piece].offset] : null; }
});
canvas.addEventListener('contextmenu', (e) => e.preventDefault());
canvas.addEventListener('pointermove', (e) => {
  if (pointers.has(e.pointerId)) pointers.set(e.pointerId, [e.clientX, e.clientY]);
  if (pinch && pointers.size === 2) {
    const [a, b] = [...pointers.values()];
    const d = Math.hypot(a[0] - b[0], a[1] - b[1]), c = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
    state.camera.zoom(pinch.d / d);
    state.camera.pan(c[0] - pinch.c[0], c[1] - pinch.c[1], canvas.clientHeight);
    pinch = { d, c };
    return;
  }
  if (state.mode === 'paint') showBrush(e.clientX, e.clientY);
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  const now = performance.now();
  switch (drag.kind) {
    case 'orbit': state.camera.orbit(dx, dy); break;
    case 'pan': state.camera.pan(dx, dy, canvas.clientHeight); break;
    case 'cut': case 'fracture': drag.points.push([e.clientX, e.clientY]); svgLine(drag.points, drag.kind === 'cut' ? '#f66' : '#fc6'); break;
    case 'paint': paintAt(e.clientX, e.clientY, false); break;
    case 'light': {
      const [w, h] = size();
      let x = 2 * e.clientX / w - 1, y = 1 - 2 * e.clientY / h;
      const l = Math.hypot(x, y); if (l > 0.98) { x *= 0.98 / l; y *= 0.98 / l; }
      const { f, r, u } = state.camera.basis();
      const z = Math.sqrt(Math.max(0, 1 - x * x - y * y));
      state.lightDir = [0, 1, 2].map((i) => r[i] * x + u[i] * y - f[i] * z);
      if (now - lastSend > 30) { send('lights', { lights: lights() }); lastSend = now; }
      break;
    }
    case 'plane': {
      const n = parseVec($('pn').value) || [0, 0, 1];
      const { r, u } = state.camera.basis();
      const rot = (v, axis, a) => { const c = Math.cos(a), s = Math.sin(a), k = dot(axis, v), x = cross(axis, v); return [0, 1, 2].map((i) => v[i] * c + x[i] * s + axis[i] * k * (1 - c)); };
      const m = normalize(rot(rot(n, u, dx * 0.01), r, dy * 0.01));
      $('pn').value = m.map((x) => x.toFixed(3)).join(',');
      drawPlane();
      break;
    }
    case 'move': if (drag.piece != null && drag.start) {
      const { r, u } = state.camera.basis();
      const s = 2 * state.camera.distance * Math.tan(state.camera.fov / 2) / canvas.clientHeight;
      drag.start = [0, 1, 2].map((i) => drag.start[i] + (r[i] * dx - u[i] * dy) * s);
      renderer.pieces[drag.piece].offset = drag.start;
      if (now - lastSend > 30) { send('move', { piece: drag.piece, offset: drag.start }); lastSend = now; }
    } break;
  }
  // The light moved, or the view orbited under it (middle or Alt drag).
  if (state.mode === 'light') drawLight();
});
canvas.addEventListener('pointerup', (e) => {
  pointers.delete(e.pointerId);
  if (pointers.size < 2) pinch = null;
  if (!drag) { gesture = null; return; }
  const d = drag; drag = null;
  if (d.kind === 'orbit' || d.kind === 'pan' || d.kind === 'move') reexpose();
  if ((d.kind === 'cut' || d.kind === 'fracture') && d.points.length >= 2 && state.camera) {
    const [w, h] = size();
    const pts = d.points.map(([x, y]) => state.camera.onPlane(x, y, w, h));
    const view = state.camera.forward();
    if (d.kind === 'cut') send('cut', { stroke: { points: pts, view } });
    else {
      const a = pts[0], b = pts[pts.length - 1];
      const normal = normalize(cross([b[0] - a[0], b[1] - a[1], b[2] - a[2]], view));
      const h0 = hit(d.points[0][0], d.points[0][1]);
      send('fracture', { piece: h0 ? h0.piece : 0, point: a, normal });
    }
    setTimeout(() => { overlay.innerHTML = ''; }, 400);
  }
  if (d.kind === 'light') send('lights', { lights: lights() });
  if (d.kind === 'move' && d.piece != null && d.start) send('move', { piece: d.piece, offset: d.start });
  if (d.kind === 'paint') flushPaint();
  gesture = null;
});
let wheelTimer = null;
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  if (state.camera) state.camera.zoom(Math.exp(e.deltaY * 0.001));
  clearTimeout(wheelTimer); wheelTimer = setTimeout(reexpose, 200);
}, { passive: false });
window.addEventListener('resize', reexpose);
$('autoexp').onchange = reexpose;
$('specular').onchange = reexpose;

// Paint: dabs spaced by σ/2 along the stroke, sent every 30 ms.
let dabs = [], lastDab = null;
function paintAt(x, y, first) {
  const h = hit(x, y);
  if (!h) return;
  if (!first && lastDab && Math.hypot(...h.point.map((v, i) => v - lastDab[i])) < sigma() / 2) return;
  dabs.push(h.point); lastDab = h.point;
  if (performance.now() - lastSend > 30) flushPaint();
}
function flushPaint() {
  if (!dabs.length) return;
  send('paint', { material: $('material').value, radius: sigma(), strength: +$('strength').value, points: dabs });
  dabs = []; lastSend = performance.now();
}
let lastProbe = 0;
function showBrush(x, y) {
  const h = hit(x, y);
  if (!h) { brush.style.display = 'none'; return; }
  const dist = Math.hypot(...h.point.map((v, i) => v - state.camera.eye()[i]));
  const px = sigma() / (dist * Math.tan(state.camera.fov / 2)) * canvas.clientHeight / 2;
  Object.assign(brush.style, { display: 'block', left: `${x - px}px`, top: `${y - px}px`, width: `${2 * px}px`, height: `${2 * px}px` });
  if (performance.now() - lastProbe > 150) { send('probe', { piece: h.piece, point: h.point }); lastProbe = performance.now(); }
}

// The plane: numeric fields, a square outline as the gizmo.
function parseVec(s) { const v = s.split(',').map(Number); return v.length === 3 && v.every(Number.isFinite) && Math.hypot(...v) > 0 ? v : null; }
function planeSpec() {
  const n = normalize(parseVec($('pn').value) || [0, 0, 1]);
  const d = +$('pd').value || 0;
  const t = state.camera ? state.camera.target : [0, 0, 0];
  return { point: [0, 1, 2].map((i) => t[i] + n[i] * d), normal: n };
}
function drawPlane() {
  if (!state.camera || state.mode !== 'plane') return;
  const { point, normal } = planeSpec();
  let a = normalize(cross(normal, Math.abs(normal[1]) < 0.9 ? [0, 1, 0] : [1, 0, 0]));
  const b = cross(normal, a), R = state.camera.radius * 1.2;
  const [w, h] = size();
  const m = state.camera.viewProj(w / h);
  const project = (p) => { const x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12], y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13], ww = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15]; return [(x / ww + 1) * w / 2, (1 - y / ww) * h / 2]; };
  const corners = [[1, 1], [-1, 1], [-1, -1], [1, -1], [1, 1]].map(([s, t]) => project([0, 1, 2].map((i) => point[i] + R * (s * a[i] + t * b[i]))));
  const tip = project([0, 1, 2].map((i) => point[i] + normal[i] * R * 0.6)), base = project(point);
  overlay.innerHTML = `<polyline points="${corners.map((p) => p.join(',')).join(' ')}" fill="#6af2" stroke="#6af" stroke-width="1.5"/>` +
    `<line x1="${base[0]}" y1="${base[1]}" x2="${tip[0]}" y2="${tip[1]}" stroke="#f66" stroke-width="2"/>`;
}
$('pn').oninput = drawPlane; $('pd').oninput = drawPlane;
$('plane-cut').onclick = () => send('cut', { plane: planeSpec() });
$('plane-fracture').onclick = () => { const p = planeSpec(); send('fracture', { piece: 0, point: p.point, normal: p.normal }); };
const recombine = () => { if (renderer.pieces.length >= 2) send('recombine', { a: 0, b: 1 }); };
$('recombine').onclick = recombine; $('recombine2').onclick = recombine;
$('fill').onclick = () => send('material', { material: $('material').value });
$('undo').onclick = () => send('undo');
$('redo').onclick = () => send('redo');
$('point').onchange = () => send('lights', { lights: lights() });
$('intensity').onchange = () => send('lights', { lights: lights() });
$('help').onclick = () => { $('helpbox').hidden = !$('helpbox').hidden; };

// Environment maps: a Radiance .hdr from the file picker or dropped on the
// view, uploaded as one binary message (the server's limit in hello).
async function loadEnvironment(file) {
  if (file && !/\.hdr$/i.test(file.name)) { $('status').textContent = `${file.name}: an environment map is a Radiance .hdr file`; return; }
  const limit = state.hello ? state.hello.max_upload : 40 << 20;
  if (file && file.size + 16 > limit) { $('status').textContent = `${file.name}: ${file.size} bytes; at most ${limit - 16} may be uploaded`; return; }
  const bytes = file ? new Uint8Array(await file.arrayBuffer()) : new Uint8Array(0);
  state.uploadName = file ? file.name : null;
  const seq = conn.upload(ENVIRONMENT_UPLOAD, bytes);
  if (seq === null) { $('status').textContent = 'not connected to trilux view: the environment map was not sent'; return; }
  state.pending.set(seq, performance.now());
}
state.loadEnvironment = loadEnvironment;
$('envmap').onchange = (e) => { if (e.target.files[0]) loadEnvironment(e.target.files[0]); e.target.value = ''; };
$('envclear').onclick = () => loadEnvironment(null);
canvas.addEventListener('dragover', (e) => e.preventDefault());
canvas.addEventListener('drop', (e) => { e.preventDefault(); const f = e.dataTransfer.files[0]; if (f) loadEnvironment(f); });

function exportFile(kind, overwrite = false) {
  const ext = { png: 'png', exr: 'exr', vtu: 'vtu', glb: 'glb', tet: 'node', session: 'json' }[kind];
  const name = $('ename').value.replace(/[^A-Za-z0-9_.-]/g, '_').replace(/^\.+/, '') + '.' + ext;
  state.lastExport = kind;
  const view = state.camera ? normalize(state.camera.eye().map((v, i) => v - state.camera.target[i])) : undefined;
  send('export', { kind, name, size: +$('size').value, overwrite, view });
}
for (const b of document.querySelectorAll('[data-export]')) b.onclick = () => exportFile(b.dataset.export);

// A control of the panel, once used, gives the focus back: a focused
// <select> would take the next key (C for cut) as type-ahead and change
// the material, and the shortcuts below ignore keys aimed at controls.
for (const el of document.querySelectorAll('#panel select, #panel input[type=checkbox], #panel input[type=range]')) {
  el.addEventListener('change', () => el.blur());
}
window.addEventListener('keydown', (e) => {
  if (e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
  const k = e.key.toLowerCase();
  if ((e.ctrlKey || e.metaKey) && k === 'z') { e.preventDefault(); send(e.shiftKey ? 'redo' : 'undo'); return; }
  if ((e.ctrlKey || e.metaKey) && k === 'y') { e.preventDefault(); send('redo'); return; }
  // The letter shortcuts are for the plain keys: Ctrl+C (copy) must not
  // switch to cut, nor Ctrl+R (reload) recombine the pieces. ? [ ] may
  // need AltGr or Option on some keyboards, so they are not filtered.
  const plain = !(e.ctrlKey || e.metaKey || e.altKey);
  const modes = { o: 'orbit', c: 'cut', x: 'plane', p: 'paint', l: 'light', f: 'fracture', m: 'move' };
  if (plain && modes[k]) setMode(modes[k]);
  else if (e.key === '?') $('helpbox').hidden = !$('helpbox').hidden;
  else if (e.key === 'Escape') $('helpbox').hidden = true;
  else if (plain && k === 's') { $('specular').checked = !$('specular').checked; reexpose(); }
  else if (plain && k === 'r') recombine();
  else if (plain && k === 'e') exportFile('png');
  else if (e.key === '[') $('radius').value = +$('radius').value * 0.8;
  else if (e.key === ']') $('radius').value = +$('radius').value * 1.25;
});
