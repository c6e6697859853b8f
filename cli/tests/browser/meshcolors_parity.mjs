// The mesh-colour shader of trilux paint (cli/src/paint/page/meshcolors.js)
// in headless Chromium, for the GPU/CPU parity test
// (cli/tests/all/paint_shader.rs) and the Table I measurement.
//
// Usage (beside the node_modules holding playwright-core, as
// target/browser-e2e; the browser is TRILUX_BROWSER, default
// /usr/bin/chromium):
//   node meshcolors_parity.mjs MESHCOLORS_JS DIR [--bench] [--shots SHOT_DIR]
// DIR holds what the Rust test wrote: meta.json ({width, channels,
// face_count, size: [w, h], view_proj: 16 numbers column-major, passes:
// [{name, filter, level?, maxSamples?, display?, channel?, range?,
// defines?}]}), samples.f32, faces.u32 (the GpuLayout's arrays),
// corners.f32 (nine floats per face) and, for --bench, atlas.rgba8
// (meta.atlas = [w, h], sRGB) and uvs.f32 (six floats per face).
//
// Parity: for each pass it draws the mesh on the canvas (not antialiased;
// alpha = face id mod 255 + 1, background 0) and reads the canvas back to DIR/<name>.rgba8;
// once, the pick pass (same program, same geometry) to DIR/pick.f32: per
// pixel 12 floats (face or -1, b0, b1, b2, db/dx, 0, db/dy, 0). Rows
// bottom-up, as readPixels gives them, in both. Then a stroke: the texel
// rectangles of DIR/update.json (GpuLayout::update's Changes) go up with
// updateRects from samples2.f32 and faces2.u32, and the linear and
// trilinear canvases are read back again to after_<filter>.rgba8. With --shots, PNGs of
// the nearest, linear and anisotropic passes (alpha 1) into SHOT_DIR.
//
// --bench: frame time of the mesh-colour shader against a plain 2D texture
// (the baked atlas, RGBA8 sRGB, hardware bilinear / trilinear with
// generated MIP levels) for the same view: medians over 40 frames each,
// each timed with gl.finish(). Prints {bench: {...}}.
//
// Prints one JSON object on stdout; {error} when something failed.
import { launch } from './lib.mjs';
import { createServer } from 'node:http';
import { readFile, writeFile } from 'node:fs/promises';
import path from 'node:path';

const args = process.argv.slice(2);
const bench = args.includes('--bench');
const shotsAt = args.indexOf('--shots');
const shots = shotsAt >= 0 ? args[shotsAt + 1] : null;
const [moduleFile, dir] = args.filter((a, i) => !a.startsWith('--') && (shotsAt < 0 || i !== shotsAt + 1));

const PAGE = `<!doctype html><html><head><meta charset="utf-8"><link rel="icon" href="data:,">
<style>html,body{margin:0;background:#202020}canvas{display:block}</style></head>
<body><canvas id="view"></canvas><script type="module" src="/harness.js"></script></body></html>`;

// The page's side: loads the data, draws, reads back, posts results.
const HARNESS = `
import { MeshColorsRenderer } from '/meshcolors.js';
const get = async (name, T) => new T(await (await fetch('/data/' + name)).arrayBuffer());
const put = (name, data) => fetch('/out/' + name, { method: 'POST', body: data });
const meta = await (await fetch('/data/meta.json')).json();
const [W, H] = meta.size;
const canvas = document.getElementById('view');
canvas.width = W; canvas.height = H;
canvas.style.width = W + 'px'; canvas.style.height = H + 'px';
const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true, premultipliedAlpha: false });
if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('no EXT_color_buffer_float');
const parts = { width: meta.width, channels: meta.channels, samples: await get('samples.f32', Float32Array), faces: await get('faces.u32', Uint32Array) };
const corners = await get('corners.f32', Float32Array);
const renderers = new Map();
const renderer = (defines = []) => {
  const key = defines.join(',');
  if (!renderers.has(key)) {
    const r = new MeshColorsRenderer(gl, { defines });
    r.setCorners(corners);
    r.setLayout(parts);
    renderers.set(key, r);
  }
  return renderers.get(key);
};
const toCanvas = (pass, tag) => {
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.viewport(0, 0, W, H);
  gl.clearColor(0, 0, 0, 0);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  renderer(pass.defines).draw(meta.view_proj, { ...pass, tagAlpha: tag });
};
window.parity = async () => {
  const px = new Uint8Array(W * H * 4);
  const timings = {};
  for (const pass of meta.passes) {
    const t0 = performance.now();
    renderer(pass.defines);
    gl.finish();
    const t1 = performance.now();
    toCanvas(pass, true);
    gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, px);
    timings[pass.name] = [t1 - t0, performance.now() - t1];
    await put(pass.name + '.rgba8', px);
  }
  const r = renderer();
  const t = r.pickFramebuffer(W, H);
  gl.bindFramebuffer(gl.FRAMEBUFFER, t.fb);
  gl.viewport(0, 0, W, H);
  gl.clearBufferfv(gl.COLOR, 0, [-1, 0, 0, 0]);
  gl.clearBufferfv(gl.COLOR, 1, [0, 0, 0, 0]);
  gl.clearBufferfv(gl.COLOR, 2, [0, 0, 0, 0]);
  gl.clear(gl.DEPTH_BUFFER_BIT);
  r.drawPick(meta.view_proj);
  const out = new Float32Array(W * H * 12), one = new Float32Array(W * H * 4);
  for (let a = 0; a < 3; a++) {
    gl.readBuffer(gl.COLOR_ATTACHMENT0 + a);
    gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT, one);
    for (let i = 0; i < W * H; i++) out.set(one.subarray(4 * i, 4 * i + 4), 12 * i + 4 * a);
  }
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  await put('pick.f32', out);
  // A stroke: the changed rectangles only, from the new arrays.
  const changes = await (await fetch('/data/update.json')).json();
  r.updateRects(changes, { samples: await get('samples2.f32', Float32Array), faces: await get('faces2.u32', Uint32Array) });
  for (const filter of ['linear', 'trilinear']) {
    toCanvas({ filter }, true);
    gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, px);
    await put('after_' + filter + '.rgba8', px);
  }
  return { renderer: gl.getParameter(gl.RENDERER), errors: gl.getError(), timings };
};
window.show = (name) => toCanvas(meta.passes.find((p) => p.name === name), false);
window.bench = async (frames) => {
  const median = (xs) => { const s = [...xs].sort((a, b) => a - b); return s[Math.floor(s.length / 2)]; };
  // Chromium's gl.finish() does not wait for the GPU process; reading one
  // pixel back after it does (the drawing must be complete to read it).
  const one = new Uint8Array(4);
  const sync = () => { gl.finish(); gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, one); };
  const time = (draw) => {
    for (let i = 0; i < 3; i++) { draw(); sync(); }
    const ts = [];
    for (let i = 0; i < frames; i++) {
      const t0 = performance.now(); draw(); sync(); ts.push(performance.now() - t0);
    }
    return median(ts);
  };
  const empty = time(() => { gl.viewport(0, 0, W, H); gl.clearColor(0, 0, 0, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT); });
  const atlas = await import('/atlas.js');
  const plain = await atlas.plainTexture(gl, meta, await get('atlas.rgba8', Uint8Array), corners, await get('uvs.f32', Float32Array));
  const frame = (f) => () => { gl.viewport(0, 0, W, H); gl.clearColor(0, 0, 0, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT); f(); };
  const mc = renderer();
  const out = {};
  out.mesh_linear_ms = time(frame(() => mc.draw(meta.view_proj, { filter: 'linear' })));
  out.texture_linear_ms = time(frame(() => plain.draw(meta.view_proj, false)));
  out.mesh_trilinear_ms = time(frame(() => mc.draw(meta.view_proj, { filter: 'trilinear' })));
  out.texture_mip_ms = time(frame(() => plain.draw(meta.view_proj, true)));
  out.mesh_anisotropic_ms = time(frame(() => mc.draw(meta.view_proj, { filter: 'anisotropic', maxSamples: 8 })));
  // Ratios of the drawing alone: the time of a cleared frame (clear and
  // the read-back) taken off both.
  out.empty_frame_ms = empty;
  out.linear_ratio = (out.mesh_linear_ms - empty) / (out.texture_linear_ms - empty);
  out.mip_ratio = (out.mesh_trilinear_ms - empty) / (out.texture_mip_ms - empty);
  out.linear_ratio_whole_frames = out.mesh_linear_ms / out.texture_linear_ms;
  out.mip_ratio_whole_frames = out.mesh_trilinear_ms / out.texture_mip_ms;
  out.frames = frames;
  out.size = [W, H];
  out.atlas = meta.atlas;
  out.samples_texels = parts.samples.length / 4;
  return out;
};
window.ready = true;
`;

// The baseline of Table I: the atlas `colors bake` makes, drawn as any
// engine draws a UV-mapped texture (same view, same geometry).
const ATLAS = `
const VS = \`#version 300 es
in vec3 position; in vec2 uv; uniform mat4 viewProj; out vec2 vUv;
void main() { vUv = uv; gl_Position = viewProj * vec4(position, 1.0); }\`;
const FS = \`#version 300 es
precision highp float; uniform sampler2D atlas; in vec2 vUv; out vec4 color;
// SRGB8_ALPHA8 decodes to linear when sampled; encode again as the mesh
// colour shader does, so both pay for one encoding.
float srgb(float x) { x = clamp(x, 0.0, 1.0); return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055; }
void main() { vec3 c = texture(atlas, vUv).rgb; color = vec4(srgb(c.r), srgb(c.g), srgb(c.b), 1.0); }\`;
export async function plainTexture(gl, meta, texels, corners, uvs) {
  const sh = (t, s) => { const x = gl.createShader(t); gl.shaderSource(x, s); gl.compileShader(x);
    if (!gl.getShaderParameter(x, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(x)); return x; };
  const p = gl.createProgram();
  gl.attachShader(p, sh(gl.VERTEX_SHADER, VS)); gl.attachShader(p, sh(gl.FRAGMENT_SHADER, FS)); gl.linkProgram(p);
  const vao = gl.createVertexArray(); gl.bindVertexArray(vao);
  for (const [name, data, n] of [['position', corners, 3], ['uv', uvs, 2]]) {
    const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    const l = gl.getAttribLocation(p, name); gl.enableVertexAttribArray(l); gl.vertexAttribPointer(l, n, gl.FLOAT, false, 0, 0);
  }
  gl.bindVertexArray(null);
  const tex = gl.createTexture();
  gl.activeTexture(gl.TEXTURE2);
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.SRGB8_ALPHA8, meta.atlas[0], meta.atlas[1], 0, gl.RGBA, gl.UNSIGNED_BYTE, texels);
  gl.generateMipmap(gl.TEXTURE_2D);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  const count = corners.length / 3;
  return {
    draw(viewProj, mip) {
      gl.useProgram(p);
      gl.enable(gl.DEPTH_TEST);
      gl.activeTexture(gl.TEXTURE2);
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, mip ? gl.LINEAR_MIPMAP_LINEAR : gl.LINEAR);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
      gl.uniform1i(gl.getUniformLocation(p, 'atlas'), 2);
      gl.uniformMatrix4fv(gl.getUniformLocation(p, 'viewProj'), false, viewProj);
      gl.bindVertexArray(vao);
      gl.drawArrays(gl.TRIANGLES, 0, count);
      gl.bindVertexArray(null);
    },
  };
}
`;

// ES modules do not load from file://: a loopback server for the page,
// the module under test, the data and the results.
function serve() {
  const server = createServer(async (req, res) => {
    try {
      const url = new URL(req.url, 'http://localhost');
      const js = (text) => { res.writeHead(200, { 'content-type': 'text/javascript' }); res.end(text); };
      if (url.pathname === '/') { res.writeHead(200, { 'content-type': 'text/html' }); res.end(PAGE); }
      else if (url.pathname === '/harness.js') js(HARNESS);
      else if (url.pathname === '/atlas.js') js(ATLAS);
      else if (url.pathname === '/meshcolors.js') js(await readFile(moduleFile));
      else if (url.pathname.startsWith('/data/')) {
        res.writeHead(200, { 'content-type': 'application/octet-stream' });
        res.end(await readFile(path.join(dir, path.basename(url.pathname))));
      } else if (url.pathname.startsWith('/out/') && req.method === 'POST') {
        const chunks = [];
        for await (const c of req) chunks.push(c);
        await writeFile(path.join(dir, path.basename(url.pathname)), Buffer.concat(chunks));
        res.writeHead(204); res.end();
      } else { res.writeHead(404); res.end(); }
    } catch (e) { res.writeHead(500); res.end(String(e)); }
  });
  return new Promise((ok) => server.listen(0, '127.0.0.1', () => ok(server)));
}

const server = await serve();
const browser = await launch();
const out = {};
const started = Date.now();
const logs = [];
try {
  const page = await browser.newPage({ viewport: { width: 1200, height: 1200 } });
  page.on('console', (m) => logs.push(m.text()));
  // An error on the page (a module that does not load, a shader that
  // does not compile) ends the run at once instead of at the timeout.
  const failed = new Promise((_, reject) => page.on('pageerror', (e) => reject(e)));
  failed.catch(() => {});
  page.on('pageerror', (e) => logs.push('pageerror: ' + e.message));
  out.launch_ms = Date.now() - started;
  await page.goto(`http://127.0.0.1:${server.address().port}/`);
  await Promise.race([page.waitForFunction(() => window.ready === true, null, { timeout: 60000 }), failed]);
  out.ready_ms = Date.now() - started;
  if (bench) {
    out.bench = await page.evaluate((n) => window.bench(n), 40);
  } else {
    Object.assign(out, await page.evaluate(() => window.parity()));
    if (shots) {
      out.shots = [];
      for (const name of ['nearest', 'linear', 'anisotropic', 'heat']) {
        if (!(await page.evaluate((n) => { if (!window.show) return false; try { window.show(n); return true; } catch { return false; } }, name))) continue;
        const file = path.join(shots, name + '.png');
        await page.locator('#view').screenshot({ path: file });
        out.shots.push(file);
      }
    }
  }
} catch (e) {
  out.error = String(e && e.stack ? e.stack : e);
}
out.console = logs;
out.total_ms = Date.now() - started;
await browser.close();
server.close();
console.log(JSON.stringify(out));
