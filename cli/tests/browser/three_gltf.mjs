// three.js (npm three, its GLTFLoader) loads a glTF file in headless
// Chromium and renders it once, unlit, for a pixel check.
//
// Usage: copied beside the node_modules that hold playwright-core and three
// (target/browser-e2e, as cli/tests/all/gltf_clients.rs does), since its
// imports and the files it serves resolve from its own folder; the browser
// is TRILUX_BROWSER (default /usr/bin/chromium):
//   node target/browser-e2e/three_gltf.mjs MODEL.glb|MODEL.gltf SCREENSHOT.png [options]
// Options:
//   --size N             the canvas is N x N CSS and device pixels (default 256)
//   --at U,V             read the pixel at normalized canvas position (U, V):
//                        U from the left edge (0) to the right (1), V from the
//                        top (0) to the bottom (1); repeatable
//   --world X,Y,Z        read the pixel where the world point projects; repeatable
//   --grid N             read the centres of an N x N grid (the default, N = 8,
//                        when no --at or --world is given)
//   --ortho CX,CY,HALF   the orthographic camera looks along -z at (CX, CY),
//                        showing [CX - HALF, CX + HALF] x [CY - HALF, CY + HALF]
//                        (default: the scene's bounding box, x and y, plus 5%)
//   --point-size PX      the size of POINTS primitives in pixels (default 6)
//   --background RRGGBB  the clear colour, 8-bit sRGB (default 404040)
//
// What is drawn: every mesh keeps its geometry, and its material is replaced
// by an unlit MeshBasicMaterial with the loaded material's base colour
// (color, the baseColorFactor), map (the baseColorTexture), vertexColors
// (COLOR_0), side (doubleSided), transparent, opacity and alphaTest, so no
// light enters the pixels; a POINTS primitive gets a PointsMaterial with
// the same colour, map, vertexColors and a fixed size in pixels. No
// antialiasing, no tone mapping, pixel ratio 1.
//
// Colour management (three r152+ defaults, kept as they are): the working
// space is linear sRGB and the canvas output is sRGB. GLTFLoader tags the
// baseColorTexture as sRGB, so the GPU decodes its texels to linear when it
// samples; COLOR_0 and baseColorFactor are linear, as glTF says. The
// fragment is factor * texel * vertex colour in linear, then encoded with
// the sRGB transfer function to 8 bits. So, away from edges:
//   - an 8-bit sRGB texel v (factor 1, no COLOR_0) reads back as v (the
//     decode/encode round trip is within 1 unit);
//   - a linear vertex colour c (no texture, factor 1) reads back as
//     round(255 * srgb(c)), srgb(c) = 12.92 c for c <= 0.0031308, else
//     1.055 c^(1/2.4) - 0.055; inside a triangle whose three vertices have
//     the same colour, exactly that;
//   - the background is the --background value itself.
// Opaque materials (glTF's default alphaMode) write alpha 255.
//
// Prints one JSON object on stdout:
//   { three: REVISION, renderer: WebGL renderer string, size: N,
//     objects: [{ kind: "mesh" | "points" | ..., name, vertices, indices,
//                 triangles, attributes (three's names), gltf_attributes
//                 (the file's names), material: { type (as loaded), color
//                 (linear RGB), map, map_size: [w, h], map_color_space,
//                 vertex_colors, color_item_size, side, transparent } }],
//     meshes, points, vertices (totals),
//     camera: { center: [x, y], half, near, far },
//     background: [r, g, b] (8-bit sRGB),
//     probes: [{ at: [u, v], world?: [x, y, z], pixel: [x, y] (from the top
//                left), rgba: [r, g, b, a] }] (--at and --world in the
//                order given, then the grid row by row from the top),
//     screenshot: PATH, console: [messages of the page], error?: string }
import { launch } from './lib.mjs';
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const args = process.argv.slice(2);
const positional = [];
const opts = { size: 256, probes: [], grid: null, ortho: null, pointSize: 6, background: '404040' };
const numbers = (s, n, what) => {
  const v = s === undefined ? [] : s.split(',').map(Number);
  if (v.length !== n || v.some((x) => !Number.isFinite(x))) {
    throw new Error(`${what} needs ${n} comma-separated numbers, got ${s}`);
  }
  return v;
};
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  const next = () => args[++i];
  if (a === '--size') opts.size = numbers(next(), 1, a)[0];
  else if (a === '--at') opts.probes.push({ at: numbers(next(), 2, a) });
  else if (a === '--world') opts.probes.push({ world: numbers(next(), 3, a) });
  else if (a === '--grid') opts.grid = numbers(next(), 1, a)[0];
  else if (a === '--ortho') opts.ortho = numbers(next(), 3, a);
  else if (a === '--point-size') opts.pointSize = numbers(next(), 1, a)[0];
  else if (a === '--background') {
    opts.background = next();
    if (!/^[0-9a-fA-F]{6}$/.test(opts.background || '')) throw new Error(`--background needs RRGGBB, got ${opts.background}`);
  } else if (a.startsWith('--')) throw new Error(`unknown option ${a}`);
  else positional.push(a);
}
if (positional.length !== 2) {
  console.error('usage: node three_gltf.mjs MODEL.glb|MODEL.gltf SCREENSHOT.png [--size N] [--at U,V]... [--world X,Y,Z]... [--grid N] [--ortho CX,CY,HALF] [--point-size PX] [--background RRGGBB]');
  process.exit(2);
}
if (opts.grid === null && opts.probes.length === 0) opts.grid = 8;
const model = path.resolve(positional[0]);
const screenshot = path.resolve(positional[1]);
const modelDir = path.dirname(model);
const here = path.dirname(fileURLToPath(import.meta.url));
const threeDir = path.join(here, 'node_modules', 'three');

// The page, three.js and the model come from page.route: no server, no
// network. /three/... is node_modules/three; /model/... the model's folder
// (so a .gltf finds its .bin and images relative to it).
const origin = 'http://three-gltf.test';
const page = `<!doctype html>
<html><head><meta charset="utf-8"><link rel="icon" href="data:,"><style>html,body{margin:0;background:#000}canvas{display:block}</style>
<script type="importmap">{"imports":{"three":"/three/build/three.module.js","three/addons/":"/three/examples/jsm/"}}</script>
</head><body>
<script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
window.run = async (o) => {
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true, alpha: false });
  renderer.setPixelRatio(1);
  renderer.setSize(o.size, o.size);
  renderer.setClearColor(new THREE.Color('#' + o.background), 1);
  renderer.domElement.id = 'view';
  document.body.appendChild(renderer.domElement);
  const gltf = await new GLTFLoader().loadAsync(o.url);
  const scene = gltf.scene;
  const json = gltf.parser.json;
  const objects = [];
  scene.updateMatrixWorld(true);
  scene.traverse((obj) => {
    if (!obj.isMesh && !obj.isPoints && !obj.isLine) return;
    const g = obj.geometry, m = obj.material;
    const assoc = gltf.parser.associations.get(obj);
    let gltfAttributes = null;
    if (assoc && assoc.meshes !== undefined && assoc.primitives !== undefined) {
      gltfAttributes = Object.keys(json.meshes[assoc.meshes].primitives[assoc.primitives].attributes).sort();
    }
    const img = m.map && m.map.image;
    objects.push({
      kind: obj.isMesh ? 'mesh' : obj.isPoints ? 'points' : 'line',
      name: obj.name,
      vertices: g.attributes.position ? g.attributes.position.count : 0,
      indices: g.index ? g.index.count : null,
      triangles: obj.isMesh ? (g.index ? g.index.count : g.attributes.position.count) / 3 : 0,
      attributes: Object.keys(g.attributes).sort(),
      gltf_attributes: gltfAttributes,
      material: {
        type: m.type,
        color: m.color ? m.color.toArray() : null,
        map: !!m.map,
        map_size: img ? [img.width, img.height] : null,
        map_color_space: m.map ? m.map.colorSpace : null,
        vertex_colors: !!m.vertexColors,
        color_item_size: g.attributes.color ? g.attributes.color.itemSize : null,
        side: m.side === THREE.DoubleSide ? 'double' : m.side === THREE.BackSide ? 'back' : 'front',
        transparent: !!m.transparent,
      },
    });
    const keep = { color: m.color ? m.color.clone() : new THREE.Color(1, 1, 1), map: m.map || null,
      vertexColors: !!m.vertexColors, side: m.side, transparent: m.transparent, opacity: m.opacity, alphaTest: m.alphaTest };
    if (obj.isPoints) {
      obj.material = new THREE.PointsMaterial({ ...keep, size: o.pointSize, sizeAttenuation: false });
    } else if (obj.isMesh) {
      obj.material = new THREE.MeshBasicMaterial(keep);
    }
  });
  const box = new THREE.Box3().setFromObject(scene);
  let cx, cy, half;
  if (o.ortho) [cx, cy, half] = o.ortho;
  else {
    const c = box.getCenter(new THREE.Vector3()), s = box.getSize(new THREE.Vector3());
    cx = c.x; cy = c.y; half = 0.5 * Math.max(s.x, s.y, 1e-6) * 1.05;
  }
  const depth = Math.max(box.max.z - box.min.z, 1e-3);
  // Left, right, top and bottom are relative to the camera, which is at (cx, cy).
  const camera = new THREE.OrthographicCamera(-half, half, half, -half, 0.5 * depth, 2.5 * depth);
  camera.position.set(cx, cy, box.max.z + depth);
  camera.lookAt(cx, cy, box.max.z - 1);
  camera.updateMatrixWorld(true);
  renderer.render(scene, camera);
  const gl = renderer.getContext();
  const n = o.size;
  const px = new Uint8Array(n * n * 4);
  gl.readPixels(0, 0, n, n, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const read = (u, v) => {
    const x = Math.min(n - 1, Math.max(0, Math.floor(u * n)));
    const y = Math.min(n - 1, Math.max(0, Math.floor(v * n)));
    const i = ((n - 1 - y) * n + x) * 4; // readPixels rows start at the bottom
    return { pixel: [x, y], rgba: Array.from(px.slice(i, i + 4)) };
  };
  const probes = [];
  for (const q of o.probes) {
    if (q.at) {
      const [u, v] = q.at;
      probes.push({ at: [u, v], ...read(u, v) });
    } else {
      const p = new THREE.Vector3(...q.world).project(camera);
      const u = 0.5 * (p.x + 1), v = 0.5 * (1 - p.y);
      probes.push({ at: [u, v], world: q.world, ...read(u, v) });
    }
  }
  if (o.grid) {
    for (let j = 0; j < o.grid; j++) for (let i = 0; i < o.grid; i++) {
      const u = (i + 0.5) / o.grid, v = (j + 0.5) / o.grid;
      probes.push({ at: [u, v], ...read(u, v) });
    }
  }
  const dbg = gl.getExtension('WEBGL_debug_renderer_info');
  return {
    three: THREE.REVISION,
    renderer: dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER),
    size: n,
    objects,
    meshes: objects.filter((x) => x.kind === 'mesh').length,
    points: objects.filter((x) => x.kind === 'points').length,
    vertices: objects.reduce((a, x) => a + x.vertices, 0),
    camera: { center: [cx, cy], half, near: camera.near, far: camera.far },
    background: [0, 2, 4].map((k) => parseInt(o.background.slice(k, k + 2), 16)),
    probes,
  };
};
window.ready = true;
</script></body></html>`;

const types = { '.js': 'text/javascript', '.mjs': 'text/javascript', '.glb': 'model/gltf-binary', '.gltf': 'model/gltf+json',
  '.bin': 'application/octet-stream', '.png': 'image/png', '.jpg': 'image/jpeg', '.jpeg': 'image/jpeg', '.webp': 'image/webp' };
// A file under root, or null for a path that leaves it.
const under = (root, rel) => {
  const p = path.resolve(root, decodeURIComponent(rel));
  return p === root || p.startsWith(root + path.sep) ? p : null;
};

const out = { console: [] };
const browser = await launch();
try {
  const tab = await browser.newPage({ viewport: { width: opts.size, height: opts.size }, deviceScaleFactor: 1 });
  tab.on('console', (m) => out.console.push(`${m.type()}: ${m.text()}`));
  tab.on('requestfailed', (r) => out.console.push(`requestfailed: ${r.url().slice(0, 100)} ${r.failure() && r.failure().errorText}`));
  tab.on('pageerror', (e) => out.console.push(`pageerror: ${e.message}`));
  await tab.route(`${origin}/**`, async (route) => {
    const url = new URL(route.request().url());
    if (url.pathname === '/') return route.fulfill({ contentType: 'text/html', body: page });
    let file = null;
    if (url.pathname.startsWith('/three/')) file = under(threeDir, url.pathname.slice('/three/'.length));
    else if (url.pathname.startsWith('/model/')) file = under(modelDir, url.pathname.slice('/model/'.length));
    if (file === null) return route.fulfill({ status: 404, body: 'not here' });
    try {
      const body = await readFile(file);
      return route.fulfill({ body, contentType: types[path.extname(file).toLowerCase()] || 'application/octet-stream' });
    } catch (e) {
      out.console.push(`404 ${url.pathname}: ${e.message}`);
      return route.fulfill({ status: 404, body: String(e.message) });
    }
  });
  await tab.goto(`${origin}/`);
  await tab.waitForFunction(() => window.ready === true, null, { timeout: 30000 });
  const url = `${origin}/model/${encodeURIComponent(path.basename(model))}`;
  Object.assign(out, await tab.evaluate((o) => window.run(o), {
    url, size: opts.size, probes: opts.probes, grid: opts.grid, ortho: opts.ortho,
    pointSize: opts.pointSize, background: opts.background,
  }));
  await tab.locator('#view').screenshot({ path: screenshot });
  out.screenshot = screenshot;
} catch (e) {
  out.error = String((e && e.stack) || e);
} finally {
  await browser.close();
}
console.log(JSON.stringify(out));
