// adit console: the sessions list. Maps are fetched by the console from the
// payload over LCM (as `adit download` does) and then saved by the browser
// from /files/<id>/map.<format>, which answers Range so a broken download
// resumes; progress comes as `download` events.

const el = (id) => document.getElementById(id);

function bytes(n) {
  if (n >= 1e9) return `${(n / 1e9).toFixed(2)} GB`;
  if (n >= 1e6) return `${(n / 1e6).toFixed(1)} MB`;
  return `${(n / 1e3).toFixed(0)} kB`;
}

export class SessionsPanel {
  constructor() {
    this.downloads = new Map();  // "<id>.<format>" -> job
    this.sessions = [];
    el('refresh-sessions').addEventListener('click', () => this.refresh());
  }

  async refresh() {
    el('sessions-message').textContent = 'asking the payload…';
    el('sessions-message').className = '';
    try {
      const r = await fetch('/api/sessions');
      const body = await r.json();
      if (!r.ok) throw new Error(body.error || r.statusText);
      this.sessions = body.sessions.reverse();  // newest first
      for (const d of body.downloads) this.downloads.set(`${d.session}.${d.format}`, d);
      el('sessions-message').textContent = this.sessions.length ? '' : 'no sessions yet';
      this.render();
    } catch (e) {
      el('sessions-message').textContent = `Sessions: ${e.message}`;
      el('sessions-message').className = 'error';
    }
  }

  onDownload(job) {
    this.downloads.set(`${job.session}.${job.format}`, job);
    this.render();
  }

  async prepare(session, format) {
    const r = await fetch('/api/downloads', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                              body: JSON.stringify({ session, format }) });
    const job = await r.json();
    if (!r.ok) { el('sessions-message').textContent = job.error; el('sessions-message').className = 'error'; return; }
    this.onDownload(job);
  }

  render() {
    const list = el('session-list');
    list.replaceChildren(...this.sessions.map((s) => {
      const li = document.createElement('li');
      li.dataset.session = s.id;
      const title = document.createElement('div');
      title.innerHTML = '<strong></strong> <span class="muted"></span>';
      title.firstChild.textContent = s.name || s.id;
      const facts = [];
      if (s.name) facts.push(s.id);
      if (s.duration_s !== undefined) facts.push(`${(s.duration_s / 60).toFixed(1)} min`);
      if (s.points !== undefined) facts.push(`${s.points.toLocaleString()} points`);
      if (s.bytes !== undefined) facts.push(bytes(s.bytes));
      if (s.loops !== undefined) facts.push(`${s.loops} loops`);
      if (s.notes) facts.push(s.notes);
      title.lastChild.textContent = facts.join(' · ');
      const actions = document.createElement('div');
      actions.className = 'actions';
      for (const format of ['ply', 'las']) {
        const job = this.downloads.get(`${s.id}.${format}`);
        if (job && job.state === 'done') {
          const a = document.createElement('a');
          a.href = job.url;
          a.download = `${s.name || s.id}.${format}`;
          a.textContent = `Save ${format.toUpperCase()} (${job.points.toLocaleString()} points, ${bytes(job.bytes)})`;
          a.dataset.format = format;
          a.dataset.points = job.points;
          actions.append(a);
        } else if (job && job.state === 'running') {
          const p = document.createElement('progress');
          p.max = Math.max(job.wanted, 1);
          p.value = job.have;
          p.title = `${format}: ${job.have}/${job.wanted} segments`;
          actions.append(p);
        } else {
          const b = document.createElement('button');
          b.type = 'button';
          b.dataset.format = format;
          b.textContent = job && job.state === 'failed' ? `Retry ${format.toUpperCase()}` : `Map ${format.toUpperCase()}`;
          b.addEventListener('click', () => this.prepare(s.id, format));
          actions.append(b);
          if (job && job.state === 'failed') {
            const m = document.createElement('span');
            m.className = 'error';
            m.textContent = job.error;
            actions.append(m);
          }
        }
      }
      if (s.trajectory) {
        const a = document.createElement('a');
        a.href = `/files/${s.id}/trajectory.tum`;
        a.download = `${s.name || s.id}-trajectory.tum`;
        a.textContent = 'Trajectory';
        actions.append(a);
      }
      // The pictures the payload made after the session (products/): the top view and the cross-sections.
      if (s.top_view) {
        const a = document.createElement('a');
        a.href = `/files/${s.id}/top_view.png`;
        a.download = `${s.name || s.id}-top_view.png`;
        a.textContent = 'Top view';
        a.dataset.picture = 'top_view';
        actions.append(a);
      }
      if (s.sections > 0) {
        const a = document.createElement('a');
        a.href = `/files/${s.id}/sections.csv`;
        a.download = `${s.name || s.id}-sections.csv`;
        a.textContent = `Sections (${s.sections})`;
        a.title = 'Width and height every interval along the path; one drawing each at /files/<session>/section_NNN.svg';
        a.dataset.picture = 'sections';
        actions.append(a);
      }
      li.append(title, actions);
      return li;
    }));
  }
}
