// adit console: the health panel from status_t (2 Hz): state, sensor rates and
// drops, the IMU, threads' loads and queues, disk free and the recording
// budget (disk free over the rate it fell at while mapping), the loops closed
// (loop_status_t, which the console adds to the status), the fault text.

const el = (id) => document.getElementById(id);

function bytes(n) {
  if (n >= 1e9) return `${(n / 1e9).toFixed(1)} GB`;
  if (n >= 1e6) return `${(n / 1e6).toFixed(1)} MB`;
  return `${(n / 1e3).toFixed(0)} kB`;
}

function cell(text, bad) {
  const td = document.createElement('td');
  td.textContent = text;
  if (bad) td.className = 'bad';
  return td;
}

// The loop closure's line (status.loops: loop_status_t), 'off' without one.
export function loopsText(loops, nowMs) {
  if (!loops) return 'off';
  let text = `${loops.accepted} closed, ${loops.rejected} refused (${loops.candidates} candidates, ${loops.keyframes} keyframes)`;
  if (loops.accepted > 0) {
    const age = loops.last_loop_us > 0 ? Math.max(0, nowMs - loops.last_loop_us / 1000) / 1000 : NaN;
    text += `; last ${Number.isFinite(age) ? `${age.toFixed(0)} s ago` : 'at start'}`;
    text += `, correction ${loops.correction_m.toFixed(2)} m ${loops.correction_deg.toFixed(1)}°`;
    if (!loops.moves_map) text += ' (applied to the exports only)';
  }
  return text;
}

export class HealthPanel {
  constructor() {
    this.disk = [];  // [ms, disk free] while mapping, for the budget
  }

  budget(status, nowMs) {
    if (status.state !== 'MAPPING') { this.disk = []; return 'not recording'; }
    this.disk.push([nowMs, status.disk_free]);
    while (this.disk.length > 2 && nowMs - this.disk[0][0] > 60000) this.disk.shift();
    const [t0, d0] = this.disk[0];
    const rate = (d0 - status.disk_free) / Math.max((nowMs - t0) / 1000, 1e-3);  // bytes/s
    if (nowMs - t0 < 5000 || rate <= 0) return 'measuring…';
    const minutes = status.disk_free / rate / 60;
    return minutes > 600 ? `> 10 h at ${bytes(rate)}/s` : `${minutes.toFixed(0)} min at ${bytes(rate)}/s`;
  }

  show(status, nowMs) {
    el('state').textContent = status.state;
    el('state').className = `badge state-${status.state}`;
    el('session-id').textContent = status.session || '';
    const fault = el('fault');
    fault.hidden = !status.fault;
    fault.textContent = status.fault ? `Fault: ${status.fault}` : '';
    const imu = status.sensors.filter((s) => s.name.startsWith('imu'));
    const figures = [
      ['state', status.state],
      ['map', `${status.map_points.toLocaleString()} points, ${status.map_tiles} tiles`],
      ['disk free', bytes(status.disk_free)],
      ['recording', this.budget(status, nowMs)],
      ['IMU', imu.length ? imu.map((s) => `${s.name} ${s.rate_hz.toFixed(0)} Hz`).join(', ') : 'none configured'],
      ['loops', loopsText(status.loops, nowMs)],
    ];
    const dl = el('health-figures');
    dl.replaceChildren(...figures.flatMap(([k, v]) => {
      const dt = document.createElement('dt'); dt.textContent = k;
      const dd = document.createElement('dd'); dd.textContent = v;
      return [dt, dd];
    }));
    const now = Date.now() * 1000;
    el('sensors').tBodies[0].replaceChildren(...status.sensors.map((s) => {
      const tr = document.createElement('tr');
      const age = s.last_seen_us > 0 ? (now - s.last_seen_us) / 1e6 : Infinity;
      tr.append(cell(s.name), cell(`${s.rate_hz.toFixed(1)} Hz`, s.rate_hz <= 0 && status.state === 'MAPPING'),
                cell(String(s.dropped), s.dropped > 0), cell(Number.isFinite(age) ? `${age.toFixed(1)} s ago` : 'never',
                                                              status.state === 'MAPPING' && age > 2));
      return tr;
    }));
    el('threads').tBodies[0].replaceChildren(...status.threads.map((t) => {
      const tr = document.createElement('tr');
      tr.append(cell(t.name), cell(`${(100 * t.load).toFixed(0)} %`, t.load > 0.9),
                cell(t.capacity > 0 ? `${t.depth}/${t.capacity}` : '', t.capacity > 0 && t.depth >= t.capacity));
      return tr;
    }));
  }
}
