// End-to-end test of trilux paint's page in headless Chromium: load, first
// frame, a stroke, the eyedropper, the detail brush, undo, redo, save and
// a GLB export through the page's buttons. Prints one JSON object with
// what it saw; the Rust test (cli/tests/all/paint_browser.rs) asserts on
// it. Usage: node paint.mjs URL SCREENSHOT_DIR [load-only]
import { launch, openPage } from './lib.mjs';

const [url, dir, only] = process.argv.slice(2);
const browser = await launch();
const out = { steps: {} };
const consoleErrors = [];
try {
  const page = await openPage(browser, consoleErrors);
  const t0 = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => window.trilux && window.trilux.ready, null, { timeout: 60000 });
  out.first_frame_ms = Date.now() - t0;
  // The canvas's pixels, kept in the page under `name` (moving 2 MB of
  // pixels to node is what would be slow); returns their hash.
  const pixels = async (name) => {
    await page.waitForTimeout(300);
    return page.evaluate((name) => {
      const c = document.getElementById('view');
      const gl = c.getContext('webgl2');
      const px = new Uint8Array(c.width * c.height * 4);
      gl.readPixels(0, 0, c.width, c.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
      (window.__px = window.__px || {})[name] = { w: c.width, h: c.height, px };
      let h = 7;
      for (let i = 0; i < px.length; i++) h = (Math.imul(h, 31) + px[i]) >>> 0;
      return h;
    }, name);
  };
  // Which pixels differ between two kept readings: a box and a count.
  const diff = (a, b) => page.evaluate(([a, b]) => {
    const A = window.__px[a], B = window.__px[b];
    let n = 0, box = [1e9, 1e9, -1, -1];
    for (let i = 0; i < A.px.length; i += 4) {
      if (Math.abs(A.px[i] - B.px[i]) + Math.abs(A.px[i + 1] - B.px[i + 1]) + Math.abs(A.px[i + 2] - B.px[i + 2]) > 6) {
        n++;
        const x = (i / 4) % A.w, y = A.h - 1 - Math.floor(i / 4 / A.w);
        box = [Math.min(box[0], x), Math.min(box[1], y), Math.max(box[2], x), Math.max(box[3], y)];
      }
    }
    return { changed: n, box };
  }, [a, b]);
  out.ms = {};
  let tStep = Date.now();
  const lap = (name) => { out.ms[name] = Date.now() - tStep; tStep = Date.now(); };
  const status = () => page.evaluate(() => window.trilux.status);
  const waitUndo = (u, r) => page.waitForFunction(([u, r]) => window.trilux.status && window.trilux.status.undo === u && window.trilux.status.redo === r, [u, r], { timeout: 60000 });
  out.steps.load = { status: await status(), hash: await pixels('load') };
  await page.screenshot({ path: dir + '/paint-1-load.png' });
  lap('load');
  if (only === 'load-only') throw null;

  // The brush ring under a hovering cursor: a circle in the plane of the
  // face there, so about the radius across and centred on the cursor.
  await page.mouse.move(400, 300);
  out.steps.ring = await page.evaluate(() => {
    const el = document.getElementById('brush');
    const pts = el.firstElementChild.getAttribute('points').trim().split(' ').map((p) => p.split(',').map(Number));
    const c = pts.reduce((a, p) => [a[0] + p[0] / pts.length, a[1] + p[1] / pts.length], [0, 0]);
    const r = pts.map((p) => Math.hypot(p[0] - 400, p[1] - 300));
    return { shown: el.style.display === 'block', points: pts.length, centroid: c,
      min_radius: Math.min(...r), max_radius: Math.max(...r), radius: Number(document.getElementById('radius').value) };
  });

  // A stroke across the middle, left to right.
  const path = [[330, 300], [470, 300]];
  await page.mouse.move(...path[0]);
  await page.mouse.down();
  for (let x = path[0][0]; x <= path[1][0]; x += 14) await page.mouse.move(x, 300);
  await page.mouse.up();
  await waitUndo(1, 0);
  out.steps.stroke = { status: await status(), hash: await pixels('stroked'), ...(await diff('load', 'stroked')),
    radius: await page.evaluate(() => Number(document.getElementById('radius').value)) };
  await page.screenshot({ path: dir + '/paint-2-stroke.png' });
  lap('stroke');

  // The eyedropper on the stroke.
  await page.keyboard.press('i');
  await page.mouse.click(400, 300);
  await page.waitForFunction(() => window.trilux.picked !== null, null, { timeout: 30000 });
  out.steps.pick = { color: await page.evaluate(() => window.trilux.picked),
    hex: await page.evaluate(() => document.getElementById('color').value) };
  lap('pick');

  // The detail brush below the stroke: more samples.
  await page.keyboard.press('d');
  await page.mouse.click(400, 380);
  await waitUndo(2, 0);
  await pixels('detailed');
  out.steps.detail = { status: await status(), ...(await diff('stroked', 'detailed')),
    notice: await page.evaluate(() => document.getElementById('busy').textContent) };
  lap('detail');

  // Undo both, redo the stroke.
  await page.keyboard.press('Control+z');
  await waitUndo(1, 1);
  await page.keyboard.press('Control+z');
  await waitUndo(0, 2);
  out.steps.undo = { status: await status(), hash: await pixels('undone'), ...(await diff('load', 'undone')) };
  await page.keyboard.press('Control+Shift+z');
  await waitUndo(1, 1);
  out.steps.redo = { hash: await pixels('redone'), ...(await diff('stroked', 'redone')) };
  lap('undo');

  // Save and export through the buttons (their prompts answered).
  const answers = ['page.meshcolors', 'page.glb'];
  page.on('dialog', (d) => d.accept(answers.shift()));
  await page.click('#save');
  await page.waitForFunction(() => window.trilux.exported.length === 1, null, { timeout: 60000 });
  await page.click('#export');
  await page.waitForFunction(() => window.trilux.exported.length === 2, null, { timeout: 120000 });
  out.steps.export = { paths: await page.evaluate(() => window.trilux.exported) };
  lap('export');
  out.help = await page.evaluate(() => document.getElementById('helpbox').textContent);
  out.errors = await page.evaluate(() => window.trilux.errors);
} catch (e) {
  if (e !== null) out.failure = String(e && e.stack || e);
} finally {
  out.console_errors = consoleErrors;
  await browser.close();
  console.log(JSON.stringify(out));
}
