// The parts the console's browser tests share: a simulated session generated
// once per build tree, aditd replaying it on loopback LCM (a pid-based port,
// ttl=0), adit console on a pid-based HTTP port, and Debian's chromium driven
// by puppeteer-core. Used by console_browser.test.mjs and measure.mjs.
import { spawn, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';
import { setTimeout as sleep } from 'node:timers/promises';

export const CHROMIUM = process.env.ADIT_CHROMIUM || '/usr/bin/chromium';

// Exits with 77 (ctest's SKIP_RETURN_CODE) and a message when a part is missing.
export async function requireBrowser() {
  if (!fs.existsSync(CHROMIUM)) skip(`${CHROMIUM} is absent (scripts/install-deps.sh installs chromium)`);
  try {
    return (await import('puppeteer-core')).default;
  } catch {
    skip('puppeteer-core is not installed in tests/console/node_modules (scripts/install-deps.sh runs npm ci)');
  }
}

export function skip(why) {
  console.log(`SKIP: ${why}`);
  process.exit(77);
}

export function adit(build, args, options = {}) {
  return execFileSync(path.join(build, 'bin/adit'), args, { encoding: 'utf8', ...options });
}

// A simulated drive through the mine (`seconds` long), made once per build tree.
export function simulatedSession(build, seconds) {
  const dir = path.join(build, `console-session-${seconds}s`);
  if (!fs.existsSync(path.join(dir, 'lidar.pcap'))) {
    adit(build, ['sim', '--scene', 'mine', '--platform', 'robot', '--sensor', 'VLP-16', '--duration', String(seconds),
                 '--seed', '3', '--out', dir]);
  }
  return dir;
}

export class Process {
  constructor(argv, log) {
    const out = fs.openSync(log, 'w');
    this.log = log;
    this.child = spawn(argv[0], argv.slice(1), { stdio: ['ignore', out, out] });
    this.exited = new Promise((resolve) => this.child.on('exit', (code, signal) => resolve({ code, signal })));
  }
  get pid() { return this.child.pid; }
  signal(name) { this.child.kill(name); }
  async stop(timeoutMs = 20000) {
    if (this.child.exitCode !== null || this.child.signalCode !== null) return this.exited;
    this.child.kill('SIGTERM');
    const result = await Promise.race([this.exited, sleep(timeoutMs).then(() => null)]);
    if (result) return result;
    this.child.kill('SIGKILL');
    return this.exited;
  }
}

// aditd on the simulated session, its own payload id, state folder and LCM port.
export async function startPayload(build, work, session) {
  const payload = `console${process.pid}`;
  const url = `udpm://239.255.76.67:${20000 + (process.pid + 11) % 30000}?ttl=0`;
  let yaml = fs.readFileSync(path.join(session, 'session.yaml'), 'utf8');
  const replace = (from, to) => {
    if (!from.test(yaml)) throw new Error(`session.yaml has no ${from}`);
    yaml = yaml.replace(from, to);
  };
  replace(/^  id: .*$/m, `  id: ${payload}`);
  replace(/^  state_dir: .*$/m, `  state_dir: ${path.join(work, 'state')}`);
  replace(/^  pcap: .*$/m, `  pcap: ${path.join(session, 'lidar.pcap')}`);
  replace(/^  calibration: .*$/m, `  calibration: ${path.join(session, 'VLP16.yaml')}`);
  replace(/^  log: .*$/m, `  log: ${path.join(session, 'can.log')}`);
  replace(/udpm:\/\/[^\s'"]*/, url);
  yaml += 'threads:\n  lock_memory: false\n';
  const config = path.join(work, 'aditd.yaml');
  fs.writeFileSync(config, yaml);
  const aditd = new Process([path.join(build, 'bin/aditd'), '--config', config], path.join(work, 'aditd.log'));
  const client = ['--payload', payload, '--lcm-url', url, '--timeout', '5'];
  adit(build, ['ping', ...client]);
  return { aditd, payload, url, client, config };
}

export async function startConsole(build, work, payload, port, extra = []) {
  const c = new Process([path.join(build, 'bin/adit'), 'console', '--payload', payload.payload, '--lcm-url', payload.url,
                         '--listen', `127.0.0.1:${port}`, '--data-dir', path.join(work, 'console'),
                         '--sessions-dir', path.join(work, 'state/sessions'), ...extra],
                        path.join(work, `console-${Date.now()}.log`));
  for (let i = 0; i < 100; ++i) {
    try {
      const r = await fetch(`http://127.0.0.1:${port}/api/config`);
      if (r.ok) return c;
    } catch { /* not listening yet */ }
    await sleep(100);
  }
  throw new Error(`adit console did not listen on ${port}: ${fs.readFileSync(c.log, 'utf8')}`);
}

export async function launchBrowser(puppeteer) {
  return puppeteer.launch({
    executablePath: CHROMIUM,
    headless: true,
    protocolTimeout: 60000,
    // Software WebGL (SwiftShader): the machine has no GPU.
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
           '--disable-dev-shm-usage'],
  });
}

export async function waitFor(what, predicate, timeoutMs = 15000, everyMs = 100) {
  const start = Date.now();
  for (;;) {
    const value = await predicate();
    if (value) return value;
    if (Date.now() - start > timeoutMs) throw new Error(`timed out after ${timeoutMs} ms waiting for ${what}`);
    await sleep(everyMs);
  }
}

export function quantile(values, q) {
  if (values.length === 0) return NaN;
  const s = [...values].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor(q * (s.length - 1) + 0.5))];
}

// CPU seconds (user + system) and resident memory (kB) of a process, from /proc.
export function processUsage(pid) {
  const stat = fs.readFileSync(`/proc/${pid}/stat`, 'utf8');
  const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
  const ticks = Number(fields[11]) + Number(fields[12]);
  const status = fs.readFileSync(`/proc/${pid}/status`, 'utf8');
  const kb = (key) => Number((status.match(new RegExp(`^${key}:\\s+(\\d+)`, 'm')) || [0, 0])[1]);
  return { cpu_s: ticks / 100, rss_kb: kb('VmRSS'), hwm_kb: kb('VmHWM') };
}

// Share of the map canvas's pixels (read in the page: the WebGL canvas keeps
// its drawing buffer) within `within` (sum of |r|, |g|, |b| differences) of
// `colour`, or with `colour` null, farther than 30 from the background (a
// corner: the clear colour).
export async function mapPixelShare(page, colour = null, within = 6) {
  return page.evaluate(([colour, within]) => {
    const src = document.getElementById('map');
    const c = document.createElement('canvas');
    c.width = src.width;
    c.height = src.height;
    const g = c.getContext('2d');
    g.drawImage(src, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    const ref = colour ?? [d[0], d[1], d[2]];
    let n = 0;
    for (let i = 0; i < d.length; i += 4) {
      const diff = Math.abs(d[i] - ref[0]) + Math.abs(d[i + 1] - ref[1]) + Math.abs(d[i + 2] - ref[2]);
      if (colour ? diff <= within : diff > 30) ++n;
    }
    return n / (c.width * c.height);
  }, [colour, within]);
}

// Share of the map canvas's pixels that differ from the background colour.
export async function mapCoverage(page) {
  return mapPixelShare(page);
}

// GET /api/grid read here, apart from the page's decoder: the PNG's chunks,
// node's zlib and the PNG row filters (https://www.w3.org/TR/png/#9Filters),
// then the cells and summary the page's gridSummary (grid_layer.js) gives.
// null when the console holds no grid.
export async function servedGrid(base) {
  const r = await fetch(`${base}/api/grid`);
  if (r.status !== 200) return null;
  const png = Buffer.from(await r.arrayBuffer());
  const { width, height, pixels } = decodeGreyAlphaPng(png);
  let occupied = 0, free = 0, unknown = 0, hash = 0x811c9dc5;
  for (let row = 0; row < height; ++row) {
    const from = (height - 1 - row) * width * 2;  // the image's top row is the grid's last (highest y)
    for (let col = 0; col < width; ++col) {
      const grey = pixels[from + 2 * col], alpha = pixels[from + 2 * col + 1];
      const c = alpha < 128 ? -1 : Math.round((255 - grey) / 2.55);
      if (c < 0) unknown += 1; else if (c >= 65) occupied += 1; else free += 1;
      hash = Math.imul(hash ^ (c & 0xff), 0x01000193) >>> 0;
    }
  }
  const h = (name) => r.headers.get(name);
  return { session: h('X-Grid-Session'), v: Number(h('X-Grid-Version')), width, height,
           resolution: Number(h('X-Grid-Resolution')), originX: Number(h('X-Grid-Origin-X')),
           originY: Number(h('X-Grid-Origin-Y')), occupied, free, unknown, hash, bytes: png.length };
}

function decodeGreyAlphaPng(png) {
  if (png.toString('latin1', 1, 4) !== 'PNG') throw new Error('/api/grid is not a PNG');
  const idat = [];
  let width = 0, height = 0, format = '';
  for (let at = 8; at < png.length;) {
    const length = png.readUInt32BE(at);
    const type = png.toString('latin1', at + 4, at + 8);
    const data = png.subarray(at + 8, at + 8 + length);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      format = `depth ${data[8]} colour ${data[9]} interlace ${data[12]}`;
    } else if (type === 'IDAT') {
      idat.push(data);
    }
    at += 12 + length;
  }
  if (format !== 'depth 8 colour 4 interlace 0') throw new Error(`/api/grid: ${format}, not 8-bit grey + alpha`);
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * 2;
  const pixels = new Uint8Array(height * stride);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    for (let x = 0; x < stride; ++x) {
      const left = x >= 2 ? pixels[y * stride + x - 2] : 0;
      const up = y > 0 ? pixels[(y - 1) * stride + x] : 0;
      const corner = x >= 2 && y > 0 ? pixels[(y - 1) * stride + x - 2] : 0;
      let predictor;
      if (filter === 0) predictor = 0;
      else if (filter === 1) predictor = left;
      else if (filter === 2) predictor = up;
      else if (filter === 3) predictor = (left + up) >> 1;
      else if (filter === 4) predictor = paeth(left, up, corner);
      else throw new Error(`/api/grid: PNG filter ${filter}`);
      pixels[y * stride + x] = (raw[y * (stride + 1) + 1 + x] + predictor) & 0xff;
    }
  }
  return { width, height, pixels };
}

function paeth(a, b, c) {
  const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
  return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}
