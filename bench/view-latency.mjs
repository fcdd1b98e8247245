// tracer view measured in the browser (headless Chromium, playwright-core from tests/browser):
// for every view of views.tsv, the time from a camera move to the first frame of the moved camera
// on screen, frames per second while the mouse drags at 60 events/s, and at rest.
//   node bench/view-latency.mjs TRACER VIEWS_TSV [threads] [extra tracer view flags...]
// Prints one Markdown table row per view.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';

const require = createRequire(new URL('../tests/browser/package.json', import.meta.url));
const { chromium } = require('playwright-core');

const [tracer, viewsPath, threads = '2', ...extra] = process.argv.slice(2);
const views = fs.readFileSync(viewsPath, 'utf8').trim().split('\n').slice(1).map((l) => l.split('\t')[0]);
const chromiumArgs = ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync', '--disable-dev-shm-usage'];
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const median = (a) => { const s = [...a].sort((x, y) => x - y); return s[Math.floor(s.length / 2)]; };
const quantile = (a, q) => { const s = [...a].sort((x, y) => x - y); return s[Math.min(s.length - 1, Math.floor(q * s.length))]; };

async function measure(view) {
  const child = spawn(tracer, ['view', '--view', view, '--views', viewsPath, '--port', '0', '--threads', threads, '-q', ...extra],
    { stdio: ['ignore', 'pipe', 'inherit'] });
  const url = await new Promise((resolve, reject) => {
    let out = '';
    child.stdout.on('data', (d) => { out += d; const m = out.match(/http:\/\/\S+/); if (m) resolve(m[0]); });
    child.on('exit', (code) => reject(new Error(`tracer view --view ${view} exited ${code}`)));
  });
  const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', args: chromiumArgs });
  try {
    const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
    await page.goto(url);
    await page.waitForFunction(() => window.tracerView.metrics.log.some((f) => !f.preview), null, { timeout: 120000 });
    const box = await page.locator('#view').boundingBox();
    const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
    const generation = () => page.evaluate(() => window.tracerView.state().generation);

    // Single moves from rest: one mouse step, then the first frame of that camera.
    const single = [];
    for (let i = 0; i < 8; ++i) {
      await sleep(400);
      const g0 = await generation();
      await page.evaluate(() => { window.tracerView.metrics.latencies.length = 0; });
      await page.mouse.move(cx, cy);
      await page.mouse.down();
      await page.mouse.move(cx + (i % 2 ? -6 : 6), cy);
      await page.mouse.up();
      await page.waitForFunction((g) => window.tracerView.state().generation > g && window.tracerView.metrics.latencies.length > 0, g0,
        { timeout: 30000 });
      single.push(await page.evaluate(() => window.tracerView.metrics.latencies[0]));
    }

    // A drag of 2 s at 60 mouse events per second.
    await sleep(400);
    await page.evaluate(() => { window.tracerView.metrics.latencies.length = 0; });
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    const t0 = await page.evaluate(() => performance.now());
    const framesBefore = await page.evaluate(() => window.tracerView.metrics.frames);
    const movesBefore = await page.evaluate(() => window.tracerView.metrics.cameraMoves);
    for (let i = 0; i < 120; ++i) {
      await page.mouse.move(cx + 100 * Math.sin(i / 20), cy + 20 * Math.sin(i / 13));
      await sleep(16);
    }
    const moving = await page.evaluate(([t, f]) => ({
      seconds: (performance.now() - t) / 1000, frames: window.tracerView.metrics.frames - f[0], moves: window.tracerView.metrics.cameraMoves - f[1],
      latencies: [...window.tracerView.metrics.latencies] }), [t0, [framesBefore, movesBefore]]);
    await page.mouse.up();

    // At rest: frames per second over the 3 s after the drag.
    await sleep(300);
    const rest = await page.evaluate(async () => {
      const f0 = window.tracerView.metrics.frames, t = performance.now();
      await new Promise((r) => setTimeout(r, 3000));
      return { frames: window.tracerView.metrics.frames - f0, seconds: (performance.now() - t) / 1000,
               last: window.tracerView.metrics.lastFrame };
    });
    return { view, single, moving, rest };
  } finally {
    await browser.close();
    child.kill('SIGINT');
  }
}

console.log('| view | move to frame, single moves: median / worst (ms) | dragging: camera moves/s | dragging: frames/s | move to frame while dragging: median / 90 % (ms) | at rest: frames/s | spp after 3.3 s at rest |');
console.log('|---|---:|---:|---:|---:|---:|---:|');
for (const view of views) {
  const r = await measure(view);
  const fps = r.moving.frames / r.moving.seconds;
  const lat = r.moving.latencies;
  console.log(`| ${view} | ${median(r.single).toFixed(0)} / ${Math.max(...r.single).toFixed(0)} | ` +
    `${(r.moving.moves / r.moving.seconds).toFixed(1)} | ${fps.toFixed(1)} | ` +
    `${median(lat).toFixed(0)} / ${quantile(lat, 0.9).toFixed(0)} | ${(r.rest.frames / r.rest.seconds).toFixed(1)} | ${r.rest.last.spp} |`);
}
