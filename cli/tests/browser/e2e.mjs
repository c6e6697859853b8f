// End-to-end test of trilux view's page in headless Chromium: load, first
// frame with radiance, orbit, stroke cut, paint, relight, undo, redo, an
// environment map, a GLB export, screenshot. Prints one JSON object with what it saw; the Rust test
// asserts on it. Usage: node e2e.mjs URL SCREENSHOT_DIR [first-frame]
// (first-frame: only load the page and time its first frame with radiance).
import { launch } from './lib.mjs';

const [url, dir, only] = process.argv.slice(2);
const browser = await launch();
const out = { steps: {} };
const consoleErrors = [];
try {
  // The page's CSP forbids eval, which Playwright's argument passing needs.
  const page = await browser.newPage({ viewport: { width: 800, height: 600 }, bypassCSP: true });
  const logs = [];
  page.on('console', (m) => { logs.push(m.text()); if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => logs.push('pageerror: ' + e.message));
  const t0 = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => window.trilux && window.trilux.firstFrameAt !== null && window.trilux.renderer.frames > 2, null, { timeout: 60000 });
  out.first_frame_ms = Date.now() - t0;
  if (only === 'first-frame') {
    await page.screenshot({ path: dir + '/0-first-frame.png' });
    throw null;
  }
  const stats = () => page.evaluate(() => ({
    radiance: window.trilux.radianceFrames, surfaces: window.trilux.surfaceFrames,
    pieces: window.trilux.renderer.pieces.filter(Boolean).length,
    triangles: window.trilux.renderer.pieces.filter(Boolean).reduce((a, p) => a + p.count / 3, 0),
    history: window.trilux.status && window.trilux.status.history, tets: window.trilux.status && window.trilux.status.tets,
    errors: window.trilux.errors.length, edit: window.trilux.status && window.trilux.status.edit,
    answered: window.trilux.answered.length,
    white: window.trilux.white, white_from: window.trilux.whiteFrom, covered: window.trilux.covered,
    environment: window.trilux.environment || null,
    light_dir: window.trilux.lightDir, sun: document.getElementById('sun') !== null,
  }));
  // The mean colour of the canvas's centre and how much of it is lit.
  const pixels = () => page.evaluate(() => {
    const c = document.getElementById('view');
    const gl = window.trilux.renderer.gl;
    const w = c.width, h = c.height, px = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    let lit = 0, sum = [0, 0, 0];
    for (let i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - 27) + Math.abs(px[i + 1] - 28) + Math.abs(px[i + 2] - 31) > 12) { lit++; sum[0] += px[i]; sum[1] += px[i + 1]; sum[2] += px[i + 2]; }
    }
    return { lit: lit / (w * h), mean: sum.map((s) => lit ? s / lit : 0) };
  });
  const waitEdit = async (name, before) => page.waitForFunction(([n, b]) => window.trilux.answered.length > b && window.trilux.answered[window.trilux.answered.length - 1] === n && window.trilux.pending.size === 0, [name, before], { timeout: 120000 });
  // Auto exposure measures the covered pixels after the first frame.
  await page.waitForFunction(() => window.trilux.whiteFrom === 'pixels', null, { timeout: 60000 });
  out.steps.load = { ...(await stats()), ...(await pixels()),
    hud: await page.evaluate(() => document.getElementById('status').textContent),
    ev: await page.evaluate(() => document.getElementById('evval').textContent) };
  await page.screenshot({ path: dir + '/1-load.png' });
  // Orbit: drag in orbit mode; the picture changes, no server round trip.
  const beforeOrbit = await pixels();
  await page.mouse.move(300, 300); await page.mouse.down(); await page.mouse.move(420, 260, { steps: 8 }); await page.mouse.up();
  await page.waitForTimeout(300);
  out.steps.orbit = { ...(await stats()), ...(await pixels()), before: beforeOrbit };
  // Stroke cut across the middle, top to bottom.
  let s = await stats();
  await page.keyboard.press('c');
  await page.mouse.move(400, 80); await page.mouse.down(); await page.mouse.move(400, 520, { steps: 12 }); await page.mouse.up();
  await waitEdit('cut', s.answered);
  out.steps.cut = { ...(await stats()), ...(await pixels()) };
  await page.screenshot({ path: dir + '/2-cut.png' });
  // Paint a stroke of ketchup on the object.
  s = await stats();
  await page.keyboard.press('p');
  // As a user does: click the list, pick, then press a shortcut. The key
  // must reach the page, not change the list's choice by type-ahead.
  await page.focus('#material');
  await page.selectOption('#material', 'ketchup');
  await page.keyboard.press('c'); await page.keyboard.press('p');
  const afterKeys = await page.evaluate(() => ({ material: document.getElementById('material').value }));
  await page.mouse.move(330, 280); await page.mouse.down(); await page.mouse.move(360, 320, { steps: 6 }); await page.mouse.up();
  await waitEdit('paint', s.answered);
  out.steps.paint = { ...(await stats()), ...(await pixels()), material_after_keys: afterKeys.material };
  // Relight: drag the light to the left.
  s = await stats();
  await page.keyboard.press('l');
  await page.mouse.move(480, 150); await page.mouse.down(); await page.mouse.move(120, 250, { steps: 6 }); await page.mouse.up();
  await waitEdit('lights', s.answered);
  out.steps.light = { ...(await stats()), ...(await pixels()) };
  await page.screenshot({ path: dir + '/3-relit.png' });
  // Undo the light, then the paint; redo the paint.
  for (const [key, name] of [['z', 'undo'], ['z', 'undo']]) {
    s = await stats();
    await page.keyboard.press('Control+' + key);
    await waitEdit(name, s.answered);
  }
  out.steps.undo = { ...(await stats()), ...(await pixels()) };
  s = await stats();
  await page.keyboard.press('Control+Shift+Z');
  await waitEdit('redo', s.answered);
  out.steps.redo = { ...(await stats()), ...(await pixels()) };
  // Load an environment map (a tiny Radiance .hdr, bright above) through
  // the file picker of the light panel.
  const hdr = [...new TextEncoder().encode('#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n')];
  for (let row = 0; row < 2; row++) for (let k = 0; k < 4; k++) hdr.push(128, 128, 128, row === 0 ? 134 : 129);
  s = await stats();
  await page.keyboard.press('l');
  await page.setInputFiles('#envmap', { name: 'sky.hdr', mimeType: 'application/octet-stream', buffer: Buffer.from(hdr) });
  await waitEdit('lights', s.answered);
  await page.waitForFunction(() => window.trilux.environment !== null && window.trilux.environment !== undefined, null, { timeout: 60000 });
  out.steps.env = { ...(await stats()), ...(await pixels()) };
  await page.screenshot({ path: dir + '/5-environment.png' });
  // Export the surface as GLB from the panel's button (the server writes
  // it into the export folder and answers with its path).
  await page.fill('#size', '64');
  await page.fill('#ename', 'page surface');
  await page.click('[data-export="glb"]');
  await page.waitForFunction(() => window.trilux.exports.length > 0 || window.trilux.errors.length > 0, null, { timeout: 60000 });
  out.steps.export = { ...(await stats()), paths: await page.evaluate(() => window.trilux.exports.map((e) => e.path)),
    hud: await page.evaluate(() => document.getElementById('status').textContent) };
  // Shortcuts with Ctrl are the browser's: copy and save neither switch
  // the mode nor toggle specular (Ctrl+R, reload, is not pressed here).
  await page.keyboard.press('Control+c'); await page.keyboard.press('Control+s');
  out.modifier_keys = await page.evaluate(() => ({ mode: window.trilux.mode, specular: document.getElementById('specular').checked }));
  // The help overlay.
  await page.keyboard.press('?');
  out.help_visible = await page.evaluate(() => !document.getElementById('helpbox').hidden);
  out.help_text = await page.evaluate(() => document.getElementById('helpbox').innerText);
  await page.screenshot({ path: dir + '/4-help.png' });
  out.logs = logs;
  out.console_errors = consoleErrors;
} catch (e) {
  if (e !== null) out.error = String(e && e.stack || e);
} finally {
  await browser.close();
}
console.log(JSON.stringify(out));
