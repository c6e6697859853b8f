// trilux paint's page: the camera and the brush run here at display rate;
// the colours live on the server, which sends back the texels a stroke
// changed. The mesh colours are drawn by the paper's real-time shader
// (meshcolors.js, Sec. 5.3).

import { Camera, cross, normalize } from './camera.js';
import { Connection } from './net.js';
import { readHeader } from './frame.js';
import { fitCanvas } from './glutil.js';
import { MeshColorsRenderer } from './meshcolors.js';
import { PointsLayer } from './points.js';

const $ = (id) => document.getElementById(id);
const canvas = $('view');
const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true });

// Everything the tests read is on window.trilux.
const state = window.trilux = {
  hello: null, status: null, camera: null, tool: 'paint', frames: 0, ready: false,
  mesh: null, layout: null, pendingFaces: null, picked: null, errors: [], exported: [],
  // The scatter: points and strands shown, frames received, and when the
  // last points frame was drawn (performance.now(); tests time a stroke).
  points: 0, strands: 0, scatterFrames: 0, pointsDrawnAt: 0,
};
const renderer = gl ? new MeshColorsRenderer(gl) : null;
const layer = gl ? new PointsLayer(gl) : null;
let pointsPending = false;
let dirty = true;
let pickDirty = true;

// ---- the connection ---------------------------------------------------

function decode(buffer) {
  const h = readHeader(buffer, 'TLXM', 1);
  return { ...h, payload: buffer.slice(16) };
}

const net = new Connection('paint', decode, onText, onFrame, (s) => { $('busy').textContent = s === 'connected' ? '' : s; });

function onText(m) {
  if (m.type === 'hello') {
    state.hello = m;
    if (!state.camera) state.camera = new Camera(m.bounds[0], m.bounds[1]);
    fillChannels(m.channels);
    fillLevels(m.max_level);
    fillScatter(m);
    if (m.autosave) {
      $('autosaveNote').textContent = 'Autosave: ' + m.autosave + ' (every few strokes and when trilux paint stops)';
      $('autosaveHelp').textContent = ', to ' + m.autosave;
    }
    // Colours an earlier session autosaved (a crash, or never resumed):
    // kept, and how to resume them.
    const earlier = m.earlier_autosaves || [];
    if (earlier.length) {
      const newest = earlier[earlier.length - 1];
      $('earlierNote').textContent = 'An earlier session of this model autosaved colours to ' + newest +
        (earlier.length > 1 ? ' (and ' + (earlier.length - 1) + ' older)' : '') +
        '. They are kept; to resume them, restart with: trilux paint MESH --colors ' + newest;
      $('earlierNote').hidden = false;
    }
  } else if (m.type === 'status') {
    state.status = m;
    // A page that connects to a server already scattering shows how.
    if (!state.scatterShown) { state.scatterShown = true; showScatter(scatterInEffect()); }
    showStatus(m);
    // The global resolution offers the finest level now in use.
    if (!state.levelSet) { $('level').value = m.finest_level; state.levelSet = true; }
  } else if (m.type === 'pick') {
    state.picked = m.color;
    if (state.channelIndex() === 0) $('color').value = toHex(m.color);
    else $('value').value = m.color[2 + state.channelIndex()];
    if (state.tool === 'pick') setTool(state.beforePick || 'paint');
  } else if (m.type === 'export') {
    state.exported.push(m.path);
    flash('written: ' + m.path);
  } else if (m.type === 'error') {
    state.errors.push(m);
    // A refused scatter request changed nothing: the panel shows again
    // what the server has (the last status says).
    if (m.seq !== undefined && m.seq === state.scatterSeq) showScatter(scatterInEffect());
    if (m.exists && pendingExport && confirm(m.message + '. Replace it?')) pendingExport(true);
    else flash(m.field + ': ' + m.message);
  }
}

function onFrame(f) {
  if (f.kind === 1) {
    const positions = new Float32Array(f.payload, 0, 3 * f.a);
    const triangles = new Uint32Array(f.payload, 12 * f.a, 3 * f.b);
    state.mesh = { positions, triangles };
    renderer.setMesh(positions, triangles);
  } else if (f.kind === 2) {
    state.pendingFaces = new Uint32Array(f.payload);
  } else if (f.kind === 3) {
    // The rows in use; the texture has f.b rows (the rest spare zeros).
    state.layout = { width: f.a, rows: f.b, channels: state.hello.channels.length + 2, samples: new Float32Array(f.payload), faces: state.pendingFaces };
    renderer.setLayout(state.layout);
  } else if (f.kind === 4) {
    renderer.updateRects({ resized: false, samples: readRects(f, f.a, 0, Float32Array).rects, faces: [] }, null);
  } else if (f.kind === 7) {
    // A resolution change that fitted the textures: both tables' runs,
    // applied together so no frame draws new faces over old samples.
    const samples = readRects(f, f.a, 0, Float32Array);
    const faces = readRects(f, f.b, samples.end, Uint32Array);
    renderer.updateRects({ resized: false, samples: samples.rects, faces: faces.rects }, null);
  } else if (f.kind === 5) {
    layer.setPoints(new Float32Array(f.payload, 0, 3 * f.a));
    // A points frame without strands after it clears the old ones.
    layer.setStrands(new Float32Array(0), 0);
    state.points = f.a; state.strands = 0; state.scatterFrames++;
    state.pointsArrivedAt = performance.now();
    pointsPending = true;
  } else if (f.kind === 6) {
    layer.setStrands(new Float32Array(f.payload, 0, 3 * f.a * f.b), f.b);
    state.strands = f.a;
  }
  dirty = true;
}

// Kinds 4 and 7: `count` rectangles from byte `at`, each x, y, w, h
// (u32) then its w·h RGBA texels (`Type`: Float32Array for the samples,
// Uint32Array for the face table). Returns them and where they end.
function readRects(f, count, at, Type) {
  const rects = [];
  const v = new DataView(f.payload);
  for (let i = 0; i < count; i++) {
    const [x, y, width, height] = [0, 1, 2, 3].map((k) => v.getUint32(at + 4 * k, true));
    at += 16;
    rects.push({ x, y, width, height, data: new Type(f.payload.slice(at, at + 16 * width * height)) });
    at += 16 * width * height;
  }
  return { rects, end: at };
}

// ---- the panel --------------------------------------------------------

function fillChannels(channels) {
  const sel = $('channel');
  if (sel.options.length) return;
  channels.forEach((c, k) => sel.add(new Option(c, k)));
}
state.channelIndex = () => Number($('channel').value || 0);

function fillLevels(max) {
  const sel = $('level');
  if (sel.options.length) return;
  for (let l = 0; l <= max; l++) sel.add(new Option(`${1 << l} (level ${l})`, l));
}

function showStatus(s) {
  const mb = (b) => (b / 1048576).toFixed(1) + ' MB';
  const scatter = $('scatterMode').value === 'off' ? '' : ` · ${s.points.toLocaleString()} points` +
    (s.strands ? ` (${s.strands.toLocaleString()} strands shown)` : '') + ` in ${s.scatter_ms.toFixed(1)} ms`;
  $('stats').textContent = `${s.samples.toLocaleString()} samples · ${mb(s.memory)} · finest level ${s.finest_level}` +
    ` · undo ${s.undo} · redo ${s.redo} (history ${mb(s.undo_memory)})` + scatter;
  // A detail change (or its undo) shows little on screen at first: say
  // what it did to the sample count.
  if (state.samples !== undefined && s.samples !== state.samples) {
    const d = s.samples - state.samples;
    flash(`samples ${state.samples.toLocaleString()} → ${s.samples.toLocaleString()} ` +
      `(${d > 0 ? '+' : '−'}${Math.abs(d).toLocaleString()})`);
  }
  state.samples = s.samples;
  const list = $('history');
  list.textContent = '';
  s.history.forEach((h, k) => {
    const li = document.createElement('li');
    li.textContent = h;
    if (k >= s.undo) li.className = 'undone';
    list.appendChild(li);
  });
}

let flashTimer = 0;
function flash(text) {
  $('busy').textContent = text;
  clearTimeout(flashTimer);
  flashTimer = setTimeout(() => { $('busy').textContent = ''; }, 4000);
}

const srgbToLinear = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);
const linearToSrgb = (c) => (c <= 0.0031308 ? 12.92 * c : 1.055 * c ** (1 / 2.4) - 0.055);
function fromHex(hex) {
  return [1, 3, 5].map((i) => srgbToLinear(parseInt(hex.slice(i, i + 2), 16) / 255));
}
function toHex(rgb) {
  return '#' + rgb.slice(0, 3).map((c) => Math.round(255 * Math.min(1, Math.max(0, linearToSrgb(c))))
    .toString(16).padStart(2, '0')).join('');
}

// The brush message: mode, channel and values from the panel.
function brush(tool) {
  const k = state.channelIndex();
  const channel = k === 0 ? 'color' : state.hello.channels[k];
  const color = k === 0 ? fromHex($('color').value) : [Number($('value').value)];
  return {
    mode: tool === 'erase' ? 'erase' : $('blend').value, channel, color,
    strength: Number($('strength').value), hardness: Number($('hardness').value),
    mirror: $('mirror').checked, eye: $('seen').checked ? state.camera.eye() : null,
  };
}

function setTool(t) {
  // The eyedropper picks once, then hands back the tool it interrupted.
  if (t === 'pick' && state.tool !== 'pick') state.beforePick = state.tool;
  state.tool = t;
  document.querySelectorAll('#tools button').forEach((b) => b.classList.toggle('on', b.dataset.tool === t));
}
document.querySelectorAll('#tools button').forEach((b) => b.addEventListener('click', () => setTool(b.dataset.tool)));
setTool('paint');

// ---- picking ----------------------------------------------------------

// The pick pass is redrawn only when the camera moved: painting changes
// colours, not which face is under a pixel.
function pickAt(clientX, clientY) {
  if (!state.layout || !state.mesh) return null;
  const w = canvas.width, h = canvas.height;
  const x = Math.floor(clientX * w / canvas.clientWidth), y = h - 1 - Math.floor(clientY * h / canvas.clientHeight);
  if (x < 0 || y < 0 || x >= w || y >= h) return null;
  const t = renderer.pickFramebuffer(w, h);
  gl.bindFramebuffer(gl.FRAMEBUFFER, t.fb);
  if (pickDirty) {
    gl.viewport(0, 0, w, h);
    gl.clearBufferfv(gl.COLOR, 0, [-1, 0, 0, 0]);
    gl.clear(gl.DEPTH_BUFFER_BIT);
    renderer.drawPick(state.camera.viewProj(w / h));
    pickDirty = false;
  }
  const px = new Float32Array(4);
  gl.readBuffer(gl.COLOR_ATTACHMENT0);
  gl.readPixels(x, y, 1, 1, gl.RGBA, gl.FLOAT, px);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  if (px[0] < 0) return null;
  const face = Math.round(px[0]);
  const b = [px[1], px[2], px[3]];
  const s = b[0] + b[1] + b[2] || 1;
  const bary = b.map((v) => Math.max(0, v / s));
  const P = state.mesh.positions, T = state.mesh.triangles;
  const point = [0, 1, 2].map((c) => [0, 1, 2].reduce((acc, k) => acc + bary[k] * P[3 * T[3 * face + k] + c], 0));
  return { face, bary, point };
}

// The brush radius in model units at `point`: screen pixels converted at
// its depth, or the model-unit slider.
function worldRadius(point) {
  const r = Number($('radius').value);
  const cam = state.camera;
  if ($('worldRadius').checked) return r * cam.radius / 200;
  const e = cam.eye(), f = cam.forward();
  const depth = (point[0] - e[0]) * f[0] + (point[1] - e[1]) * f[1] + (point[2] - e[2]) * f[2];
  return r * 2 * depth * Math.tan(cam.fov / 2) / canvas.clientHeight;
}

// ---- strokes ----------------------------------------------------------

let drag = null;
state.pickAt = (x, y) => pickAt(x, y);

canvas.addEventListener('contextmenu', (e) => e.preventDefault());
canvas.addEventListener('pointerdown', (e) => {
  canvas.setPointerCapture(e.pointerId);
  if (e.button !== 0 || e.altKey) { drag = { kind: 'camera', x: e.clientX, y: e.clientY, pan: e.shiftKey }; return; }
  const hit = pickAt(e.clientX, e.clientY);
  if (!hit) { drag = { kind: 'camera', x: e.clientX, y: e.clientY, pan: e.shiftKey }; return; }
  const tool = state.tool;
  if (tool === 'pick') { net.send('pick', { face: hit.face, barycentric: hit.bary }); return; }
  if (tool === 'fill') { net.send('fill', { face: hit.face, brush: brush(tool) }); return; }
  if (tool === 'detail') {
    net.send('detail', { center: hit.point, radius: worldRadius(hit.point), levels: e.shiftKey ? -1 : 1 });
    return;
  }
  net.send('begin', { brush: brush(tool) });
  drag = { kind: 'stroke', x: e.clientX, y: e.clientY };
  net.send('dabs', { dabs: [dab(hit, e)] });
});

function dab(hit, e) {
  const pressure = e.pointerType === 'mouse' || !e.pressure ? 1 : Math.min(1, e.pressure);
  return [...hit.point, worldRadius(hit.point), pressure];
}

canvas.addEventListener('pointermove', (e) => {
  // The ring is hidden while the camera moves (each new view would need a
  // new pick pass per event) and comes back with the next move.
  state.pointer = { clientX: e.clientX, clientY: e.clientY };
  if (drag && drag.kind === 'camera') $('brush').style.display = 'none'; else showBrush(e);
  if (!drag) return;
  if (drag.kind === 'camera') {
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (drag.pan) state.camera.pan(dx, dy, canvas.clientHeight); else state.camera.orbit(dx, dy);
    drag.x = e.clientX; drag.y = e.clientY;
    dirty = pickDirty = true;
    return;
  }
  // Dabs every `spacing` of the radius along the pointer's path in
  // screen space, however fast it moves: no gaps.
  const step = Math.max(1, Number($('radius').value) * Number($('spacing').value));
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  const n = Math.floor(Math.hypot(dx, dy) / step);
  const dabs = [];
  for (let i = 1; i <= n; i++) {
    const x = drag.x + dx * i / n, y = drag.y + dy * i / n;
    const hit = pickAt(x, y);
    if (hit) dabs.push(dab(hit, e));
  }
  if (n > 0) { drag.x += dx; drag.y += dy; }
  if (dabs.length) net.send('dabs', { dabs });
});

function endDrag() {
  if (drag && drag.kind === 'stroke') net.send('end');
  drag = null;
}
canvas.addEventListener('pointerup', endDrag);
canvas.addEventListener('pointercancel', endDrag);
canvas.addEventListener('pointerleave', () => { $('brush').style.display = 'none'; state.pointer = null; });
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  $('brush').style.display = 'none';
  state.camera.zoom(Math.exp(e.deltaY * 0.001));
  dirty = pickDirty = true;
}, { passive: false });

// The brush ring lies on the surface: a circle of the brush's radius in
// the plane of the face under the cursor, projected as the camera sees it
// (as Blender's paint cursor), so it shows the area a dab covers even at
// a grazing angle. Off the model it is the screen circle of the radius.
function showBrush(e) {
  const el = $('brush');
  const world = $('worldRadius').checked;
  const r = Number($('radius').value);
  $('radiusText').textContent = world ? '' : r + ' px';
  if (state.tool === 'fill' || state.tool === 'pick' || !state.camera) { el.style.display = 'none'; return; }
  const hit = pickAt(e.clientX, e.clientY);
  const ring = hit ? surfaceRing(hit) : (world ? null : screenRing(e.clientX, e.clientY, r));
  if (!ring) { el.style.display = 'none'; return; }
  el.firstElementChild.setAttribute('points', ring.map((p) => p[0].toFixed(1) + ',' + p[1].toFixed(1)).join(' '));
  el.style.display = 'block';
}

const RING_POINTS = 64;

function screenRing(x, y, r) {
  return Array.from({ length: RING_POINTS + 1 }, (_, k) => {
    const t = 2 * Math.PI * k / RING_POINTS;
    return [x + r * Math.cos(t), y + r * Math.sin(t)];
  });
}

// The circle of radius worldRadius(point) around the hit point in its
// face's plane, in CSS pixels; null if a point falls behind the camera.
function surfaceRing(hit) {
  const P = state.mesh.positions, T = state.mesh.triangles;
  const v = [0, 1, 2].map((k) => [0, 1, 2].map((c) => P[3 * T[3 * hit.face + k] + c]));
  const sub = (a, b) => a.map((x, c) => x - b[c]);
  const n = normalize(cross(sub(v[1], v[0]), sub(v[2], v[0])));
  // Any unit vector in the plane, then its perpendicular.
  const helper = Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
  const u = normalize(cross(n, helper)), w = cross(n, u);
  const r = worldRadius(hit.point);
  const m = state.camera.viewProj(canvas.clientWidth / canvas.clientHeight);
  const ring = [];
  for (let k = 0; k <= RING_POINTS; k++) {
    const t = 2 * Math.PI * k / RING_POINTS, c = Math.cos(t) * r, s = Math.sin(t) * r;
    const p = [0, 1, 2].map((i) => hit.point[i] + c * u[i] + s * w[i]);
    const clip = [0, 1, 3].map((j) => m[j] * p[0] + m[4 + j] * p[1] + m[8 + j] * p[2] + m[12 + j]);
    if (clip[2] <= 1e-9) return null;
    ring.push([(clip[0] / clip[2] + 1) / 2 * canvas.clientWidth, (1 - clip[1] / clip[2]) / 2 * canvas.clientHeight]);
  }
  return ring;
}

// ---- the scatter panel ------------------------------------------------

// The channels a density can come from; the first scalar channel (say
// "density") is chosen, and the rate gives 100,000 points where value 1
// covers the whole model.
function fillScatter(hello) {
  const sel = $('scatterChannel'), len = $('hairChannel');
  if (sel.options.length) return;
  hello.channels.forEach((c, k) => {
    sel.add(new Option(k === 0 ? 'color (its brightness)' : c, c));
    if (k > 0) len.add(new Option(c, c));
  });
  if (hello.channels.length > 1) sel.value = hello.channels[1];
  state.area = hello.area;
  $('rate').value = Number((1e5 / Math.max(hello.area, 1e-30)).toPrecision(3));
  showRate();
}

function showRate() {
  const full = Number($('rate').value) * (state.area || 0);
  $('rateText').textContent = full > 0 ? `(${Math.round(full).toLocaleString()} if painted everywhere)` : '';
}

function diagonal() {
  const [lo, hi] = state.hello.bounds;
  return Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

// The scatter request the panel describes.
// The boxes' numbers go as typed: the server refuses what it cannot take
// (a count of 0 or 1.5, a negative seed) with a message, and the panel
// then shows again what is in effect.
function scatterRequest() {
  const mode = $('scatterMode').value;
  const req = { mode, channel: $('scatterChannel').value, seed: Number($('seed').value) };
  if (mode === 'rate') req.rate = Number($('rate').value);
  if (mode === 'count' || mode === 'blue_noise') req.count = Number($('count').value);
  req.hair = $('hair').checked ? {
    length: Number($('hairLength').value) * diagonal(),
    segments: Number($('hairSegments').value),
    length_channel: $('hairChannel').value || null,
  } : null;
  return req;
}

// The scatter request the server follows, by the last status.
function scatterInEffect() {
  const s = state.status && state.status.scatter;
  return s || { mode: 'off', channel: $('scatterChannel').value, seed: 0, hair: null };
}

// Sets the panel to a scatter request (without sending it).
function showScatter(r) {
  $('scatterMode').value = r.mode; $('scatterChannel').value = r.channel; $('seed').value = r.seed;
  if (r.rate !== undefined) $('rate').value = r.rate;
  if (r.count !== undefined) $('count').value = r.count;
  $('hair').checked = !!r.hair;
  if (r.hair) {
    $('hairSegments').value = r.hair.segments;
    $('hairLength').value = r.hair.length / diagonal();
    $('hairChannel').value = r.hair.length_channel || '';
    $('hairLength').dispatchEvent(new Event('input'));
  }
  showScatterRows(); showRate();
}

function showScatterRows() {
  const mode = $('scatterMode').value, on = mode !== 'off';
  $('rateRow').hidden = mode !== 'rate';
  $('countRow').hidden = mode !== 'count' && mode !== 'blue_noise';
  for (const id of ['seedRow', 'hairRow', 'sizeRow', 'scatterButtons']) $(id).hidden = !on;
  $('hairBox').hidden = !on || !$('hair').checked;
}

// Typing in a number box waits for a pause; the rest sends at once.
let scatterTimer = 0;
function sendScatter() {
  showScatterRows(); showRate();
  clearTimeout(scatterTimer);
  scatterTimer = setTimeout(() => { if (state.hello) state.scatterSeq = net.send('scatter', scatterRequest()); }, 150);
}
state.scatter = (fields) => net.send('scatter', fields);
for (const id of ['scatterMode', 'scatterChannel', 'hair', 'hairChannel', 'hairLength']) $(id).addEventListener('change', sendScatter);
for (const id of ['rate', 'count', 'seed', 'hairSegments']) $(id).addEventListener('input', sendScatter);
$('pointSize').addEventListener('input', () => { dirty = true; });

// Every slider shows its value beside it (the radius its own way).
document.querySelectorAll('#panel input[type=range]').forEach((r) => {
  if (r.id === 'radius') return;
  const v = document.createElement('span');
  v.className = 'value';
  const show = () => { v.textContent = Number(r.value).toFixed(r.step && Number(r.step) < 0.01 ? 3 : 2).replace(/\.?0+$/, ''); };
  r.after(v);
  r.addEventListener('input', show);
  show();
});

// ---- keys and buttons -------------------------------------------------

let pendingExport = null;
function exportFile(op, fields) {
  pendingExport = (overwrite) => net.send(op, { ...fields, overwrite });
  pendingExport(false);
}

$('undo').onclick = () => net.send('undo');
$('redo').onclick = () => net.send('redo');
$('save').onclick = () => {
  const name = askName('Save the colours as (.meshcolors, in the export folder)', 'painted.meshcolors', 'meshcolors');
  if (name) exportFile('save', { name });
};
// A name for `ext`, with the extension added when left out.
function askName(text, suggested, ext) {
  const name = prompt(text, suggested);
  if (!name) return null;
  return name.toLowerCase().endsWith('.' + ext) ? name : name + '.' + ext;
}
$('export').onclick = () => {
  const name = askName('Export a GLB (the colours baked into a texture)', 'painted.glb', 'glb');
  if (name) exportFile('export', { kind: 'glb', name });
};
$('exportObj').onclick = () => {
  const name = askName('Export OBJ + MTL + PNG (the colours baked into a texture)', 'painted.obj', 'obj');
  if (name) exportFile('export', { kind: 'obj', name });
};
$('exportSession').onclick = () => {
  const name = askName('Export the session (every edit; trilux paint MESH --replay FILE)', 'session.json', 'json');
  if (name) exportFile('export', { kind: 'session', name });
};
$('exportPoints').onclick = () => {
  const name = prompt('Export the points (.glb or .ply: position, normal, face)', 'points.glb');
  if (name) exportFile('export', { kind: 'points', name });
};
$('exportStrands').onclick = () => {
  const name = prompt('Export the strands (.usda, .glb or .hair)', 'strands.usda');
  if (name) exportFile('export', { kind: 'strands', name });
};
// The view as the canvas shows it, downloaded as a PNG.
$('screenshot').onclick = () => {
  dirty = true;
  canvas.toBlob((blob) => {
    const a = document.createElement('a');
    a.href = URL.createObjectURL(blob);
    a.download = 'trilux-paint.png';
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 1000);
  }, 'image/png');
};
$('applyLevel').onclick = () => net.send('resolution', { level: Number($('level').value) });
$('help').onclick = () => { $('helpbox').hidden = !$('helpbox').hidden; };
$('filter').onchange = () => { dirty = true; };
$('channel').onchange = () => {
  const scalar = state.channelIndex() !== 0;
  $('colorRow').hidden = scalar; $('valueRow').hidden = !scalar; $('heatLegend').hidden = !scalar;
  dirty = true;
};
$('shade').onchange = () => { dirty = true; };

addEventListener('keydown', (e) => {
  // Typing goes to a text or number box; a slider, tick box or colour
  // well with focus leaves the keys to the page.
  if (e.target.tagName === 'INPUT' && !['range', 'checkbox', 'color'].includes(e.target.type)) return;
  const k = e.key.toLowerCase();
  if (e.key === 'Escape') { $('helpbox').hidden = true; return; }
  // Frame the model again (Blender's Home).
  if (e.key === 'Home' || (k === 'f' && !e.ctrlKey && !e.metaKey)) {
    state.camera = new Camera(state.hello.bounds[0], state.hello.bounds[1]);
    dirty = pickDirty = true;
    return;
  }
  if ((e.ctrlKey || e.metaKey) && k === 'z') { net.send(e.shiftKey ? 'redo' : 'undo'); e.preventDefault(); return; }
  if ((e.ctrlKey || e.metaKey) && k === 'y') { net.send('redo'); e.preventDefault(); return; }
  if ((e.ctrlKey || e.metaKey) && k === 's') { $('save').onclick(); e.preventDefault(); return; }
  if (e.ctrlKey || e.metaKey) return;
  const tools = { b: 'paint', e: 'erase', g: 'fill', i: 'pick', d: 'detail' };
  if (tools[k]) setTool(tools[k]);
  else if (k === 'x') $('mirror').checked = !$('mirror').checked;
  else if (k === '[' || k === ']') {
    const r = $('radius');
    r.value = Math.max(2, Math.min(200, Number(r.value) * (k === ']' ? 1.25 : 0.8)));
    if (state.pointer) showBrush(state.pointer);
  } else if (e.key === '?') $('helpbox').hidden = !$('helpbox').hidden;
});

// ---- drawing ----------------------------------------------------------

function frame() {
  requestAnimationFrame(frame);
  if (!gl || !state.layout || !state.camera) return;
  fitCanvas(canvas);
  if (!dirty) return;
  dirty = false;
  drawScene({ mesh: true, points: true });
}

// The mesh and the scatter's layer; `parts` leaves either out (the
// benchmark times them apart).
function drawScene(parts) {
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clearColor(0.106, 0.11, 0.122, 1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  const k = state.channelIndex();
  const viewProj = state.camera.viewProj(canvas.width / canvas.height);
  if (parts.mesh) {
    renderer.draw(viewProj, {
      filter: $('filter').value,
      display: k === 0 ? 'color' : 'heat', channel: k === 0 ? 0 : k + 2,
      shade: $('shade').checked ? 0.6 : 0, eye: state.camera.eye(),
    });
  }
  if (parts.points) layer.draw(viewProj, { size: Number($('pointSize').value) * devicePixelRatio });
  if (pointsPending) {
    // Waits for the drawing once per points frame, so that the time a
    // stroke takes to show its points is measured to the finished frame.
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    pointsPending = false;
    state.pointsDrawnAt = performance.now();
  }
  state.frames++;
  state.ready = true;
}

// Draws `parts` once and waits for it: milliseconds (the benchmark's
// split of a frame into the mesh colours and the points).
state.timeDraw = (parts) => {
  const t = performance.now();
  drawScene(parts);
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  dirty = true;
  return performance.now() - t;
};
if (!gl) flash('this browser has no WebGL2: trilux paint needs it');
new ResizeObserver(() => { dirty = pickDirty = true; }).observe(canvas);
requestAnimationFrame(frame);
