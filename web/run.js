// The run page: live over Server-Sent Events while the run goes on, then final. The server
// sends decimated series (min/max per column), never every event. When the plots have
// been drawn, <body> gets data-plots (non-background pixels per plot) and
// data-first-plot-ms (time from navigation to the first drawn plot) for tests and
// measurements.
'use strict';

const runId = document.body.dataset.runId;
const api = '/api/runs/' + encodeURIComponent(runId);
const colors = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b', '#e377c2', '#7f7f7f', '#bcbd22', '#17becf'];
const charts = {};
let firstPlotMs = null;

function el(tag, text) {
  const node = document.createElement(tag);
  if (text !== undefined && text !== null) node.textContent = String(text);
  return node;
}

function fmt(x, digits) {
  if (x === null || x === undefined) return '-';
  if (typeof x !== 'number') return String(x);
  if (Number.isInteger(x) && Math.abs(x) < 1e15) return x.toLocaleString('en-US');
  return Number(x.toPrecision(digits || 6)).toString();
}

function xy(points) { return points.map((p) => ({x: p[0], y: p[1]})); }

function chart(id, xTitle, yTitle) {
  if (charts[id]) return charts[id];
  charts[id] = new Chart(document.getElementById(id), {
    type: 'scatter',
    data: {datasets: []},
    options: {
      animation: false, responsive: true, maintainAspectRatio: false, parsing: false, normalized: true,
      showLine: true, elements: {point: {radius: 0}, line: {borderWidth: 1.5}},
      plugins: {legend: {labels: {boxWidth: 12}}},
      scales: {x: {type: 'linear', title: {display: true, text: xTitle}}, y: {title: {display: true, text: yTitle}}},
    },
  });
  return charts[id];
}

function drawScene(scene) {
  const canvas = document.getElementById('scene');
  const g = canvas.getContext('2d');
  g.clearRect(0, 0, canvas.width, canvas.height);
  const x = scene.positions;
  const n = x.length;
  const lo = Math.min(...x), hi = Math.max(...x);
  const span = hi - lo || 1;
  const px = (v) => 40 + (canvas.width - 80) * (v - lo) / span;
  const y0 = 55;
  g.strokeStyle = '#999';
  g.beginPath(); g.moveTo(10, y0); g.lineTo(canvas.width - 10, y0); g.stroke();
  const finite = scene.masses.filter((m) => typeof m === 'number');
  const mMin = Math.min(...finite), mMax = Math.max(...finite);
  for (let i = 0; i < n; ++i) {
    const m = scene.masses[i];
    const cx = px(x[i]);
    g.fillStyle = colors[i % colors.length];
    if (m === 'inf') {
      g.fillRect(cx - 3, y0 - 40, 6, 45);
    } else {
      const r = n > 50 ? 2 : 5 + 12 * (mMax > mMin ? Math.log(m / mMin) / Math.log(mMax / mMin) : 0.5);
      g.beginPath(); g.arc(cx, y0 - r, r, 0, 2 * Math.PI); g.fill();
      const v = scene.velocities[i];
      if (n <= 10 && v !== 0) {
        g.strokeStyle = g.fillStyle;
        g.beginPath(); g.moveTo(cx, y0 - 2 * r - 6); g.lineTo(cx + Math.sign(v) * 25, y0 - 2 * r - 6); g.stroke();
      }
    }
    if (n <= 10) {
      g.fillStyle = '#222';
      g.font = '11px sans-serif';
      const label = (m === 'inf' ? 'wall' : fmt(m, 3) + ' kg') + ', ' + fmt(scene.velocities[i], 3) + ' m/s';
      const at = (text) => Math.max(2, Math.min(canvas.width - g.measureText(text).width - 2, cx - g.measureText(text).width / 2));
      g.fillText(label, at(label), y0 + 18);
      g.fillText(fmt(x[i], 4) + ' m', at(fmt(x[i], 4) + ' m'), y0 + 31);
    }
  }
}

function velocityDatasets(run) {
  const p = run.plots;
  const sets = [];
  const name = (i) => (run.scene.masses.length <= 3 ? 'ABC'[i] : 'body ' + i);
  p.velocity.forEach((s, k) => sets.push({label: 'v ' + name(s.body) + ' simulated', data: xy(s.points), borderColor: colors[k % 10], stepped: false}));
  p.predicted_velocity.forEach((s, k) => sets.push({label: 'v ' + name(s.body) + ' closed form', data: xy(s.points), borderColor: colors[k % 10], borderDash: [6, 4]}));
  p.paper_velocity.forEach((s, k) => sets.push({label: 'v ' + name(s.body) + ' paper (2.15)/(2.16)', data: xy(s.points), borderColor: colors[k % 10], borderDash: [2, 3]}));
  // Other models give the final velocities only: drawn beside the end of the run.
  const fin = run.prediction && p.predicted_velocity.length === 0 ? run.prediction.final_velocities : [];
  if (fin.length > 0) {
    const end = Math.max(1, run.collisions);
    p.velocity.forEach((s, k) => {
      const v = fin[s.body];
      if (v !== null && v !== undefined) sets.push({label: 'v ' + name(s.body) + ' predicted final', data: [{x: end, y: v}, {x: end * 1.08 + 0.5, y: v}], borderColor: colors[k % 10], borderDash: [6, 4], borderWidth: 3});
    });
  }
  return sets;
}

function xtDatasets(run) {
  return run.plots.worldlines.map((s, k) => ({label: 'body ' + s.body, data: s.points.map((q) => ({x: q[1], y: q[0]})), borderColor: colors[k % 10]}));
}

function summaryRows(run) {
  const s = run.summary, p = run.prediction;
  const rows = [];
  const count = s ? s.collision_count : run.collisions;
  rows.push(['collisions', count, p ? (p.infinite_collisions ? 'infinitely many' : p.collision_count) : null,
    p ? p.paper_collision_count : null]);
  const heat = run.plots.heat;  // while running: the heat so far
  rows.push(['heat [J]', s ? s.energy_lost : (heat.length ? heat[heat.length - 1][1] : null), p ? p.energy_lost : null, null]);
  const n = run.scene.masses.length;
  if (n <= 10) {
    const paperFinal = run.plots.paper_final_velocities || [];
    for (let i = 0; i < n; ++i) {
      const bodyName = n <= 3 ? 'ABC'[i] : 'body ' + i;
      rows.push(['final v ' + bodyName + ' [m/s]', s ? s.final_velocities[i] : null, p ? p.final_velocities[i] : null,
        paperFinal.length === n ? paperFinal[i] : null]);
    }
  }
  if (s) {
    rows.push(['max prediction error [1]', s.max_prediction_error, null, null]);
    rows.push(['energy drift [1]', s.energy_relative_drift, null, null]);
    rows.push(['stop reason', s.stop_reason + (s.truncated ? ' (truncated: ' + s.truncation_reason + ')' : ''), null, null]);
  }
  return rows;
}

function nonBackgroundPixels(canvas) {
  const g = canvas.getContext('2d');
  const data = g.getImageData(0, 0, canvas.width, canvas.height).data;
  let count = 0;
  for (let i = 3; i < data.length; i += 4) if (data[i] !== 0) ++count;
  return count;
}

// A run that will change no more: finished, or interrupted (its lab node died during it).
const ended = (state) => state === 'finished' || state === 'interrupted';

function render(run) {
  const status = document.getElementById('status');
  const who = run.student ? ' by ' + run.student : '';
  const count = run.summary ? run.summary.collision_count : run.collisions;
  status.textContent = run.state + who + ': ' + fmt(count) + ' collisions' +
    (!ended(run.state) && run.prediction && run.prediction.collision_count !== null ? ' of ' + fmt(run.prediction.collision_count) + ' predicted' : '') +
    (run.summary && run.summary.published_events < run.summary.collision_count ? ' (plots from the bag: every collision)' : '');
  document.body.dataset.state = run.state;
  if (!run.scene) return;
  drawScene(run.scene);
  document.getElementById('model').textContent = run.prediction ? 'Model: ' + run.prediction.model + '. ' + run.prediction.model_reason : '';
  const v = chart('velocity', 'collision index [1]', 'velocity [m/s]');
  v.data.datasets = velocityDatasets(run);
  v.options.plugins.legend.display = v.data.datasets.length <= 12;
  v.update('none');
  const e = chart('energy', 'collision index [1]', 'energy [J]');
  e.data.datasets = [{label: 'kinetic energy', data: xy(run.plots.energy), borderColor: colors[0]},
    {label: 'heat so far', data: xy(run.plots.heat), borderColor: colors[1]}];
  e.update('none');
  const t = chart('xt', 'x [m]', 't [s]');
  t.data.datasets = xtDatasets(run);
  t.options.plugins.legend.display = t.data.datasets.length <= 12;
  t.update('none');
  const tbody = document.querySelector('#summary tbody');
  tbody.replaceChildren(...summaryRows(run).map((row) => {
    const tr = el('tr');
    row.forEach((cell) => tr.appendChild(el(tr.children.length === 0 ? 'th' : 'td', fmt(cell, 9))));
    return tr;
  }));
  const drawn = ['velocity', 'energy', 'xt'].map((id) => id + ':' + nonBackgroundPixels(document.getElementById(id)));
  document.body.dataset.plots = drawn.join(' ');
  if (firstPlotMs === null) {
    firstPlotMs = Math.round(performance.now());
    document.body.dataset.firstPlotMs = String(firstPlotMs);
  }
  if (ended(run.state)) {
    document.body.dataset.final = 'true';
    document.getElementById('stop').hidden = true;
  }
}

function setupDownloads() {
  document.getElementById('dl_csv').href = api + '/events.csv';
  const json = document.getElementById('dl_json');
  json.href = api;
  json.download = runId + '_summary.json';
  document.getElementById('dl_bag').href = api + '/bag';
  document.querySelectorAll('button[data-plot]').forEach((b) => {
    b.onclick = () => {
      const c = charts[b.dataset.plot];
      if (!c) return;
      const a = document.createElement('a');
      a.href = c.toBase64Image('image/png', 1);
      a.download = runId + '_' + b.dataset.plot + '.png';
      a.click();
    };
  });
}

async function poll() {
  const run = await (await fetch(api)).json();
  render(run);
  if (!ended(run.state)) setTimeout(poll, 1000);
}

// While queued: the run's place in the lab's queue (GET /api/queue), until it runs.
async function showQueue() {
  const place = document.getElementById('queue');
  if (ended(document.body.dataset.state)) { place.textContent = ''; return; }
  const queue = await (await fetch('/api/queue')).json();
  const waiting = queue.runs.filter((r) => !r.running);
  const mine = queue.runs.find((r) => r.run_id === runId);
  if (mine && !mine.running) {
    place.textContent = 'Waiting: place ' + (waiting.indexOf(mine) + 1) + ' of ' + waiting.length + ' in the ' + mine.lane + ' lane.';
  } else {
    place.textContent = '';
  }
  if (!ended(document.body.dataset.state)) setTimeout(showQueue, 2000);
}

// The Stop button: only in the browser that sent the run (its stop_token in localStorage).
function setupStop() {
  const token = localStorage.getItem('collision_lab_stop_' + runId);
  const button = document.getElementById('stop');
  if (!token || ended(document.body.dataset.state)) return;
  button.hidden = false;
  button.onclick = async () => {
    button.disabled = true;
    const res = await fetch(api + '/stop', {method: 'POST', headers: {'Content-Type': 'application/json'},
      body: JSON.stringify({stop_token: token})});
    const answer = await res.json();
    document.getElementById('stop_result').textContent = res.status === 200 ? answer.message : 'HTTP ' + res.status + ': ' + answer.error;
  };
}

async function main() {
  setupDownloads();
  const run = await (await fetch(api)).json();
  render(run);
  if (ended(run.state)) return;
  setupStop();
  showQueue();
  const source = new EventSource(api + '/stream');
  source.addEventListener('run', (e) => render(JSON.parse(e.data)));
  source.addEventListener('final', (e) => { render(JSON.parse(e.data)); source.close(); });
  // 503 (too many live streams) or a dropped connection: reload the run every second.
  source.onerror = () => { if (document.body.dataset.final !== 'true') { source.close(); poll(); } };
}

main();
