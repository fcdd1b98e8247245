// `tracer view` in a real browser: headless Chromium (Debian's) driven by playwright-core. Loads
// the page, sees frames arrive and the samples per pixel rise, drags, wheels and flies the camera
// and sees the accumulation restart, changes the integrator, copies the command and runs it (its
// image equals the page's saved PNG), takes a screenshot, finds no console error, and stops the
// server with Ctrl-C (exit 130).
//   node tests/browser/view.test.mjs TRACER_BINARY OUT_DIR
// Exit 0 passed, 1 failed, 77 skipped (no Chromium on this machine).
import assert from 'node:assert/strict';
import { execFileSync, spawn } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

const [tracer, outDir] = process.argv.slice(2);
if (!tracer || !outDir) {
  console.error('usage: node view.test.mjs TRACER_BINARY OUT_DIR');
  process.exit(2);
}
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
if (!fs.existsSync(chromiumPath)) {
  console.log(`SKIP: no Chromium at ${chromiumPath} (scripts/setup.sh --deps installs Debian's chromium)`);
  process.exit(77);
}
let chromium;
try {
  ({ chromium } = await import('playwright-core'));
} catch (e) {
  // Outside CI a machine that cannot reach the npm registry still runs every other test.
  if (process.env.CI !== 'true') {
    console.log('SKIP: playwright-core is not installed (npm ci --prefix tests/browser failed or was not run)');
    process.exit(77);
  }
  console.error('playwright-core is not installed: run npm ci --prefix tests/browser (scripts/test.sh does)');
  process.exit(1);
}
fs.mkdirSync(outDir, { recursive: true });

// The flags Chromium needs as root on a machine without network (the env's notes).
export const chromiumArgs = ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync', '--disable-dev-shm-usage'];

function startViewer(args) {
  const child = spawn(tracer, ['view', '--port', '0', ...args], { stdio: ['ignore', 'pipe', 'pipe'] });
  let stderr = '';
  child.stderr.on('data', (d) => { stderr += d; });
  const url = new Promise((resolve, reject) => {
    let out = '';
    child.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/\S+/);
      if (m) resolve(m[0]);
    });
    child.on('exit', (code) => reject(new Error(`tracer view exited ${code}: ${stderr}`)));
  });
  const exited = new Promise((resolve) => child.on('exit', (code, signal) => resolve({ code, signal, stderr })));
  return { child, url, exited, stderr: () => stderr };
}

const viewer = startViewer(['--threads', '2', '--width', '160', '--height', '120', '--spp', '16']);
const url = await viewer.url;
const browser = await chromium.launch({ executablePath: chromiumPath, args: chromiumArgs });
let failed = false;
try {
  const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 900, height: 600 } });
  await context.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: new URL(url).origin });
  const page = await context.newPage();
  const consoleErrors = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(String(e)));
  await page.goto(url);

  const lastFrame = () => page.evaluate(() => window.tracerView.metrics.lastFrame);
  const viewState = () => page.evaluate(() => window.tracerView.state());
  const waitFor = (fn, arg) => page.waitForFunction(fn, arg, { timeout: 60000 });
  // Every change sent and answered, then the state.
  const settledState = async (g) => {
    await waitFor((after) => window.tracerView.idle() && window.tracerView.state().generation > after, g);
    return viewState();
  };

  // Frames arrive, path tracing's denoised once the view rests (the toggle on by default).
  await waitFor(() => window.tracerView.metrics.lastFrame?.complete === true);
  assert.equal((await lastFrame()).mime, 'image/png');
  assert.equal((await lastFrame()).denoised, true);
  assert.ok(await page.isChecked('#denoise'));
  assert.match(await page.textContent('#spp'), /^16 \/ 16, denoised$/);
  // The toggle off: the accumulation starts again, noisy and refined tile by tile; with a higher
  // target the samples per pixel rise pass by pass, shown on the panel.
  await page.uncheck('#denoise');
  await waitFor(() => {
    const v = window.tracerView;
    return !v.state().denoise && v.metrics.lastFrame?.generation === v.state().generation && v.metrics.lastFrame.complete;
  });
  assert.equal((await lastFrame()).denoised, false);
  assert.match(await page.textContent('#spp'), /^16 \/ 16$/);
  await page.fill('#spp-target', '4096');
  await page.press('#spp-target', 'Enter');
  await waitFor(() => {
    const v = window.tracerView;
    const g = v.state().generation;
    return v.state().spp === 4096 && new Set(v.metrics.log.filter((f) => f.generation === g && !f.preview).map((f) => f.spp)).size >= 4;
  });
  const rising = await page.evaluate(() => {
    const g = window.tracerView.state().generation;
    return window.tracerView.metrics.log.filter((f) => f.generation === g && !f.preview).map((f) => f.spp);
  });
  assert.ok(rising.every((spp, i) => i === 0 || spp >= rising[i - 1]), `spp never falls: ${rising}`);
  assert.match(await page.textContent('#spp'), /^\d+\+? \/ 4096$/);
  await page.fill('#spp-target', '16');
  await page.press('#spp-target', 'Enter');
  await waitFor(() => {
    const v = window.tracerView;
    return v.state().spp === 16 && v.metrics.lastFrame.generation === v.state().generation && v.metrics.lastFrame.complete;
  });

  // Dragging orbits the camera; the accumulation restarts from the new state.
  const before = await viewState();
  const box = await page.locator('#view').boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  for (let i = 1; i <= 10; ++i) await page.mouse.move(cx + 8 * i, cy + 2 * i);
  await page.mouse.up();
  await settledState(before.generation);
  await waitFor(() => {
    const v = window.tracerView;
    return v.metrics.lastFrame.generation === v.state().generation && v.metrics.lastFrame.complete;
  });
  const afterDrag = await viewState();
  assert.notDeepEqual(afterDrag.eye, before.eye, 'the drag moved the eye');
  assert.deepEqual(afterDrag.look, before.look, 'orbiting keeps the look point');
  const restarted = await page.evaluate((g) => window.tracerView.metrics.log.filter((f) => f.generation > g), before.generation);
  assert.ok(restarted.some((f) => f.preview || f.spp < 16), 'a frame of the new state before it finished');
  const latencies = await page.evaluate(() => window.tracerView.metrics.latencies.length);
  assert.ok(latencies >= 1, 'a move was followed by a frame of its state');

  // Shift-drag pans (eye and look move together), the wheel dollies, W flies forward.
  await page.keyboard.down('Shift');
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  await page.mouse.move(cx + 30, cy, { steps: 3 });
  await page.mouse.up();
  await page.keyboard.up('Shift');
  let s = await settledState(afterDrag.generation);
  assert.notDeepEqual(s.look, afterDrag.look, 'panning moves the look point');
  const beforeWheel = s;
  await page.mouse.wheel(0, 300);
  s = await settledState(beforeWheel.generation);
  const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  assert.ok(dist(s.eye, s.look) > dist(beforeWheel.eye, beforeWheel.look), 'wheel down dollies out');
  const beforeFly = s;
  await page.locator('#view').click({ position: { x: 5, y: 5 } });
  await page.keyboard.down('w');
  await page.waitForTimeout(300);
  await page.keyboard.up('w');
  s = await settledState(beforeFly.generation);
  assert.ok(dist(s.eye, beforeFly.look) < dist(beforeFly.eye, beforeFly.look), 'W flies toward the look point');

  // A lens from the panel; a click (no drag) focuses it on the surface under the pointer.
  await page.fill('#aperture', '0.05');
  await page.press('#aperture', 'Enter');
  s = await settledState(s.generation);
  assert.equal(s.aperture, 0.05);
  await page.mouse.click(cx, cy);
  const focused = await settledState(s.generation);
  assert.notEqual(focused.focus_distance, s.focus_distance, 'a click sets the focus distance');
  assert.match(focused.command, /--aperture 0.05 --focus-distance /);

  // The panel: another integrator and target; a bad value gets the server's message.
  await page.selectOption('#integrator', 'ao');
  await page.fill('#spp-target', '4');
  await page.press('#spp-target', 'Enter');
  await waitFor(() => window.tracerView.state().integrator === 'ao' && window.tracerView.state().spp === 4);
  await page.fill('#width', '0');
  await page.press('#width', 'Enter');
  await waitFor(() => document.querySelector('#status').textContent.includes('width: must be between 1 and 4096, got 0'));
  await page.fill('#width', '150');
  await page.press('#width', 'Enter');
  await waitFor(() => window.tracerView.state().width === 150);
  await waitFor(() => {
    const v = window.tracerView;
    return v.metrics.lastFrame.generation === v.state().generation && v.metrics.lastFrame.complete;
  });

  // Copy command; save PNG; the command renders the same image.
  await page.click('#copy');
  const copied = await page.evaluate(() => navigator.clipboard.readText());
  assert.equal(copied, (await viewState()).command);
  assert.match(copied, /^tracer render .*--integrator ao --spp 4 /);
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#save-png')]);
  const saved = path.join(outDir, 'view-saved.png');
  await download.saveAs(saved);
  const rendered = path.join(outDir, 'view-rendered.png');
  const command = copied.replace(/^tracer /, JSON.stringify(tracer) + ' ') + ` -q -o ${JSON.stringify(rendered)}`;
  execFileSync('/bin/sh', ['-c', command]);
  const compare = execFileSync(tracer, ['compare', saved, rendered]).toString();
  assert.match(compare, /RMSE 0, largest difference 0/, compare);

  await page.screenshot({ path: path.join(outDir, 'view-screenshot.png') });
  // The one error expected: Chromium logs the 400 that the deliberate width 0 got.
  const bad = consoleErrors.findIndex((m) => m.includes('status of 400'));
  if (bad >= 0) consoleErrors.splice(bad, 1);
  assert.deepEqual(consoleErrors, [], 'console errors');
  console.log(`ok: frames, spp to 16, orbit/pan/dolly/fly, panel, copy command = saved PNG, screenshot in ${outDir}`);
} catch (e) {
  failed = true;
  console.error(e);
  console.error('tracer view said:', viewer.stderr());
} finally {
  await browser.close();
}

// Ctrl-C stops the server at once, mid-frame: exit 130.
viewer.child.kill('SIGINT');
const end = await viewer.exited;
if (end.code !== 130 || !/interrupted/.test(end.stderr)) {
  console.error(`tracer view after SIGINT: exit ${end.code} (signal ${end.signal}), stderr: ${end.stderr}`);
  failed = true;
}
process.exit(failed ? 1 : 0);
