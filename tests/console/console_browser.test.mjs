// adit console in a real browser (Debian's chromium, headless, software
// WebGL), against aditd replaying a simulated mine drive on loopback LCM:
//   - the page loads with no console errors; poses advance; the health shows MAPPING
//     and the loop closure; the session's pictures are offered once the payload made them;
//   - a START without the passphrase is refused with a visible message and changes nothing;
//   - unlocked, START and STOP by clicking work; two browsers watch at once;
//   - a hint typed in the form reaches the payload, whose refusal (no prior map) shows;
//   - the map renders (non-background pixels of the map canvas);
//   - the payload's live 2D grid reaches the page cell for cell (the whole
//     grid's PNG, /api/grid, decoded here, against the blocks the page fetched
//     and decoded there) and shows in the top view; its button hides it;
//   - the console restarting (a browser losing its link) shows a message, and the
//     page resumes without reloading the map (only changed tiles are fetched);
//   - a payload that stops answering (SIGSTOP) shows a message, which clears on SIGCONT;
//   - a map download's point count equals `adit download`'s, and an interrupted
//     download resumes with Range to the same bytes; the trajectory downloads too.
// Usage: node console_browser.test.mjs <build dir> [--screenshots <dir>]
// Exit 0 pass, 1 fail, 77 skip (chromium or puppeteer-core absent).
import fs from 'node:fs';
import path from 'node:path';
import assert from 'node:assert/strict';
import { setTimeout as sleep } from 'node:timers/promises';
import { adit, launchBrowser, mapCoverage, mapPixelShare, processUsage, quantile, requireBrowser, servedGrid, simulatedSession,
         startConsole, startPayload, waitFor } from './harness.mjs';

const build = path.resolve(process.argv[2] || 'build');
const shotsAt = process.argv.indexOf('--screenshots');
const screenshots = shotsAt > 0 ? path.resolve(process.argv[shotsAt + 1]) : null;
const puppeteer = await requireBrowser();

const work = path.join(build, `console-test-${process.pid}`);
fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(work, { recursive: true });
const session = simulatedSession(build, 60);
const port = 40000 + (process.pid % 20000);
const base = `http://127.0.0.1:${port}`;
const passphrase = 'correct horse battery';
fs.writeFileSync(path.join(work, 'passphrase'), adit(build, ['console', '--hash-passphrase'], { input: `${passphrase}\n` }));

const payload = await startPayload(build, work, session);
let consoleProcess = await startConsole(build, work, payload, port, ['--passphrase-file', path.join(work, 'passphrase')]);
const browser = await launchBrowser(puppeteer);
const figures = {};
let failed = false;

// Clicks `selector` once it is drawn; a list drawn again between finding the
// element and clicking it (the node replaced) is clicked again, as a person would.
async function clickWhenDrawn(page, selector) {
  for (let attempt = 0; ; ++attempt) {
    await page.waitForSelector(selector, { visible: true, timeout: 10000 });
    try {
      await page.click(selector);
      return;
    } catch (e) {
      if (attempt >= 4 || !/not clickable|detached|not an Element/.test(String(e))) throw e;
      await new Promise((resolve) => setTimeout(resolve, 200));
    }
  }
}

function watchErrors(page, errors) {
  // With the resource's address: a 404 alone does not say which request failed.
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()} ${m.location()?.url ?? ''}`); });
  page.on('pageerror', (e) => errors.push(`page: ${e.message}`));
}
const t0 = Date.now();
const step = (what) => console.log(`[${((Date.now() - t0) / 1000).toFixed(1)} s] ${what}`);
const text = (page, selector) => page.$eval(selector, (e) => (e.hidden ? '' : e.textContent));
const metrics = (page) => page.evaluate(() => ({ ...window.adit.metrics, frameTimes: undefined }));

try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  const errors = [];
  watchErrors(page, errors);
  await page.goto(base, { waitUntil: 'load' });
  await waitFor('the snapshot', async () => (await metrics(page)).hellos > 0);
  await waitFor('the IDLE state', async () => (await text(page, '#state')) === 'IDLE');

  assert.deepEqual(errors, [], 'no console errors while the page loads');
  step('Without the passphrase');
  // Without the passphrase: refused, visibly, and nothing changes.
  assert.equal(await page.$eval('#lock', (e) => e.hidden), false, 'the passphrase form shows when control is locked');
  await page.evaluate(() => { document.getElementById('start').disabled = false; });
  await page.click('#start');
  await waitFor('the refusal', async () => (await text(page, '#command-message')).startsWith('Refused'));
  assert.match(await text(page, '#command-message'), /passphrase/);
  await sleep(1500);
  assert.equal(await text(page, '#state'), 'IDLE', 'a refused START changed nothing');
  // A wrong passphrase is refused too.
  await page.type('#passphrase', 'wrong');
  await page.click('#unlock');
  await waitFor('the wrong passphrase message', async () => (await text(page, '#command-message')) === 'wrong passphrase');

  step('Unlock, name the scan');
  // Unlock, name the scan, start by clicking.
  await page.$eval('#passphrase', (e) => { e.value = ''; });
  await page.type('#passphrase', passphrase);
  await page.click('#unlock');
  await waitFor('unlocking', async () => (await text(page, '#command-message')) === 'Control unlocked');
  await page.type('#scan-name', 'drift east');
  await page.click('#start');
  await waitFor('MAPPING', async () => (await text(page, '#state')) === 'MAPPING');
  const started = await text(page, '#command-message');
  const id = (started.match(/session ([0-9TZ-]+)/) || [])[1];
  assert.ok(id, `START names its session: ${started}`);

  step('Poses advance');
  // Poses advance; a second browser watches at the same time.
  // A second browser (its own process: a background tab of the same one would not draw).
  const browser2 = await launchBrowser(puppeteer);
  const other = await browser2.newPage();
  await other.setViewport({ width: 390, height: 844, isMobile: true, hasTouch: true });
  const otherErrors = [];
  watchErrors(other, otherErrors);
  await other.goto(base, { waitUntil: 'load' });
  assert.deepEqual(otherErrors, [], 'no console errors while the phone page loads');
  const m0 = await metrics(page);
  await sleep(3000);
  const m1 = await metrics(page);
  // At scan rate (10 Hz; half of it allowed) in the optimised build. A
  // sanitizer build runs aditd several times slower (CI's ASan pass drew 13
  // poses in 3 s), so there the rate is reported and only advancing is asserted.
  figures.poses_per_s = (m1.lastSeq - m0.lastSeq) / 3;
  const minPoses = process.env.ADIT_SANITIZED ? 3 : 15;
  assert.ok(m1.lastSeq > m0.lastSeq + minPoses, `poses advance at scan rate: seq ${m0.lastSeq} -> ${m1.lastSeq} in 3 s`);
  const o1 = await metrics(other);
  assert.ok(o1.poses > 10, `the second browser gets poses too (${o1.poses})`);
  // The loop closure runs (map.loop_closure, the default): the health says
  // what it found (loop_status_t, carried in the status).
  const loopsLine = await page.evaluate(() => {
    const dt = [...document.querySelectorAll('#health-figures dt')].find((d) => d.textContent === 'loops');
    return dt ? dt.nextElementSibling.textContent : null;
  });
  assert.match(loopsLine || '', /^\d+ closed, \d+ refused \(\d+ candidates, \d+ keyframes\)/,
               `the health shows the loop closure: ${loopsLine}`);

  step('A hint');
  // A hint goes from the form to the payload and its answer comes back: this
  // session has no prior map, so the payload refuses it and says why. A hint
  // out of range is refused by the console, naming the field.
  await page.type('#hint-x', '12.5');
  await page.type('#hint-y', '-3');
  await page.type('#hint-heading', '90');
  await page.click('#send-hint');
  await waitFor('the payload\'s answer to the hint', async () => (await text(page, '#command-message')).startsWith('HINT refused'));
  assert.match(await text(page, '#command-message'), /no prior map/);
  const outOfRange = await page.evaluate(async (token) => {
    const r = await fetch('/api/command', { method: 'POST', headers: { 'Content-Type': 'application/json', 'X-Adit-Token': token },
                                            body: JSON.stringify({ verb: 'HINT', x: 1, y: 2, radius: 500 }) });
    return { status: r.status, body: await r.json() };
  }, await page.evaluate(() => sessionStorage.getItem('adit-token')));
  assert.equal(outOfRange.status, 400, JSON.stringify(outOfRange));
  assert.match(outOfRange.body.error, /radius/);
  assert.equal(await text(page, '#state'), 'MAPPING', 'a refused hint changed nothing');

  step('The map renders.');
  // The map renders.
  await waitFor('map tiles', async () => (await metrics(page)).tileFetches > 3, 20000);
  await page.click('#camera-modes button[data-mode="top"]');
  await sleep(1500);
  figures.coverage_top = await mapCoverage(page);
  assert.ok(figures.coverage_top > 0.02, `the map covers ${(100 * figures.coverage_top).toFixed(1)} % of the view`);
  await page.click('#camera-modes button[data-mode="follow"]');
  // The payload's frame (frame_t: a prior map's anchor, or gravity's level)
  // places the whole view: the pose marker moves with it, and back. This drive
  // has no prior and an accelerometer: the tiles' frame is the level, a turn
  // of under 1° about a horizontal axis through the first pose (decision 060).
  // The odometry's frame is that times the loop closure's latest correction
  // (docs/LOOPS.md, *Live tiles*): identity until a loop closes, then a few
  // centimetres on this drive (a slow run drives far enough to close one).
  const mapFrame = await page.evaluate(() => window.adit.metrics.mapFrame);
  const frameText = JSON.stringify(mapFrame);
  assert.equal(mapFrame?.source, 'level', frameText);
  const { tp, tq } = mapFrame;
  assert.deepEqual(tp, [0, 0, 0], frameText);
  assert.ok(Math.abs(tq[3]) < 1e-9 && 2 * Math.acos(Math.min(1, Math.abs(tq[0]))) < Math.PI / 180, frameText);
  assert.ok(Math.hypot(...mapFrame.p.map((c, i) => c - tp[i])) < 0.1, frameText);
  const shift = await page.evaluate(() => {
    const v = window.adit.view;
    const before = v.markerPosition();
    const local = v.marker.position.clone();  // in the odometry frame
    v.setFrame({ p: [100, -20, 0], q: [Math.SQRT1_2, 0, 0, Math.SQRT1_2] });  // a quarter turn about z
    const after = v.markerPosition();
    v.setFrame(window.adit.metrics.mapFrame);
    const back = v.markerPosition();
    return { x: after.x - (100 - local.y), y: after.y - (-20 + local.x), back: back.distanceTo(before) };
  });
  assert.ok(Math.abs(shift.x) < 1e-3 && Math.abs(shift.y) < 1e-3 && shift.back < 1e-6, JSON.stringify(shift));
  // The pose graph's path (graph_path_t, after a loop closed; this drive's
  // first loop comes after the stop, so the page is given one as the
  // console's graph_path event would: ConsoleGraphPath.* tests that side):
  // drawn with the tiles, and the poses' path kept from its newest keyframe on.
  // A slow run may have closed a real loop already, whose graph path cut the
  // poses' path to its newest keyframe: the path grows again as poses come.
  await waitFor('a path of more than 10 points', async () => page.evaluate(() => window.adit.view.pathCount > 10), 20000);
  const graphPath = await page.evaluate(() => {
    const v = window.adit.view;
    const n = v.pathCount;
    const mid = v.pathTimes[Math.floor(n / 2)];
    const kept = Array.from(v.pathTimes.subarray(0, n)).filter((t) => t >= mid).length;
    v.setGraphPath({ utime: mid, points: [[0, 0, 0], [1, 0, 0], [2, 1, 0]] });
    return { before: n, after: v.pathCount, kept, first: v.pathTimes[0], mid, withTiles: v.graphPath.parent === v.tilesWorld,
             visible: v.graphPath.visible, drawn: v.graphGeometry.drawRange.count };
  });
  assert.ok(graphPath.before > 10 && graphPath.after === graphPath.kept && graphPath.after < graphPath.before &&
            graphPath.first >= graphPath.mid && graphPath.withTiles && graphPath.visible && graphPath.drawn === 3,
            JSON.stringify(graphPath));
  if (screenshots) {
    await waitFor('the phone page to draw the map', async () => (await metrics(other)).tileFetches > 3, 20000);
    await other.screenshot({ path: path.join(screenshots, 'console-phone.png') });
  }
  assert.deepEqual(otherErrors, [], 'no console errors in the phone page');
  await browser2.close();

  step("The console's CPU");
  // The console's CPU and memory while one browser watches.
  const u0 = processUsage(consoleProcess.pid);
  const t0 = Date.now();
  await sleep(5000);
  const u1 = processUsage(consoleProcess.pid);
  figures.console_cpu_percent = (100 * (u1.cpu_s - u0.cpu_s)) / ((Date.now() - t0) / 1000);
  figures.console_rss_mb = u1.rss_kb / 1024;
  if (screenshots) {
    await page.screenshot({ path: path.join(screenshots, 'console-tablet.png') });
  }

  step('The link breaks');
  // The link breaks (the console restarts): a visible message, then the
  // stream resumes without loading the map again.
  const before = await metrics(page);
  const tilesBefore = await page.evaluate(() => window.adit.view.tiles.size);
  await consoleProcess.stop();
  await waitFor('the lost-link message', async () => (await text(page, '#banner')).includes('Connection to the console lost'));
  consoleProcess = await startConsole(build, work, payload, port, ['--passphrase-file', path.join(work, 'passphrase')]);
  await waitFor('the stream resuming', async () => (await metrics(page)).hellos > before.hellos, 15000);
  await waitFor('the message clearing', async () => (await text(page, '#banner')) === '');
  const tilesAfter = await page.evaluate(() => window.adit.view.tiles.size);
  assert.ok(tilesAfter >= tilesBefore, `the map stays after reconnecting (${tilesBefore} -> ${tilesAfter} tiles)`);
  await sleep(2000);
  const after = await metrics(page);
  figures.reconnect_tile_fetches = after.tileFetches - before.tileFetches;
  figures.tiles_held = tilesAfter;
  assert.ok(after.lastSeq > before.lastSeq, 'poses flow again after reconnecting');

  step('Stop by clicking');
  // Stop by clicking. The restarted console holds no tokens (they live in its
  // memory): the page is refused, shows the passphrase field again, and stops
  // once unlocked anew.
  await page.click('#stop');
  await waitFor('the refusal of a stale token', async () => (await text(page, '#command-message')).startsWith('Refused'));
  assert.equal(await page.$eval('#lock', (e) => e.hidden), false, 'the passphrase field is back');
  await page.type('#passphrase', passphrase);
  await page.click('#unlock');
  await waitFor('unlocking again', async () => (await text(page, '#command-message')) === 'Control unlocked');
  await page.click('#stop');
  await waitFor('STOP accepted', async () => (await text(page, '#command-message')).startsWith('STOP: '));
  await waitFor('IDLE after STOP', async () => (await text(page, '#state')) === 'IDLE', 30000);
  const lat = (await metrics(page)).latencies;
  figures.latency_ms_p50 = quantile(lat, 0.5);
  figures.latency_ms_p95 = quantile(lat, 0.95);
  figures.latency_samples = lat.length;

  step('The 2D grid');
  // The session's grid, as the console serves it (decoded here) and as the
  // page holds it (decoded there), once the page has the version served.
  const grids = await waitFor('the page to hold the grid the console serves', async () => {
    const served = await servedGrid(base);
    const held = await page.evaluate(() => window.adit.view.grid.summary());
    return served && held && held.v === served.v ? { served, held } : null;
  }, 30000, 500);
  const { served, held } = grids;
  const { bytes: _, ...servedSummary } = served;
  assert.deepEqual(held, servedSummary, 'the page holds the served grid cell for cell');
  figures.grid_cells = `${served.width} x ${served.height}`;
  figures.grid_occupied = served.occupied;
  figures.grid_free = served.free;
  figures.grid_png_bytes = served.bytes;
  const m = await metrics(page);
  figures.grid_fetches = m.gridFetches;
  figures.grid_blocks_fetched = m.gridBlocks;
  figures.grid_bytes_fetched = m.gridBytes;
  assert.equal(served.session, id, 'the grid is the session\'s');
  assert.ok(served.occupied > 1000 && served.free > 10000, `a mine drive's grid: ${JSON.stringify(served)}`);
  assert.equal(await text(page, '#grid-text'), ` · grid ${(served.width * served.resolution).toFixed(0)} × ${
    (served.height * served.resolution).toFixed(0)} m`);
  // In the top view the grid is drawn over the points (pixels of exactly the
  // free cells' colour); its button hides it.
  const freeShare = async () => mapPixelShare(page, await page.evaluate(() => window.adit.view.grid.freeColour));
  await page.click('#camera-modes button[data-mode="top"]');
  await sleep(1000);
  figures.grid_free_share_top = await freeShare();
  await page.click('#grid-toggle');
  await sleep(1000);
  const hidden = await freeShare();
  assert.equal(await page.$eval('#grid-toggle', (b) => b.getAttribute('aria-pressed')), 'false');
  assert.ok(figures.grid_free_share_top > 0.01 && hidden < figures.grid_free_share_top / 10,
            `the grid's free cells show in the top view (${(100 * figures.grid_free_share_top).toFixed(2)} % of the ` +
            `pixels), and not once hidden (${(100 * hidden).toFixed(2)} %)`);
  await page.click('#grid-toggle');
  await page.click('#camera-modes button[data-mode="follow"]');

  step('The payload stops answering');
  // The payload stops answering: a visible message; it clears when it answers again.
  payload.aditd.signal('SIGSTOP');
  await waitFor('the silent-payload message', async () => (await text(page, '#banner')).includes('is not answering'), 8000);
  payload.aditd.signal('SIGCONT');
  await waitFor('the payload answering again', async () => (await text(page, '#banner')) === '', 8000);

  step('A map download');
  // A map download: prepared by the console over LCM, saved by the browser.
  await page.click('#refresh-sessions');
  const item = `#session-list li[data-session="${id}"]`;
  await waitFor('the session in the list', async () => (await page.$(item)) !== null);
  assert.match(await text(page, item), /drift east/, 'the scan keeps its name');
  // The list is drawn again when the refresh answers: click the button as it is then.
  await clickWhenDrawn(page, `${item} button[data-format="ply"]`);
  try {
    await waitFor('the map prepared', async () => (await page.$(`${item} a[data-format="ply"]`)) !== null, 30000);
  } catch (e) {
    // What the console's download came to (its state and error): once, in a clean-clone CI run on
    // 2026-11-27, it was not prepared within 30 s and passed on the next run.
    const jobs = await page.evaluate(async () => (await fetch('/api/downloads')).text());
    throw new Error(`${e.message}; the console's downloads: ${jobs}`);
  }
  const consolePoints = Number(await page.$eval(`${item} a[data-format="ply"]`, (a) => a.dataset.points));
  const url = await page.$eval(`${item} a[data-format="ply"]`, (a) => a.href);
  const cli = adit(build, ['download', ...payload.client, '--session', id, '--format', 'ply', '--quiet', '--out',
                           path.join(work, 'cli.ply')]);
  const cliPoints = Number(cli.match(/^(\d+) points/)[1]);
  figures.download_points = consolePoints;
  assert.equal(consolePoints, cliPoints, '`adit console` and `adit download` give the same map');
  step('Interrupted half way');
  // Interrupted half way, resumed with Range: the same bytes as in one go.
  const whole = Buffer.from(await (await fetch(url)).arrayBuffer());
  const half = Math.floor(whole.length / 2);
  const first = await fetch(url, { headers: { Range: `bytes=0-${half - 1}` } });
  const rest = await fetch(url, { headers: { Range: `bytes=${half}-` } });
  assert.equal(first.status, 206);
  assert.equal(rest.status, 206);
  assert.equal(rest.headers.get('content-range'), `bytes ${half}-${whole.length - 1}/${whole.length}`);
  const joined = Buffer.concat([Buffer.from(await first.arrayBuffer()), Buffer.from(await rest.arrayBuffer())]);
  assert.ok(joined.equals(whole), 'the resumed download has the same bytes');
  const header = whole.subarray(0, 400).toString('latin1');
  assert.equal(Number(header.match(/element vertex (\d+)/)[1]), cliPoints, 'the PLY holds every point');
  assert.ok(fs.readFileSync(path.join(work, 'cli.ply')).equals(whole), 'byte for byte the file `adit download` wrote');
  // The trajectory, read from the sessions folder (the console on the payload), with Range too.
  const trajectoryUrl = await page.$eval(`${item} a[href$="trajectory.tum"]`, (a) => a.href);
  const trajectory = await (await fetch(trajectoryUrl)).text();
  const onDisk = fs.readFileSync(path.join(work, 'state/sessions', id, 'trajectory.tum'), 'utf8');
  assert.equal(trajectory, onDisk);
  assert.ok(onDisk.split('\n').length > 20, 'poses in the trajectory');
  const tail = await fetch(trajectoryUrl, { headers: { Range: 'bytes=10-' } });
  assert.equal(tail.status, 206);
  assert.equal(await tail.text(), onDisk.slice(10));

  step('The pictures');
  // The payload makes the session's pictures after it stops (products, at idle
  // priority): the list offers the top view once made, and it is the payload's file.
  const topView = `${item} a[data-picture="top_view"]`;
  await waitFor('the top view offered', async () => {
    if ((await page.$(topView)) !== null) return true;
    await page.click('#refresh-sessions');
    await sleep(2000);
    return false;
  }, 120000, 0);
  const picture = Buffer.from(await (await fetch(await page.$eval(topView, (a) => a.href))).arrayBuffer());
  assert.ok(picture.subarray(0, 8).equals(Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a])), 'a PNG');
  assert.ok(picture.equals(fs.readFileSync(path.join(work, 'state/sessions', id, 'products/top_view.png'))),
            'the payload\'s top view, byte for byte');
  figures.top_view_bytes = picture.length;
  const sections = await page.$eval(`${item} a[data-picture="sections"]`, (a) => a.textContent);
  assert.match(sections, /^Sections \(\d+\)$/, 'the cross-sections are offered');

  // Afterwards only the failures this test provokes: refused commands and a
  // wrong passphrase (403), the hint the payload refused (409) and the one out
  // of range (400), the stream cut by the console's restart.
  const expected = /status of 40[039] \((Forbidden|Conflict|Bad Request)\)|ERR_INCOMPLETE_CHUNKED_ENCODING|ERR_CONNECTION_REFUSED|ERR_EMPTY_RESPONSE/;
  assert.deepEqual(errors.filter((e) => !expected.test(e)), [], 'no other console errors in the tablet page');
  // The live view's target (pose on LCM -> drawn <= 200 ms at p95) is a speed
  // figure: printed here and reported in docs/CONSOLE.md, not asserted on a
  // shared CI machine. What is asserted is that poses stream at all: a stalled
  // or buffered stream (seconds) fails.
  assert.ok(figures.latency_ms_p95 <= 1000, `latency p95 ${figures.latency_ms_p95} ms: the pose stream stalls`);
} catch (e) {
  failed = true;
  console.error(`FAIL: ${e.stack || e}`);
} finally {
  console.log(`figures: ${JSON.stringify(figures)}`);
  await browser.close();
  await consoleProcess.stop();
  await payload.aditd.stop();
  if (!failed) fs.rmSync(work, { recursive: true, force: true });
  else console.error(`logs kept in ${work}`);
}
process.exit(failed ? 1 : 0);
