// adit console: the page. One event stream (/api/events) brings the
// snapshot (`hello`), poses, status, tile and grid changes, link and download
// news; tiles are fetched as binary, only the segments changed since the
// version held, decimated to a point budget so the view stays smooth on a
// tablet; the live 2D grid's changed blocks when its version moves.
// A reconnecting stream starts with a snapshot and the page fetches only the
// tiles whose version moved: the map is not loaded again.
import { MapView } from './map_view.js';
import { fetchGridBlock, fetchGridBlocks } from './grid_layer.js';
import { HealthPanel } from './health.js';
import { SessionsPanel } from './sessions.js';

const el = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
// Points drawn at most (the map is decimated by a power-of-two stride above it): docs/CONSOLE.md.
const pointBudget = Number(params.get('budget')) || 300000;

// What the browser tests read (tests/console): latencies, poses, frames.
const metrics = { latencies: [], poses: 0, lastSeq: -1, frames: 0, frameTimes: [], tileFetches: 0, tileBytes: 0,
                  hellos: 0, errors: [], gridFetches: 0, gridBlocks: 0, gridBytes: 0, mapFrame: null, graphPaths: 0, graphPath: null };
window.adit = { metrics };

const view = new MapView(el('map'));
const health = new HealthPanel();
const sessions = new SessionsPanel();
window.adit.view = view;
view.continuous = params.get('continuous') === '1';
window.adit.sessions = sessions;

let lastPose = null;
let pendingLatency = null;  // the console's receive time (ms) of the newest pose not drawn yet
let mapPoints = 0;
let mapSession = null;  // the session whose map the view holds
let mapFrame = null;    // its frame (frame_t), null: the odometry's
let payload = 'adit';
let locked = false;
let token = sessionStorage.getItem('adit-token') || '';
let consoleUp = false, payloadUp = true, payloadSilentMs = 0;

view.onFrame = (now, poseDrawn) => {
  metrics.frames += 1;
  metrics.frameTimes.push(now);
  if (metrics.frameTimes.length > 600) metrics.frameTimes.shift();
  if (poseDrawn && pendingLatency !== null) {
    metrics.latencies.push(Date.now() - pendingLatency);
    if (metrics.latencies.length > 5000) metrics.latencies.shift();
    pendingLatency = null;
  }
};
setInterval(() => {
  const t = metrics.frameTimes;
  const fps = t.length > 10 ? (t.length - 1) * 1000 / (t[t.length - 1] - t[0]) : 0;
  el('fps').textContent = `${fps.toFixed(0)} fps`;
}, 1000);

// ---- banner: what is wrong with the link, visibly
function showBanner() {
  const b = el('banner');
  let text = '';
  if (!consoleUp) text = 'Connection to the console lost: reconnecting…';
  else if (!payloadUp) text = `Payload '${payload}' is not answering (no status for ${(payloadSilentMs / 1000).toFixed(0)} s)`;
  b.hidden = !text;
  b.textContent = text;
}

// ---- tiles
const strideFor = (n) => { let k = 1; while (n / k > pointBudget) k *= 2; return k; };
const queue = new Map();  // id -> wanted version
let inFlight = 0;
function wantTile(id, v) {
  if (view.tileVersion(id) >= v && view.tileEvery(id) === strideFor(mapPoints)) return;
  queue.set(id, v);
  pump();
}
function pump() {
  while (inFlight < 4 && queue.size > 0) {
    const [id] = queue.keys();
    queue.delete(id);
    inFlight += 1;
    fetchTile(id).catch((e) => metrics.errors.push(String(e))).finally(() => { inFlight -= 1; pump(); });
  }
}
async function fetchTile(id) {
  const every = strideFor(mapPoints);
  const have = view.tileEvery(id) === every ? view.tileVersion(id) : 0;
  const r = await fetch(`/api/tile/${id}?have=${have}&every=${every}`);
  if (r.status === 404) return;  // not held (any more): a newer session
  if (!r.ok) throw new Error(`tile ${id}: ${r.status}`);
  const buffer = await r.arrayBuffer();
  metrics.tileFetches += 1;
  metrics.tileBytes += buffer.byteLength;
  const v = Number(r.headers.get('X-Tile-Version'));
  const from = Number(r.headers.get('X-Tile-From'));
  const nSegments = Number(r.headers.get('X-Tile-Segments'));
  const segments = [];
  const data = new DataView(buffer);
  for (let at = 0; at < buffer.byteLength;) {
    const count = data.getUint32(at, true);
    segments.push(new Float32Array(buffer, at + 4, count * 3));
    at += 4 + count * 12;
  }
  if (view.tileVersion(id) > v) return;  // an answer overtaken by a newer one
  view.setTile(id, v, every, from, nSegments, segments);
  const drawn = view.pointCount();  // the status's count can lag the tiles by a moment
  el('map-text').textContent = `${drawn.toLocaleString()} of ${Math.max(mapPoints, drawn).toLocaleString()} points drawn`;
}

// ---- the live 2D grid: one update at a time, again if its version moved meanwhile.
// Its version (the sum of its patches' versions) only grows within a session,
// and is the same for the same grid in any console: a restarted console that
// holds less of it so far is not fetched from until it has caught up.
// An update fetches the block list, then each block whose version moved.
// At most one update per kGridIntervalMs: each new block is a texture upload,
// which in software rendering delays the frame it lands in (docs/CONSOLE.md).
const kGridIntervalMs = 3000;
let gridWanted = 0;  // the newest version announced and not fetched since
let gridFetching = false;
let gridLastFetch = -Infinity;  // performance.now() of the last update
let gridTimer = null;
function wantGrid(g) {
  // None held, or none newer than the page's (a restarted console catching
  // up): an update still waiting out the interval is dropped, not sent to a 204.
  if (!g || g.v <= view.gridVersion()) {
    gridWanted = 0;
    return;
  }
  gridWanted = g.v;
  pumpGrid();
}
async function pumpGrid() {
  if (gridFetching || gridWanted === 0 || gridTimer !== null) return;
  const wait = gridLastFetch + kGridIntervalMs - performance.now();
  if (wait > 0) {
    gridTimer = setTimeout(() => { gridTimer = null; pumpGrid(); }, wait);
    return;
  }
  const wanted = gridWanted;
  gridFetching = true;
  gridLastFetch = performance.now();
  try {
    const index = await fetchGridBlocks();  // null: not held (a new session without a patch yet)
    if (index && index.v > view.gridVersion() && (!mapSession || index.session === mapSession)) await updateGrid(index);
  } catch (e) {
    metrics.errors.push(String(e));
  }
  if (gridWanted === wanted) gridWanted = 0;  // the answer is at least as new as what was announced
  gridFetching = false;
  pumpGrid();
}
// The blocks whose versions moved, then the list: the page's version is the
// list's once every block it names is held as listed (or newer). A block
// listed older than the page holds it comes from a console restarted since
// (it holds fewer of the block's patches so far): fetched too, so the page
// shows what the console has; blocks of one console only grow. The blocks go to
// the GPU together, in one frame: in software rendering each upload delays the
// frame it lands in, and one delayed frame every 3 s costs the pose latency
// less than several.
async function updateGrid(index) {
  const current = () => !mapSession || index.session === mapSession;
  const fetched = [];
  const drop = () => { for (const b of fetched) b.bitmap.close(); };
  for (const [x, y, v] of index.blocks) {
    if (v === view.gridBlockVersion(x, y)) continue;
    const block = await fetchGridBlock(x, y);
    if (block) fetched.push(block);
    // Another session began meanwhile, or the console moved on: its grid comes with its event.
    if (!current() || !block || block.session !== index.session) { drop(); return; }
    metrics.gridBlocks += 1;
    metrics.gridBytes += block.bytes;
  }
  if (!current()) { drop(); return; }
  for (const block of fetched) {
    view.setGridBlock(block);
  }
  metrics.gridFetches += 1;
  view.setGridIndex(index);
  el('grid-toggle').hidden = false;
  const m = (n) => (n * index.resolution).toFixed(0);
  el('grid-text').textContent = ` · grid ${m(index.width)} × ${m(index.height)} m`;
  el('grid-text').hidden = false;
}
function clearGrid() {
  gridWanted = 0;
  gridLastFetch = -Infinity;  // a new session's first grid at once
  el('grid-toggle').hidden = true;
  el('grid-text').hidden = true;
}
el('grid-toggle').addEventListener('click', () => {
  const on = !el('grid-toggle').classList.contains('on');
  el('grid-toggle').classList.toggle('on', on);
  el('grid-toggle').setAttribute('aria-pressed', String(on));
  view.showGrid(on);
});

// ---- the event stream
function applySnapshot(s) {
  metrics.hellos += 1;
  payload = s.payload;
  el('payload').textContent = s.payload;
  payloadUp = s.link.up;
  payloadSilentMs = s.link.silent_ms;
  if (s.status) health.show(s.status, Date.now());
  if (s.pose) onPose(s.pose, false);
  // Tiles only grow within a session: a console that is still catching up
  // (restarted) lists fewer, and the ones held stay. A console that has not
  // heard the payload yet knows no session (""): that is no new session.
  if (s.session && s.session !== mapSession) { view.clear(); queue.clear(); clearGrid(); mapSession = s.session; }
  if (s.frame) onFrame(s.frame);
  if (s.graph_path) onGraphPath(s.graph_path);
  if (s.path.length >= view.pathCount) view.setPath(s.path);  // a restarted console knows less of it
  mapPoints = Math.max(mapPoints, s.map_points);
  for (const t of s.tiles) wantTile(t.id, t.v);
  wantGrid(s.grid);
  showBanner();
}

function onPose(p, live) {
  lastPose = p;
  view.setPose(p);
  if (live) {
    metrics.poses += 1;
    metrics.lastSeq = p.seq;
    pendingLatency = p.rx;
  }
  const flag = p.lost ? ' (LOST: held on the prediction)' : !p.valid ? ' (invalid)' : p.relocalised ? ' (relocalised)'
    : p.degenerate ? ' (degenerate)' : p.held ? ' (held)' : '';
  const at = view.markerPosition();  // in the map frame
  const where = mapFrame && mapFrame.source === 'prior_map' ? ' in the prior map' : '';
  el('pose-text').textContent =
    `pose ${p.seq}: ${[at.x, at.y, at.z].map((v) => v.toFixed(2)).join(', ')} m${where}${flag}`;
}

// The payload's frame (frame_t): the odometry frame placed in the map frame,
// the prior map's once the payload localised in it.
function onFrame(f) {
  if (mapSession && f.session && f.session !== mapSession) return;
  mapFrame = f;
  metrics.mapFrame = f;
  view.setFrame(f);
  if (lastPose) onPose(lastPose, false);
}

// The path as the pose graph placed it (a loop closed): drawn with the
// tiles, which the graph moved too; the poses' path goes on from its end.
function onGraphPath(g) {
  if (mapSession && g.session && g.session !== mapSession) return;
  metrics.graphPaths += 1;
  metrics.graphPath = { rev: g.rev, utime: g.utime, n: g.points.length };
  view.setGraphPath(g);
}

function connect() {
  const events = new EventSource('/api/events');
  events.onopen = () => { consoleUp = true; showBanner(); };
  events.onerror = () => { consoleUp = false; showBanner(); };  // EventSource retries by itself
  events.addEventListener('hello', (e) => { consoleUp = true; applySnapshot(JSON.parse(e.data)); });
  events.addEventListener('pose', (e) => onPose(JSON.parse(e.data), true));
  events.addEventListener('frame', (e) => onFrame(JSON.parse(e.data)));
  events.addEventListener('graph_path', (e) => onGraphPath(JSON.parse(e.data)));
  events.addEventListener('status', (e) => {
    const s = JSON.parse(e.data);
    mapPoints = Math.max(mapPoints, s.map_points);
    health.show(s, Date.now());
    updateControls(s.state);
  });
  events.addEventListener('tiles', (e) => {
    for (const t of JSON.parse(e.data).tiles) wantTile(t.id, t.v);
  });
  events.addEventListener('grid', (e) => wantGrid(JSON.parse(e.data)));
  events.addEventListener('session', (e) => {
    const session = JSON.parse(e.data).session;
    if (session === mapSession) return;
    view.clear();
    queue.clear();
    clearGrid();
    mapPoints = 0;
    mapSession = session;
    mapFrame = null;
    metrics.mapFrame = null;
  });
  events.addEventListener('link', (e) => {
    const l = JSON.parse(e.data);
    payloadUp = l.up;
    payloadSilentMs = l.silent_ms || 0;
    showBanner();
  });
  events.addEventListener('download', (e) => sessions.onDownload(JSON.parse(e.data)));
  events.addEventListener('command', (e) => {
    const c = JSON.parse(e.data);
    if (c.accepted && c.verb === 'STOP') setTimeout(() => sessions.refresh(), 3000);
  });
  window.adit.events = events;
}
setInterval(() => { if (!payloadUp) { payloadSilentMs += 1000; showBanner(); } }, 1000);

// ---- control: start, stop, the passphrase
let currentState = 'UNKNOWN';
function updateControls(state) {
  currentState = state;
  el('start').disabled = state !== 'IDLE';
  el('stop').disabled = state !== 'MAPPING';
  el('send-hint').disabled = state !== 'MAPPING';
  el('lock').hidden = !locked || !!token;
}

function say(text, ok) {
  const m = el('command-message');
  m.textContent = text;
  m.className = ok ? 'ok' : 'error';
}

// `fields`: the command's own (HINT: x, y, heading), checked by the console.
async function command(verb, fields = {}) {
  const body = { verb, ...fields };
  if (verb === 'START' && el('scan-name').value.trim()) body.name = el('scan-name').value.trim();
  say(`${verb}…`, true);
  el('start').disabled = el('stop').disabled = el('send-hint').disabled = true;
  try {
    const r = await fetch('/api/command', { method: 'POST', body: JSON.stringify(body),
                                            headers: { 'Content-Type': 'application/json', 'X-Adit-Token': token } });
    const answer = await r.json();
    if (r.status === 403) {
      token = '';
      sessionStorage.removeItem('adit-token');
      el('lock').hidden = !locked;
      say(`Refused: ${answer.error}`, false);
    } else if (!r.ok) {
      say(`${verb} refused: ${answer.error || answer.reason}`, false);
    } else {
      const session = answer.session && !answer.reason.includes(answer.session) ? ` (session ${answer.session})` : '';
      say(`${verb}: ${answer.reason}${session}`, true);
    }
  } catch (e) {
    say(`${verb} failed: the console did not answer (${e.message})`, false);
  }
  updateControls(currentState);
}

el('start').addEventListener('click', () => command('START'));
el('stop').addEventListener('click', () => command('STOP'));
// A hint for the search against the prior map: where the payload is in the
// prior's frame, and the way it faces when given (docs/PRIOR-MAP.md).
el('hint').addEventListener('submit', (e) => {
  e.preventDefault();
  const fields = { x: Number(el('hint-x').value), y: Number(el('hint-y').value) };
  if (el('hint-heading').value.trim() !== '') fields.heading = Number(el('hint-heading').value);
  command('HINT', fields);
});
el('lock').addEventListener('submit', async (e) => {
  e.preventDefault();
  const r = await fetch('/api/unlock', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                         body: JSON.stringify({ passphrase: el('passphrase').value }) });
  const answer = await r.json();
  if (!r.ok) { say(answer.error, false); return; }
  token = answer.token;
  sessionStorage.setItem('adit-token', token);
  el('passphrase').value = '';
  say('Control unlocked', true);
  updateControls(currentState);
});

for (const b of document.querySelectorAll('#camera-modes button')) {
  b.addEventListener('click', () => { view.setMode(b.dataset.mode); markMode(b.dataset.mode); });
}
function markMode(mode) {
  for (const b of document.querySelectorAll('#camera-modes button')) b.classList.toggle('on', b.dataset.mode === mode);
}
view.onModeChange = markMode;

el('theme').addEventListener('click', () => {
  const sun = document.body.classList.toggle('theme-sun');
  document.body.classList.toggle('theme-dark', !sun);
  el('theme').textContent = sun ? 'Dark' : 'Sun';
  view.setTheme(sun);
});

async function start() {
  const config = await (await fetch('/api/config')).json();
  payload = config.payload;
  locked = config.locked;
  el('payload').textContent = payload;
  updateControls('UNKNOWN');
  connect();
  sessions.refresh();
}
start();
