// End-to-end test of trilux paint's scatter panel in headless Chromium:
// points by rate where the density channel is painted, a stroke that adds
// them, strands, and both exports through the buttons. Prints one JSON
// object with what it saw; the Rust test (cli/tests/all/paint_browser.rs)
// asserts on it.
//
// Usage: node scatter.mjs URL SCREENSHOT_DIR [bench POINTS]
//   bench: fills the density, scatters about POINTS points by rate, then
//   times strokes from the dab sent to the points frame drawn (medians).
import { launch, openPage } from './lib.mjs';

const [url, dir, mode, benchPoints] = process.argv.slice(2);
const browser = await launch();
const out = { steps: {} };
const consoleErrors = [];
try {
  const page = await openPage(browser, consoleErrors);
  const names = [];
  page.on('dialog', (d) => d.accept(names.shift()));
  await page.goto(url);
  await page.waitForFunction(() => window.trilux && window.trilux.ready, null, { timeout: 60000 });
  const t = () => page.evaluate(() => ({
    points: window.trilux.points, strands: window.trilux.strands, frames: window.trilux.scatterFrames,
    status: window.trilux.status, errors: window.trilux.errors, hud: document.getElementById('stats').textContent,
  }));
  const framesAfter = (n) => page.waitForFunction((n) => window.trilux.scatterFrames > n, n, { timeout: 60000 });
  // Orange pixels (the points' colour) in the canvas.
  const orange = () => page.evaluate(() => {
    const c = document.getElementById('view');
    const gl = c.getContext('webgl2');
    const px = new Uint8Array(c.width * c.height * 4);
    gl.readPixels(0, 0, c.width, c.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
    let n = 0;
    for (let i = 0; i < px.length; i += 4) if (px[i] > 230 && px[i + 1] > 90 && px[i + 1] < 140 && px[i + 2] < 60) n++;
    return n;
  });

  // The density channel as the brush's, value 1.
  await page.selectOption('#channel', { label: 'density' });
  await page.evaluate(() => { const v = document.getElementById('value'); v.value = '1'; });
  // A scalar channel shows as a heat map, with its legend in the panel.
  out.steps.legend = await page.evaluate(() => !document.getElementById('heatLegend').hidden);

  let frames = (await t()).frames;
  if (mode === 'bench') {
    // The rate that gives about POINTS points where all is painted.
    await page.selectOption('#scatterMode', 'rate');
    await page.evaluate((n) => {
      const r = document.getElementById('rate');
      r.value = String(Number(n) / window.trilux.hello.area);
      r.dispatchEvent(new Event('input'));
    }, benchPoints);
    await framesAfter(frames);
    // Fill the whole model with density 1.
    frames = (await t()).frames;
    await page.keyboard.press('g');
    await page.mouse.click(400, 300);
    await framesAfter(frames);
    out.steps.filled = await t();
    // One frame split: the mesh colours alone, the points alone, both
    // (medians of 5, each waited for).
    out.draw_ms = await page.evaluate(() => {
      const med = (parts) => {
        const v = [0, 1, 2, 3, 4].map(() => window.trilux.timeDraw(parts)).sort((a, b) => a - b);
        return v[2];
      };
      return { mesh: med({ mesh: true }), points: med({ points: true }), both: med({ mesh: true, points: true }) };
    });
    await page.keyboard.press('e');
    const times = [];
    for (let k = 0; k < 7; k++) {
      frames = (await t()).frames;
      // Across the middle of the model (the camera frames it centred).
      const x = 340 + 15 * k;
      await page.mouse.move(x, 380);
      const sent = await page.evaluate(() => performance.now());
      await page.mouse.down();
      await page.mouse.move(x + 10, 385);
      await page.mouse.up();
      await framesAfter(frames);
      await page.waitForFunction((n) => window.trilux.pointsDrawnAt > 0 && window.trilux.scatterFrames > n, frames);
      await page.waitForTimeout(50);
      const [arrived, drawn] = await page.evaluate(() => [window.trilux.pointsArrivedAt, window.trilux.pointsDrawnAt]);
      times.push(drawn - sent);
      (out.arrived_ms = out.arrived_ms || []).push(arrived - sent);
    }
    times.sort((a, b) => a - b);
    out.stroke_to_points_ms = times;
    out.median_ms = times[Math.floor(times.length / 2)];
    out.steps.after = await t();
    await page.screenshot({ path: dir + '/scatter-bench.png' });
    throw null;
  }

  // Rate mode, nothing painted yet: a points frame with no points.
  await page.selectOption('#scatterMode', 'rate');
  await framesAfter(frames);
  out.steps.rate = await t();
  out.steps.rate.orange = await orange();

  // Nothing painted: exporting the points is refused, not an empty file.
  names.push('empty.glb');
  const errorsBefore = (await t()).errors.length;
  await page.click('#exportPoints');
  await page.waitForFunction((n) => window.trilux.errors.length > n, errorsBefore, { timeout: 60000 });
  out.steps.empty_export = (await t()).errors.slice(-1)[0];

  // A count of 0 in blue-noise mode is refused by the server, and the
  // panel goes back to what is in effect (rate).
  await page.selectOption('#scatterMode', 'blue_noise');
  await page.fill('#count', '0');
  await page.waitForFunction(() => window.trilux.errors.some((e) => e.field === 'count'), null, { timeout: 60000 });
  await page.waitForFunction(() => document.getElementById('scatterMode').value === 'rate', null, { timeout: 60000 });
  out.steps.refused = { mode: await page.evaluate(() => document.getElementById('scatterMode').value) };
  frames = (await t()).frames;

  // A stroke of density 1 across the middle: points under it.
  frames = (await t()).frames;
  await page.mouse.move(330, 300);
  await page.mouse.down();
  for (let x = 340; x <= 470; x += 10) await page.mouse.move(x, 300);
  await page.mouse.up();
  await framesAfter(frames);
  await page.waitForFunction(() => window.trilux.status && window.trilux.status.points > 0 && window.trilux.status.undo === 1, null, { timeout: 60000 });
  await page.waitForTimeout(300);
  out.steps.stroke = await t();
  out.steps.stroke.orange = await orange();
  await page.screenshot({ path: dir + '/scatter-1-stroke.png' });

  // Strands on.
  frames = (await t()).frames;
  await page.check('#hair');
  await page.waitForFunction(() => window.trilux.strands > 0, null, { timeout: 60000 });
  await page.waitForTimeout(300);
  out.steps.hair = await t();
  await page.screenshot({ path: dir + '/scatter-2-hair.png' });

  // Both exports through the buttons.
  names.push('page-points.glb');
  await page.click('#exportPoints');
  await page.waitForFunction(() => window.trilux.exported.length >= 1, null, { timeout: 60000 });
  names.push('page-strands.usda');
  await page.click('#exportStrands');
  await page.waitForFunction(() => window.trilux.exported.length >= 2, null, { timeout: 60000 });
  out.steps.export = { paths: await page.evaluate(() => window.trilux.exported) };

  // The screenshot button: a PNG download of the view.
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 60000 }), page.click('#screenshot')]);
  const shot = dir + '/scatter-screenshot.png';
  await download.saveAs(shot);
  const fs = await import('node:fs');
  const bytes = fs.readFileSync(shot);
  out.steps.screenshot = { name: download.suggestedFilename(), bytes: bytes.length, png: bytes.subarray(1, 4).toString() === 'PNG' };
  // A page of another protocol version asks for a reload instead of
  // reading frames it would misread.
  out.steps.mismatch = await page.evaluate(async () => {
    const { Connection } = await import('./net.js');
    const states = [], texts = [];
    const c = new Connection('paint', (b) => b, (m) => texts.push(m.type), () => {}, (s) => states.push(s), 99);
    for (let i = 0; i < 100 && !states.some((s) => s.includes('reload')); i++) await new Promise((r) => setTimeout(r, 50));
    c.ws.onclose = null; c.ws.close();
    return { states, texts };
  });
  out.steps.autosave_note = await page.evaluate(() => document.getElementById('autosaveNote').textContent);
} catch (e) {
  if (e !== null) out.failure = String(e && e.stack || e);
} finally {
  out.console_errors = consoleErrors;
  await browser.close();
  console.log(JSON.stringify(out));
}
