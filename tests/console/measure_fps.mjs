// Frames per second of the console's live view with a large map, in headless
// chromium with software WebGL (SwiftShader), drawing every animation frame
// (?continuous=1) at several point budgets. The map is synthetic: `points`
// points of a 4 m x 3 m tunnel walls in 20 m tiles (a 60-minute drive maps
// several million), decimated by the page's own rule (a power-of-two stride
// down to the budget). No payload is needed: the console serves the page.
// Usage: node measure_fps.mjs <build dir> [points=5000000] [budgets=1000000,300000,150000,75000]
import fs from 'node:fs';
import path from 'node:path';
import { setTimeout as sleep } from 'node:timers/promises';
import { launchBrowser, Process, requireBrowser, waitFor } from './harness.mjs';

const build = path.resolve(process.argv[2] || 'build');
const points = Number(process.argv[3] || 5000000);
const budgets = (process.argv[4] || '1000000,300000,150000,75000').split(',').map(Number);
const puppeteer = await requireBrowser();
const port = 40000 + ((process.pid + 7) % 20000);
const work = fs.mkdtempSync('/tmp/adit-fps-');
const console_ = new Process([path.join(build, 'bin/adit'), 'console', '--payload', 'fps', '--lcm-url',
                              `udpm://239.255.76.67:${20000 + (process.pid % 30000)}?ttl=0`, '--listen',
                              `127.0.0.1:${port}`, '--data-dir', work], path.join(work, 'console.log'));
await waitFor('the console', async () => { try { return (await fetch(`http://127.0.0.1:${port}/api/config`)).ok; } catch { return false; } });
const browser = await launchBrowser(puppeteer);
const results = [];
try {
  for (const budget of budgets) {
    const page = await browser.newPage();
    await page.setViewport({ width: 1280, height: 800 });
    await page.goto(`http://127.0.0.1:${port}/?continuous=1&budget=${budget}`, { waitUntil: 'load' });
    const drawn = await page.evaluate((total, budget) => {
      let every = 1;
      while (total / every > budget) every *= 2;
      const view = window.adit.view;
      const perTile = 80000;  // points per 20 m of tunnel before decimation
      let seed = 1;
      const rnd = () => ((seed = (seed * 1664525 + 1013904223) >>> 0) / 4294967296);
      for (let tile = 0; tile * perTile < total; ++tile) {
        const n = Math.min(perTile, total - tile * perTile);
        const kept = Math.ceil(n / every);
        const xyz = new Float32Array(kept * 3);
        for (let i = 0; i < kept; ++i) {
          const along = tile * 20 + rnd() * 20, around = rnd() * 14;  // the 4 x 3 m section's perimeter
          const [y, z] = around < 4 ? [around - 2, 0] : around < 7 ? [2, around - 4] : around < 11 ? [2 - (around - 7), 3] : [-2, 3 - (around - 11)];
          xyz.set([along, y, z], i * 3);
        }
        view.setTile(String(tile), 1, every, 0, 1, [xyz]);
      }
      view.setPose({ p: [total / perTile * 10, 0, 1], q: [1, 0, 0, 0], valid: true });
      view.setMode('free');
      view.orbit.distance = total / perTile * 12;
      view.orbit.target.set(total / perTile * 10, 0, 0);
      return view.pointCount();
    }, points, budget);
    await sleep(1500);  // shaders compiled, buffers uploaded
    const fps = await page.evaluate(async () => {
      const f0 = window.adit.metrics.frames, t0 = performance.now();
      await new Promise((r) => setTimeout(r, 5000));
      return (window.adit.metrics.frames - f0) * 1000 / (performance.now() - t0);
    });
    results.push({ map_points: points, budget, drawn, fps: Number(fps.toFixed(1)) });
    console.log(JSON.stringify(results.at(-1)));
    await page.close();
  }
} finally {
  await browser.close();
  await console_.stop();
  fs.rmSync(work, { recursive: true, force: true });
}
