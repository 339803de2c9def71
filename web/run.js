// The run page: live over Server-Sent Events while the run goes on, then final. The server
// sends decimated series (min/max per column), never every event. When the plots have
// been drawn, <body> gets data-plots (non-background pixels per plot) and
// data-first-plot-ms (time from navigation to the first drawn plot) for tests and
// measurements. What the page says and which bodies it names and colours come from the run's
// view description (run.view, the server's RunView, the same as rviz's): the page decides
// nothing on its own. For tests, <body> also gets data-view-end (the run's end [s]),
// data-xt-end (the latest time any x-t line reaches [s]) and data-xt-max-jump (the largest
// x step between two vertices of one x-t segment [m]; on a ring below half its length) and
// data-scene-colours (how many colours the sketch drew its bodies in).
'use strict';

const runId = document.body.dataset.runId;
const api = '/api/runs/' + encodeURIComponent(runId);
// Totals (not bodies) in neutral colours; bodies in rviz's colours, from the view.
const totalColours = ['#333333', '#b8860b'];
let viewBodies = new Map();  // body index -> {name, colour}, from run.view
let viewColours = [];  // body i's "#rrggbb" (run.view.body_colours): what rviz draws for it

// core::bodyName: "A".."Z", then "#26", "#27", ...
const letterName = (i) => (i < 26 ? String.fromCharCode(65 + i) : '#' + i);
const bodyName = (i) => (viewBodies.has(i) ? viewBodies.get(i).name : letterName(i));
const bodyColour = (i) => viewColours[i] || (viewBodies.has(i) ? viewBodies.get(i).colour : '#aaaaaa');
const plural = (n, word) => fmt(n) + ' ' + word + (n === 1 ? '' : 's');
// The server's kClassTableMaxBodies: wider runs have no positions and velocities CSV.
const CLASS_TABLE_MAX_BODIES = 64;
const charts = {};
let firstPlotMs = null;

function el(tag, text, attrs) {
  const node = document.createElement(tag);
  if (text !== undefined && text !== null) node.textContent = String(text);
  for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
  return node;
}

function fmt(x, digits) {
  if (x === null || x === undefined) return '-';
  if (typeof x !== 'number') return String(x);
  if (Number.isInteger(x) && Math.abs(x) < 1e15) return x.toLocaleString('en-US');
  const text = Number(x.toPrecision(digits || 6)).toString();
  // No e-notation that wraps: "1.2e-7" becomes "1.2×10⁻⁷" (one word, no break).
  const m = /^(-?[\d.]+)e([+-]\d+)$/.exec(text);
  // Thousands separators in the whole part, as rviz writes them: "929,465.012".
  if (!m) return text.replace(/^(-?)(\d{4,})/, (all, sign, whole) => sign + Number(whole).toLocaleString('en-US'));
  return m[1] + '×10' + superscript(Number(m[2]));
}

// The view's texts (rviz's, which writes "4.68×10^11") in the page's style: "4.68×10¹¹".
function pageText(text) {
  return text.replace(/×10\^(-?\d+)/g, (all, n) => '×10' + superscript(Number(n)));
}

function superscript(n) {
  const sup = {'-': '⁻', '0': '⁰', '1': '¹', '2': '²', '3': '³', '4': '⁴', '5': '⁵', '6': '⁶', '7': '⁷', '8': '⁸', '9': '⁹'};
  return String(n).split('').map((c) => sup[c]).join('');
}

// A log axis's labels: 1, 2 and 5 x 10^n when the axis spans at most 3 decades, else the
// decades only (the other ticks keep their grid line, unlabelled), so that labels never
// crowd. Plain numbers from 0.01 to 1,000, else "2×10⁻⁵".
function logTickLabel(value, span) {
  const n = Math.floor(Math.log10(value) + 1e-9);
  const mantissa = Math.round(value / Math.pow(10, n));
  if (!(span > 3 ? mantissa === 1 : [1, 2, 5].includes(mantissa))) return '';
  if (n >= -2 && n <= 3) return fmt(Number((mantissa * Math.pow(10, n)).toPrecision(1)));
  return (mantissa === 1 ? '' : mantissa + '×') + '10' + superscript(n);
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
  const colours = new Set();
  for (let i = 0; i < n; ++i) {
    const m = scene.masses[i];
    const cx = px(x[i]);
    g.fillStyle = bodyColour(i);
    colours.add(bodyColour(i));
    if (m === 'inf') {
      g.fillRect(cx - 3, y0 - 40, 6, 45);
    } else {
      const r = n > 50 ? 2 : 5 + 12 * (mMax > mMin ? Math.log(m / mMin) / Math.log(mMax / mMin) : 0.5);
      g.beginPath(); g.arc(cx, y0 - r, r, 0, 2 * Math.PI); g.fill();
      const v = scene.velocities[i];
      if (n <= 10 && v !== 0) {  // the velocity arrow, with its head
        const ay = y0 - 2 * r - 6, tip = cx + Math.sign(v) * 25;
        g.strokeStyle = g.fillStyle;
        g.beginPath(); g.moveTo(cx, ay); g.lineTo(tip, ay); g.stroke();
        g.beginPath(); g.moveTo(tip, ay); g.lineTo(tip - Math.sign(v) * 6, ay - 4); g.lineTo(tip - Math.sign(v) * 6, ay + 4); g.closePath(); g.fill();
      }
    }
    if (n > 10 && viewBodies.has(i)) {  // many bodies: the shown ones are named
      g.fillStyle = '#222';
      g.font = '10px sans-serif';
      g.fillText(bodyName(i), cx - g.measureText(bodyName(i)).width / 2, y0 + 14);
    }
    if (n <= 10) {
      g.fillStyle = '#222';
      g.font = '11px sans-serif';
      const label = bodyName(i) + ': ' + (m === 'inf' ? 'wall' : fmt(m, 3) + ' kg') + ', ' + fmt(scene.velocities[i], 3) + ' m/s';
      const at = (text) => Math.max(2, Math.min(canvas.width - g.measureText(text).width - 2, cx - g.measureText(text).width / 2));
      g.fillText(label, at(label), y0 + 18);
      g.fillText(fmt(x[i], 4) + ' m', at(fmt(x[i], 4) + ' m'), y0 + 31);
    }
  }
  document.body.dataset.sceneColours = colours.size;
}

// The collision-index axis ends one past the last collision, as rviz's does: each series
// goes on there with its last value, so that the state after the last collision shows.
function indexAxisEnd(run) {
  let last = 0;
  run.plots.velocity.forEach((s) => s.points.forEach((q) => { last = Math.max(last, q[0]); }));
  run.plots.energy.forEach((q) => { last = Math.max(last, q[0]); });
  return Math.max(1, Math.ceil(last) + 1);
}

function toEnd(points, end) {
  const data = xy(points);
  if (data.length > 0 && data[data.length - 1].x < end) data.push({x: end, y: data[data.length - 1].y});
  return data;
}

function indexAxis(c, end) {
  c.options.scales.x.min = 0;
  c.options.scales.x.max = end;
  c.options.scales.x.ticks = {precision: 0};  // collisions are counted: whole numbers
}

function velocityDatasets(run) {
  const p = run.plots;
  const sets = [];
  const name = bodyName;
  const colour = (s) => bodyColour(s.body);
  const end = indexAxisEnd(run);
  p.velocity.forEach((s) => sets.push({label: 'v ' + name(s.body) + ' simulated', data: toEnd(s.points, end), borderColor: colour(s), stepped: false}));
  p.predicted_velocity.forEach((s) => sets.push({label: 'v ' + name(s.body) + ' closed form', data: toEnd(s.points, end), borderColor: colour(s), borderDash: [6, 4]}));
  p.paper_velocity.forEach((s) => sets.push({label: 'v ' + name(s.body) + ' paper (2.15)/(2.16)', data: toEnd(s.points, end), borderColor: colour(s), borderDash: [2, 3]}));
  // Other models give the final velocities only: drawn beside the end of the run.
  const fin = run.prediction && p.predicted_velocity.length === 0 ? run.prediction.final_velocities : [];
  if (fin.length > 0) {  // on the last segment, after the last collision
    p.velocity.forEach((s) => {
      const v = fin[s.body];
      if (v !== null && v !== undefined) sets.push({label: 'v ' + name(s.body) + ' predicted final', data: [{x: end - 1, y: v}, {x: end, y: v}], borderColor: colour(s), borderDash: [6, 4], borderWidth: 3});
    });
  }
  return sets;
}

// ---- Phase space (the paper's picture; the clacks' circle) ----
// Velocities scaled by sqrt(m), u_i = sqrt(m_i) v_i: the kinetic energy is |u|^2 / 2, so an
// elastic run stays on a circle and each impact reflects the point across a line through
// its centre. Three finite masses: u projected on the plane of constant momentum; two finite
// masses and a wall at rest: (u of the right one, u of the left one) as they are. Drawn for
// runs whose velocity series are exact (every impact kept: at most PHASE_MAX_COLLISIONS).
const PHASE_MAX_COLLISIONS = 400;

// The phase picture of a run, or {why} when it has none: two axes (unit vectors in u space),
// the states (start, then after each impact) as 2D points, and the lines v_i = v_j of each
// pair (a wall at rest: v = 0) with the side where that pair no longer approaches.
function phasePicture(run) {
  const masses = run.scene.masses.map((m) => (m === 'inf' ? Infinity : m));
  const n = masses.length;
  const finite = masses.map((m, i) => i).filter((i) => Number.isFinite(masses[i]));
  if (run.scene.ring > 0) return {why: 'not drawn for a ring, whose third pair (the seam) the plane leaves out'};
  if (n !== 3 && !(n === 2 && finite.length === 2)) return {why: 'drawn for three bodies (walls included)'};
  if (finite.length < 2) return {why: 'drawn when at least two bodies have finite mass'};
  if (n === 2) return {why: 'two bodies alone have one velocity that changes, their relative one: no plane to draw'};
  const walls = [0, 2].filter((i) => !Number.isFinite(masses[i]));
  if (walls.some((i) => run.scene.velocities[i] !== 0)) return {why: 'drawn for walls at rest'};
  const count = run.view ? run.view.simulated_collisions : null;
  if (count === null || count === undefined) return {why: 'the run was not simulated'};
  if (count > PHASE_MAX_COLLISIONS) return {why: 'drawn for runs of at most ' + PHASE_MAX_COLLISIONS + ' collisions; this one has ' + fmt(count)};
  const root = masses.map((m) => (Number.isFinite(m) ? Math.sqrt(m) : 0));
  let axes;
  if (finite.length === 3) {
    // e1 along an AB impact's change of u, e2 completes the plane orthogonal to sqrt(m).
    const norm = (a) => { const l = Math.hypot(...a); return a.map((c) => c / l); };
    const e1 = norm([root[1], -root[0], 0]);
    const nHat = norm(root);
    const e2 = [nHat[1] * e1[2] - nHat[2] * e1[1], nHat[2] * e1[0] - nHat[0] * e1[2], nHat[0] * e1[1] - nHat[1] * e1[0]];
    axes = {e1, e2, x: 'along an A-B impact', y: 'across it, at constant momentum'};
  } else {
    const [i, j] = finite;
    axes = {e1: [0, 1, 2].map((k) => (k === i ? 1 : 0)), e2: [0, 1, 2].map((k) => (k === j ? 1 : 0)),
      x: '\u221Am\u00B7v of ' + bodyName(i), y: '\u221Am\u00B7v of ' + bodyName(j)};
  }
  const project = (v) => {
    const u = v.map((vi, k) => root[k] * (Number.isFinite(vi) ? vi : 0));
    return [u.reduce((a, c, k) => a + c * axes.e1[k], 0), u.reduce((a, c, k) => a + c * axes.e2[k], 0)];
  };
  // The state after impact k: each body's series at its last vertex at index <= k.
  const series = new Map(run.plots.velocity.map((s) => [s.body, s.points]));
  const valueAt = (body, k) => {
    const pts = series.get(body);
    if (!pts) return run.scene.velocities[body];
    let v = pts.length ? pts[0][1] : run.scene.velocities[body];
    for (const q of pts) { if (q[0] <= k) v = q[1]; else break; }
    return v;
  };
  const states = [];
  for (let k = 0; k <= count; ++k) states.push(project([0, 1, 2].map((b) => valueAt(b, k))));
  // Pair (i, i + 1) stops approaching when v_i >= v_{i+1}: a . u >= 0 with a_i = 1/sqrt(m_i),
  // a_{i+1} = -1/sqrt(m_{i+1}) (a wall's term dropped: v_wall = 0).
  const lines = [0, 1].map((i) => {
    const a = [0, 0, 0];
    if (root[i]) a[i] = 1 / root[i];
    if (root[i + 1]) a[i + 1] = -1 / root[i + 1];
    const normal = [a.reduce((s2, c, k) => s2 + c * axes.e1[k], 0), a.reduce((s2, c, k) => s2 + c * axes.e2[k], 0)];
    return {pair: bodyName(i) + bodyName(i + 1), normal};
  });
  return {states, lines, axes};
}

// Draws the picture into canvas g of w x h pixels: the circle of the start's energy in the
// plane, the wedge where no pair approaches (shaded), the reflection lines, then the path.
function drawPhase(g, w, h, picture, title) {
  g.fillStyle = '#ffffff';
  g.fillRect(0, 0, w, h);
  const top = title ? 40 : 8;
  const r0 = Math.hypot(...picture.states[0]);
  const reach = Math.max(r0, ...picture.states.map((p) => Math.hypot(...p))) || 1;
  const size = Math.min(w, h - top) / 2 - 24;
  const cx = w / 2, cy = top + (h - top) / 2;
  const scale = size / (1.08 * reach);
  const X = (p) => cx + p[0] * scale, Y = (p) => cy - p[1] * scale;
  if (title) {
    g.fillStyle = '#222';
    g.font = 'bold ' + Math.round(w / 60) + 'px sans-serif';
    g.textAlign = 'center';
    g.fillText(title, w / 2, 26);
    g.textAlign = 'left';
  }
  // The wedge: points with both pairs apart, sampled on rays.
  const apart = (p) => picture.lines.every((l) => l.normal[0] * p[0] + l.normal[1] * p[1] >= 0);
  g.fillStyle = 'rgba(60, 160, 90, 0.16)';
  g.beginPath();
  let open = false;
  for (let k = 0; k <= 720; ++k) {
    const phi = (k / 720) * 2 * Math.PI;
    const p = [Math.cos(phi) * 1.08 * reach, Math.sin(phi) * 1.08 * reach];
    if (apart(p)) {
      if (!open) { g.moveTo(cx, cy); open = true; }
      g.lineTo(X(p), Y(p));
    } else if (open) {
      g.lineTo(cx, cy); open = false;
    }
  }
  if (open) g.lineTo(cx, cy);
  g.fill();
  g.strokeStyle = '#999';
  g.setLineDash([5, 4]);
  g.beginPath(); g.arc(cx, cy, r0 * scale, 0, 2 * Math.PI); g.stroke();
  g.setLineDash([]);
  g.font = Math.max(13, Math.round(w / 60)) + 'px sans-serif';
  picture.lines.forEach((l) => {
    const d = [-l.normal[1], l.normal[0]];
    const len = Math.hypot(...d) || 1;
    const e = [d[0] / len * 1.08 * reach, d[1] / len * 1.08 * reach];
    g.strokeStyle = '#777';
    g.beginPath(); g.moveTo(X([-e[0], -e[1]]), Y([-e[0], -e[1]])); g.lineTo(X(e), Y(e)); g.stroke();
    g.fillStyle = '#555';
    g.fillText(l.pair + ' meet', X(e) + 4, Y(e));
  });
  g.strokeStyle = '#1f5fbf';
  g.lineWidth = Math.max(1, w / 500);
  g.beginPath();
  picture.states.forEach((p, k) => (k ? g.lineTo(X(p), Y(p)) : g.moveTo(X(p), Y(p))));
  g.stroke();
  g.lineWidth = 1;
  const dot = (p, colour) => { g.fillStyle = colour; g.beginPath(); g.arc(X(p), Y(p), Math.max(3, w / 150), 0, 2 * Math.PI); g.fill(); };
  dot(picture.states[0], '#333');
  dot(picture.states[picture.states.length - 1], '#c0392b');
}

function showPhase(run) {
  const box = document.getElementById('phase_box');
  const picture = phasePicture(run);
  document.body.dataset.phase = picture.why ? 'none' : String(picture.states.length - 1);
  document.querySelector('button[data-plot="phase"]').hidden = Boolean(picture.why);
  if (picture.why) {
    box.hidden = true;
    return;
  }
  box.hidden = false;
  // For tests: how far the states stray from the start's circle (0 when elastic), and
  // whether the last state lies in the wedge where no pair approaches.
  const r0 = Math.hypot(...picture.states[0]);
  document.body.dataset.phaseSpread = String(Math.max(...picture.states.map((p) => Math.abs(Math.hypot(...p) - r0))) / r0);
  const last = picture.states[picture.states.length - 1];
  document.body.dataset.phaseEndsApart = String(picture.lines.every((l) => l.normal[0] * last[0] + l.normal[1] * last[1] >= -1e-12 * r0));
  const canvas = document.getElementById('phase');
  drawPhase(canvas.getContext('2d'), canvas.width, canvas.height, picture, '');
  phaseImage = () => {
    const slide = document.createElement('canvas');
    slide.width = PNG_WIDTH;
    slide.height = PNG_WIDTH * 3 / 4;
    drawPhase(slide.getContext('2d'), slide.width, slide.height, picture,
      'Phase space (\u221Am\u00B7v, energy = distance\u00B2 / 2): run ' + runId);
    return slide;
  };
  const details = el('details', null, {class: 'plot_table'});
  details.appendChild(el('summary', 'The numbers of this plot, as a table'));
  details.addEventListener('toggle', () => {
    if (!details.open) return;
    const table = el('table');
    const head = el('tr');
    for (const h of ['after collision', picture.axes.x + ' [\u221Akg\u00B7m/s]', picture.axes.y + ' [\u221Akg\u00B7m/s]']) head.appendChild(el('th', h));
    table.appendChild(head);
    picture.states.forEach((p, k) => {
      const tr = el('tr');
      [k === 0 ? 'start' : fmt(k), fmt(p[0], 9), fmt(p[1], 9)].forEach((cell) => tr.appendChild(el('td', cell)));
      table.appendChild(tr);
    });
    details.replaceChildren(details.firstChild, table);
  });
  box.querySelectorAll('details.plot_table').forEach((old) => old.remove());
  box.appendChild(details);
  document.getElementById('phase_legend').textContent =
    'Each point is the three velocities scaled by \u221Am (axes: ' + picture.axes.x + '; ' + picture.axes.y +
    ' [\u221Akg\u00B7m/s]). The kinetic energy is half the squared distance from the centre: an elastic ' +
    'collision keeps the point on the dashed circle and reflects it across the line of the pair that meets. ' +
    'Black: the start; red: after the last collision, inside the shaded wedge, where no body catches another, ' +
    'so the run ends there. ' + plural(picture.states.length - 1, 'collision') + ' drawn.';
}
let phaseImage = null;

// The x-t lines: every tracked body to the run's end, one dataset per segment (a ring's
// lines are cut at its seam); the legend names each body once.
function xtDatasets(run) {
  const lines = run.plots.worldline_segments ||
    run.plots.worldlines.map((s) => ({body: s.body, segments: [s.points]}));
  const sets = [];
  let end = 0, maxJump = 0;
  lines.forEach((line) => line.segments.forEach((segment, k) => {
    segment.forEach((q, j) => {
      end = Math.max(end, q[0]);
      if (j > 0) maxJump = Math.max(maxJump, Math.abs(q[1] - segment[j - 1][1]));
    });
    sets.push({label: k === 0 ? bodyName(line.body) : '', data: segment.map((q) => ({x: q[1], y: q[0]})), borderColor: bodyColour(line.body)});
  }));
  document.body.dataset.xtEnd = String(end);
  document.body.dataset.xtMaxJump = String(maxJump);
  return sets;
}

function summaryRows(run) {
  const s = run.summary, p = run.prediction;
  const view = run.view || {};
  const rows = [];
  // A run that was not simulated claims no simulated value: its counts are the model's.
  const simulated = view.simulated_collisions !== null && view.simulated_collisions !== undefined;
  const count = simulated ? view.simulated_collisions : (run.view ? null : (s ? s.collision_count : run.collisions));
  rows.push(['collisions', count, p ? (p.infinite_collisions ? 'infinitely many' : p.collision_count) : null,
    p ? p.paper_collision_count : null]);
  const heat = run.plots.heat;  // while running: the heat so far
  const notSimulated = Boolean(view.not_simulated);
  rows.push(['heat [J]', notSimulated ? null : (s ? s.energy_lost : (heat.length ? heat[heat.length - 1][1] : null)), p ? p.energy_lost : null, null]);
  const n = run.scene.masses.length;
  if (n <= 10) {
    const paperFinal = run.plots.paper_final_velocities || [];
    // A run stopped part-way has no final velocities of its own: its row says where it stopped.
    const stoppedAt = view.truncated && simulated ? ' (simulated: at the stop, after collision ' + fmt(count) + ')' : '';
    for (let i = 0; i < n; ++i) {
      rows.push([(stoppedAt ? 'v ' : 'final v ') + bodyName(i) + ' [m/s]' + stoppedAt, s && !notSimulated ? s.final_velocities[i] : null,
        p ? p.final_velocities[i] : null, paperFinal.length === n ? paperFinal[i] : null]);
    }
  }
  // Momentum and kinetic energy of the finite masses, at the start and at the end by each
  // column (correctly rounded by the server): a collision between bodies keeps the momentum,
  // an elastic one the energy too; a wall takes or gives momentum, a moving one energy too;
  // the paper's printed formulas need not keep either.
  const totals = run.totals;
  if (totals && totals.start) {
    const end = (column, key) => (totals[column] ? totals[column][key] : null);
    rows.push(['momentum at the start [kg m/s]', totals.start.momentum, null, null]);
    rows.push(['momentum at the end [kg m/s]', notSimulated ? null : end('simulated', 'momentum'), end('predicted', 'momentum'), end('paper', 'momentum')]);
    rows.push(['kinetic energy at the start [J]', totals.start.kinetic_energy, null, null]);
    rows.push(['kinetic energy at the end [J]', notSimulated ? null : end('simulated', 'kinetic_energy'), end('predicted', 'kinetic_energy'), end('paper', 'kinetic_energy')]);
  }
  if (s) {
    rows.push(['max prediction error (ratio)', s.max_prediction_error, null, null]);
    rows.push(['energy drift (ratio)', s.energy_relative_drift, null, null]);
    // Every other value shown is the exact one correctly rounded (docs/physics.md).
    if (s.uncertified_values && s.uncertified_values.length) {
      rows.push(['not certified as correctly rounded', s.uncertified_values.map((k) => k.replace(/_/g, ' ')).join(', '), null, null]);
    }
    if (s.time_beyond_range) rows.push(['time', 'an impact came after 1.8e308 s, the largest double: shown as inf', null, null]);
    if (s.recorded === false) {
      rows.push(['recorded', 'no: this run has no bag to download or replay' + (s.recording_error ? ' (' + s.recording_error + ')' : ''), null, null]);
    }
    rows.push(['stop reason', s.stop_reason + (view.truncated ? ': ' + pageText(view.truncated) : ''), null, null]);
  }
  return rows;
}

// The paper beside the correct formulas (docs/physics.md, Errata), shown when the paper's
// printed values were computed (three elastic bodies, the rotation model): for each
// printed formula, what it gives here, whether that keeps momentum and energy, and the
// correct formula. Totals are the server's, each correctly rounded; "kept" allows the
// rounding of the velocities (relative 1e-12).
function paperRows(run) {
  const totals = run.totals, p = run.prediction, s = run.summary;
  if (!totals || !totals.paper || !totals.start) return [];
  const wall = run.scene.masses.some((m) => m === 'inf');
  const kept = (key, unit) => {
    const a = totals.start[key], b = totals.paper[key];
    const scale = Math.max(Math.abs(a), Math.abs(b), 1e-300);
    if (Math.abs(a - b) <= 1e-12 * scale) return 'yes';
    return 'no: ' + fmt(b, 6) + ' ' + unit + ' after, ' + fmt(a, 6) + ' before';
  };
  const rows = [];
  rows.push(['(2.15), (2.16): the velocities after 2k and 2k+1 collisions',
    'v\u2082\u2096 = V\u00B71 + S\u207B\u00B9(cos k\u03B8 w \u2212 sin k\u03B8 (\u015D\u00D7w)), v\u2082\u2096\u208A\u2081 = D_AB v\u2082\u2096',
    wall ? 'a wall takes momentum: not a test here' : kept('momentum', 'kg m/s'),
    kept('kinetic_energy', 'J'),
    'The printed eigenvectors (2.4) are wrong in general, so P, P\u207B\u00B9, D\u1D4F and these closed forms are too: ' +
    'their first rows keep v_A + v_B, which no collision does.']);
  if (p && p.paper_collision_count !== null && p.paper_collision_count !== undefined) {
    const simulatedCount = run.view ? run.view.simulated_collisions : null;
    rows.push(['(3.22): the number of collisions n = 1 + \u230Ax\u230B + \u2308x\u2309',
      'N = \u2308\u03C8/\u03B1\u2309 \u2212 1 (\u03C8 the start\u2019s angle in the plane, \u03B1 the wedge\u2019s opening)',
      'counts: ' + fmt(p.paper_collision_count) + ' printed, ' + fmt(p.collision_count) + ' correct' +
        (simulatedCount !== null && simulatedCount !== undefined ? ', ' + fmt(simulatedCount) + ' simulated' : ''),
      '',
      'For any x that is not a whole number, 1 + \u230Ax\u230B + \u2308x\u2309 is even, yet three bodies often collide an odd number of times.']);
  }
  rows.push(['(4.4)-(4.7): the energy each collision hands on',
    'v_k = (v_A \u2212 v_B)/2, half the relative velocity now',
    '', '',
    'The printed formulas take v\u0304_AB as the average of the start, which assumes v_A + v_B never changes; ' +
    'read with the current relative velocity they hold.']);
  return rows;
}

function showPaper(run) {
  const rows = paperRows(run);
  const box = document.getElementById('paper_box');
  box.hidden = rows.length === 0;
  if (!rows.length) return;
  document.querySelector('#paper tbody').replaceChildren(...rows.map((row) => {
    const tr = el('tr');
    row.forEach((cell, k) => tr.appendChild(el(k === 0 ? 'th' : 'td', cell)));
    return tr;
  }));
}

// A gas: T(t) on log-log axes with Haff's law T0/(1 + t/tau)^2 fitted (the view's numbers,
// rviz's too). Points at t = 0 or T = 0 cannot be drawn on log axes: left out. For tests,
// <body> gets data-temperature-points and data-haff-tau [s].
function drawTemperature(view) {
  document.getElementById('temperature_box').hidden = false;
  document.querySelector('button[data-plot="temperature"]').hidden = false;
  const points = view.temperature.filter((q) => q[0] > 0 && q[1] > 0).map((q) => ({x: q[0], y: q[1]}));
  const c = chart('temperature', 't [s]', 'T [J]');
  c.options.scales.x.type = 'logarithmic';
  c.options.scales.y.type = 'logarithmic';
  const sets = [{label: 'T(t)', data: points, borderColor: totalColours[0]}];
  if (view.haff) {
    const fit = points.map((p) => ({x: p.x, y: view.haff.t0 / Math.pow(1 + p.x / view.haff.tau, 2)}));
    sets.push({label: "Haff's law", data: fit, borderColor: totalColours[1], borderDash: [6, 4]});
    document.body.dataset.haffTau = String(view.haff.tau);
  }
  c.data.datasets = sets;
  const decades = (values) => Math.log10(Math.max(...values) / Math.min(...values));
  const spanX = decades(points.map((p) => p.x)), spanY = decades(points.map((p) => p.y));
  c.options.scales.x.ticks = {autoSkip: false, maxRotation: 0, callback: (value) => logTickLabel(value, spanX)};
  c.options.scales.y.ticks = {autoSkip: false, callback: (value) => logTickLabel(value, spanY)};
  c.update('none');
  document.getElementById('temperature_legend').textContent =
    pageText(view.temperature_legend + (view.temperature_fit_note ? '. ' + view.temperature_fit_note : ''));
  document.body.dataset.temperaturePoints = String(points.length);
  // For tests: the labels drawn on each axis, '|'-separated.
  const labels = (axis) => c.scales[axis].ticks.map((t) => t.label).filter((l) => l !== '').join('|');
  document.body.dataset.temperatureTicksX = labels('x');
  document.body.dataset.temperatureTicksY = labels('y');
}

// A run that was not simulated has no simulated series: no empty chart is drawn, but what
// was not simulated and why (the view's not_simulated) and the model's answer.
function showNotSimulated(run, view) {
  const box = document.getElementById('not_simulated_box');
  const hide = Boolean(view && view.not_simulated);
  box.hidden = !hide;
  ['velocity', 'energy', 'xt', 'momentum', 'bars'].forEach((id) => { document.getElementById(id + '_box').hidden = hide; });
  // Nor downloads of what does not exist: the plots' PNGs and the events CSV (a 404).
  document.querySelectorAll('button[data-plot]').forEach((b) => { if (b.dataset.plot !== 'temperature' && b.dataset.plot !== 'phase') b.hidden = hide; });
  document.getElementById('dl_csv').hidden = hide;
  document.getElementById('dl_table').hidden = hide || run.scene.masses.length > CLASS_TABLE_MAX_BODIES;
  if (!hide) return false;
  const p = run.prediction;
  let answer = 'The model (' + (p ? p.model : 'none') + ') answered: ';
  if (view.infinitely_many_predicted) answer += 'infinitely many collisions';
  else if (view.predicted_collisions !== null && view.predicted_collisions !== undefined) answer += plural(view.predicted_collisions, 'collision');
  else answer += 'no count';
  const finals = p ? p.final_velocities : [];
  const named = finals.map((v, i) => (v === null || v === undefined ? null : bodyName(i) + ' ' + fmt(v, 9) + ' m/s')).filter((t) => t);
  if (named.length > 0 && named.length <= 10) answer += '; final velocities ' + named.join(', ');
  document.getElementById('not_simulated_reason').textContent =
    'Nothing to plot, since this run was not simulated: ' + pageText(view.not_simulated.replace(/^not simulated: /, '')) + '.';
  document.getElementById('model_answer').textContent = answer + '. The summary below has its numbers.';
  document.body.dataset.plotsHidden = 'velocity energy xt';
  return true;
}

// The view's facts: what was simulated and what not, a cut, a collapse, a ring or a box,
// and which bodies each plot shows.
function showFacts(view) {
  const facts = document.getElementById('view_facts');
  // The note repeats a cut's sentence when there is one: said once.
  const items = view ? [view.title, view.not_simulated, view.note ? '' : view.truncated, view.collapse, view.spiral, view.ring, view.box, view.moving_wall, view.note] : [];
  facts.replaceChildren(...items.filter((text) => text).map((text) => el('li', pageText(text))));
  document.getElementById('velocity_legend').textContent = view ? 'Bodies shown: ' + pageText(view.velocity_legend) + '.' : '';
  document.getElementById('xt_legend').textContent = view ? 'Bodies shown: ' + pageText(view.worldline_legend) + '.' : '';
  // Many bodies: what their colours mean (few: each is named in its colour).
  document.getElementById('colour_legend').textContent = view && view.colour_legend ? pageText(view.colour_legend[0].toUpperCase() + view.colour_legend.slice(1)) + '.' : '';
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
  const view = run.view;
  if (view) {
    viewBodies = new Map();
    view.worldline_bodies.concat(view.velocity_bodies).forEach((b) => viewBodies.set(b.index, b));
    viewColours = view.body_colours || [];
    // The counter and state word are the view's (rviz's) own.
    status.textContent = run.state + who + ': ' + pageText(view.counter);
  } else {
    const count = run.summary ? run.summary.collision_count : run.collisions;
    status.textContent = run.state + who + ': ' + plural(count, 'collision');
  }
  if (run.summary && run.summary.published_events < run.summary.collision_count && run.summary.simulated) {
    status.textContent += ' (plots from the bag: every collision)';
  }
  document.body.dataset.state = run.state;
  if (!run.scene) return;
  showFacts(view);
  drawScene(run.scene);
  document.getElementById('model').textContent = run.prediction ? 'Model: ' + run.prediction.model + '. ' + run.prediction.model_reason : '';
  const notSimulated = showNotSimulated(run, view);
  // No collision: no event to export (the events CSV would answer 404).
  if (ended(run.state) && run.summary && run.summary.collision_count === 0) document.getElementById('dl_csv').hidden = true;
  const v = chart('velocity', 'collision index', 'velocity [m/s]');
  const indexEnd = indexAxisEnd(run);
  v.data.datasets = velocityDatasets(run);
  v.options.plugins.legend.display = v.data.datasets.length <= 12;
  indexAxis(v, indexEnd);
  v.update('none');
  const e = chart('energy', 'collision index', 'energy [J]');
  e.data.datasets = [{label: 'kinetic energy', data: toEnd(run.plots.energy, indexEnd), borderColor: totalColours[0]},
    {label: 'heat so far', data: toEnd(run.plots.heat, indexEnd), borderColor: totalColours[1]}];
  indexAxis(e, indexEnd);
  e.update('none');
  document.body.dataset.indexAxisEnd = String(indexEnd);
  if (!notSimulated) drawMomentumAndEnergy(run, indexEnd);
  const t = chart('xt', 'x [m]', 't [s]');
  t.data.datasets = xtDatasets(run);
  t.options.plugins.legend.display = (run.plots.worldlines || []).length <= 12;
  t.options.plugins.legend.labels.filter = (item) => item.text !== '';
  if (view && view.end_time !== null) {
    t.options.scales.y.min = 0;
    t.options.scales.y.max = roundUp(view.end_time);
    document.body.dataset.viewEnd = String(view.end_time);
  }
  if (view && view.ring_circumference > 0) {
    t.options.scales.x.min = 0;
    t.options.scales.x.max = view.ring_circumference;
  }
  t.update('none');
  if (view && view.gas) drawTemperature(view);
  if (ended(run.state)) showPhase(run);
  showPaper(run);
  const tbody = document.querySelector('#summary tbody');
  tbody.replaceChildren(...summaryRows(run).map((row) => {
    const tr = el('tr');
    row.forEach((cell) => tr.appendChild(el(tr.children.length === 0 ? 'th' : 'td', fmt(cell, 9))));
    return tr;
  }));
  if (!notSimulated) {
    const drawn = ['velocity', 'energy', 'xt'].map((id) => id + ':' + nonBackgroundPixels(document.getElementById(id)));
    document.body.dataset.plots = drawn.join(' ');
  }
  if (firstPlotMs === null) {
    firstPlotMs = Math.round(performance.now());
    document.body.dataset.firstPlotMs = String(firstPlotMs);
  }
  if (ended(run.state)) {
    document.body.dataset.final = 'true';
    document.getElementById('stop').hidden = true;
    addPlotTables();
    setupXtWindow(run);
    if (location.hash === '#check-png') checkSlideImages();
    // For tests and screenshots: every plot's table open.
    if (location.hash === '#open-tables') document.querySelectorAll('details.plot_table').forEach((d) => { d.open = true; });
  }
}

function setupDownloads() {
  document.getElementById('dl_csv').href = api + '/events.csv';
  document.getElementById('dl_table').href = api + '/table.csv';
  const json = document.getElementById('dl_json');
  json.href = api;
  json.download = runId + '_summary.json';
  document.getElementById('dl_bag').href = api + '/bag';
  document.querySelectorAll('button[data-plot]').forEach((b) => {
    b.onclick = () => {
      const c = charts[b.dataset.plot];
      if (!c && !(b.dataset.plot === 'phase' && phaseImage)) return;
      const a = document.createElement('a');
      a.href = c ? slideImage(c, b.dataset.plot) : phaseImage().toDataURL('image/png');
      a.download = runId + '_' + b.dataset.plot + '.png';
      a.click();
    };
  });
}

// Paints the canvas white under the plot: a PNG that reads on a dark slide too.
const opaqueBackground = {
  id: 'opaqueBackground',
  beforeDraw(c) {
    const g = c.ctx;
    g.save();
    g.globalCompositeOperation = 'destination-over';
    g.fillStyle = '#ffffff';
    g.fillRect(0, 0, c.width, c.height);
    g.restore();
  },
};

// A plot as a slide: PNG_WIDTH pixels wide, opaque, titled with what it shows and the run
// (the axes carry the units), drawn at twice the page's scale so its text stays legible.
const PNG_WIDTH = 1600;
function slideCanvas(c, id) {
  const scale = 2;
  const canvas = document.createElement('canvas');
  canvas.width = PNG_WIDTH / scale;
  canvas.height = Math.round(PNG_WIDTH * 9 / 16 / scale);
  canvas.style.width = canvas.width + 'px';
  canvas.style.height = canvas.height + 'px';
  const heading = document.querySelector('#' + id + '_box h2');
  const title = (heading ? heading.textContent : id) + ': run ' + runId;
  const options = c.config.options;
  const copy = new Chart(canvas, {
    type: c.config.type,
    data: {labels: c.data.labels, datasets: c.data.datasets.map((d) => Object.assign({}, d, {data: d.data.slice()}))},
    options: Object.assign({}, options, {
      responsive: false, animation: false, devicePixelRatio: scale,
      plugins: Object.assign({}, options.plugins, {title: {display: true, text: title, font: {size: 15}}}),
    }),
    plugins: [opaqueBackground],
  });
  const slide = document.createElement('canvas');  // the chart clears its own canvas when destroyed
  slide.width = canvas.width;
  slide.height = canvas.height;
  slide.getContext('2d').drawImage(canvas, 0, 0);
  copy.destroy();
  return slide;
}
const slideImage = (c, id) => slideCanvas(c, id).toDataURL('image/png');

// ---- Momentum, the centre of mass, energy before and after ----
// The finite masses' momentum against the collision index (a wall's impacts are its steps),
// each body's kinetic energy and the heat at the start and at the end as bars, and what is
// conserved, in words. Every number is the server's (run.totals: each the exact value
// correctly rounded).
function drawMomentumAndEnergy(run, indexEnd) {
  const totals = run.totals;
  const m = chart('momentum', 'collision index', 'momentum [kg m/s]');
  m.data.datasets = [{label: 'total momentum of the finite masses', data: toEnd(run.plots.momentum || [], indexEnd), borderColor: totalColours[0]}];
  indexAxis(m, indexEnd);
  m.update('none');
  const s = run.summary;
  const end = totals && totals.simulated;
  const perBody = totals && totals.start && totals.start.kinetic_per_body;
  const walls = run.scene.masses.map((mass, i) => (mass === 'inf' ? i : -1)).filter((i) => i >= 0);
  const bodies = perBody ? run.scene.masses.map((mass, i) => i).filter((i) => !walls.includes(i)) : [];
  const labels = perBody ? bodies.map((i) => bodyName(i)) : ['all bodies'];
  labels.push('heat');
  const startValues = perBody ? bodies.map((i) => perBody[i]) : [totals && totals.start ? totals.start.kinetic_energy : null];
  startValues.push(0);
  const endValues = end ? (perBody && end.kinetic_per_body ? bodies.map((i) => end.kinetic_per_body[i]) : [end.kinetic_energy]) : [];
  if (end) endValues.push(s ? s.energy_lost : null);
  if (!charts.energy_bars) {
    charts.energy_bars = new Chart(document.getElementById('energy_bars'), {
      type: 'bar',
      data: {labels: [], datasets: []},
      options: {animation: false, responsive: true, maintainAspectRatio: false, plugins: {legend: {labels: {boxWidth: 12}}},
        scales: {x: {title: {display: true, text: 'kinetic energy of each body, and the heat'}}, y: {title: {display: true, text: 'energy [J]'}}}},
    });
  }
  const bars = charts.energy_bars;
  bars.data.labels = labels;
  bars.data.datasets = [{label: 'at the start', data: startValues, backgroundColor: '#6b7c93'},
    {label: 'at the end', data: endValues, backgroundColor: totalColours[1]}];
  bars.update('none');
  document.getElementById('conservation').replaceChildren(...conservationText(run).map((t) => el('li', t)));
}

// What is conserved and what is not, and why, from the server's totals.
function conservationText(run) {
  const t = run.totals, s = run.summary;
  if (!t || !t.start || !t.simulated) return [];
  const walls = run.scene.masses.filter((mass) => mass === 'inf').length;
  const movingWall = run.scene.masses.some((mass, i) => mass === 'inf' && run.scene.velocities[i] !== 0);
  const p0 = t.start.momentum, p1 = t.simulated.momentum;
  const e0 = t.start.kinetic_energy, e1 = t.simulated.kinetic_energy;
  const heat = s ? s.energy_lost : 0;
  const out = [];
  if (walls) {
    out.push('Momentum: ' + fmt(p0) + ' kg m/s at the start, ' + fmt(p1) + ' kg m/s at the end. A wall is an infinite mass: ' +
      'it takes and gives momentum at each of its impacts, so the bodies\u2019 total is not conserved (the steps in the plot).');
  } else {
    out.push('Momentum: ' + fmt(p0) + ' kg m/s at the start and ' + fmt(p1) + ' kg m/s at the end' +
      (p0 === p1 ? ': conserved, as in every collision between bodies, elastic or not (equal and opposite impulses).'
                 : ': it should be conserved; the difference is the rounding of the velocities shown.'));
  }
  const v0 = t.start.centre_of_mass_velocity, v1 = t.simulated.centre_of_mass_velocity;
  let why;
  if (walls) why = v0 === v1 ? ' (the walls gave back what they took).' : ' (the walls changed it).';
  else why = v0 === v1 ? ' (the same: no outside force acts).' : ' (no outside force acts: the difference is the rounding of the velocities).';
  out.push('Centre of mass: at ' + fmt(t.centre_of_mass_start) + ' m at the start, moving at ' + fmt(v0) + ' m/s; at the end at ' +
    fmt(v1) + ' m/s' + why);
  if (movingWall) {
    out.push('Energy: ' + fmt(e0) + ' J at the start, ' + fmt(e1) + ' J at the end, ' + fmt(heat) + ' J of heat. ' +
      'A moving wall does work on the bodies it pushes, so their energy is not conserved.');
  } else if (heat > 0) {
    out.push('Energy: ' + fmt(e0) + ' J at the start, ' + fmt(e1) + ' J at the end: ' + fmt(heat) +
      ' J turned into heat in the collisions with e < 1. Kinetic energy plus heat is conserved.');
  } else {
    out.push('Energy: ' + fmt(e0) + ' J at the start and ' + fmt(e1) + ' J at the end: conserved, since every collision is elastic' +
      (walls ? ' and a wall at rest does no work.' : '.'));
  }
  return out;
}

// ---- A time window of the x-t diagram ----
// A long run's whole-run lines keep its early impacts as a few columns; a window is read
// again from every event in the bag (GET .../worldlines), for the bodies the view tracks.
// Axis ends are round numbers (1, 2 or 5 x 10^n).
function roundUp(x) {
  if (!(x > 0)) return x;
  const p = Math.pow(10, Math.floor(Math.log10(x)));
  for (const m of [1, 2, 2.5, 5, 10]) if (m * p >= x * (1 - 1e-12)) return m * p;
  return 10 * p;
}

let wholeRunXt = null;  // the whole run's datasets and axis, to go back to
function setupXtWindow(run) {
  const box = document.getElementById('xt_window');
  const view = run.view || {};
  const recorded = run.summary && run.summary.recorded === true;
  box.hidden = !(ended(run.state) && recorded && !(view.ring_circumference > 0) && view.end_time > 0);
  if (box.hidden) return;
  const c = charts.xt;
  wholeRunXt = {datasets: c.data.datasets, min: c.options.scales.y.min, max: c.options.scales.y.max};
  const bodies = (run.plots.worldline_segments || run.plots.worldlines).map((l) => l.body);
  const note = document.getElementById('xt_window_note');
  // log: a logarithmic time axis over the whole run, x held to the scene's extent (the start's
  // positions and as much again on each side), where the collisions happen.
  const show = async (from, to, log) => {
    document.getElementById('xt_from').value = from;
    document.getElementById('xt_to').value = to;
    note.textContent = 'Reading every event from ' + fmt(from) + ' s to ' + fmt(to) + ' s...';
    const buttons = [...box.querySelectorAll('button')];
    buttons.forEach((b) => { b.disabled = true; });  // one window at a time
    let res, answer;
    try {
      res = await fetch(api + '/worldlines?from=' + from + '&to=' + to + '&bodies=' + bodies.join(','));
      answer = await res.json();
    } catch (err) {
      note.textContent = 'The lab did not answer: ' + err;
      return;
    } finally {
      buttons.forEach((b) => { b.disabled = false; });
    }
    if (res.status !== 200) { note.textContent = 'HTTP ' + res.status + ': ' + answer.error; return; }
    c.data.datasets = answer.lines.map((l) => ({label: bodyName(l.body), data: l.points.map((q) => ({x: q[1], y: q[0]})),
      borderColor: bodyColour(l.body)}));
    if (log) {
      let first = answer.to;
      answer.lines.forEach((l) => l.points.forEach((q) => { if (q[0] > 0) first = Math.min(first, q[0]); }));
      const x = run.scene.positions, lo = Math.min(...x), hi = Math.max(...x), pad = Math.max(hi - lo, 1);
      const step = roundUp((hi - lo + 2 * pad) / 6);  // round axis ends
      c.options.scales.y.type = 'logarithmic';
      c.options.scales.y.min = Math.pow(10, Math.floor(Math.log10(first)));
      const span = Math.log10(answer.to / c.options.scales.y.min);
      c.options.scales.y.ticks = {autoSkip: false, callback: (value) => logTickLabel(value, span)};
      c.options.scales.x.min = Math.floor((lo - pad) / step) * step;
      c.options.scales.x.max = Math.ceil((hi + pad) / step) * step;
    } else {
      c.options.scales.y.type = 'linear';
      c.options.scales.y.ticks = {};
      c.options.scales.y.min = answer.from;
      delete c.options.scales.x.min;
      delete c.options.scales.x.max;
    }
    c.options.scales.y.max = answer.to;
    c.update('none');
    note.textContent = 'Shown: t from ' + fmt(answer.from) + ' s to ' + fmt(answer.to) + ' s, ' +
      (answer.exact ? 'every event.' : 'drawn per column (over 2,048 points per body).');
    document.body.dataset.xtWindow = answer.from + '-' + answer.to + ':' + answer.lines.length;
  };
  document.getElementById('xt_show').onclick = () => {
    const from = Number(document.getElementById('xt_from').value), to = Number(document.getElementById('xt_to').value);
    if (!(from >= 0 && to > from)) { note.textContent = 'Give 0 <= from < to, in seconds.'; return; }
    show(from, to);
  };
  document.getElementById('xt_early').onclick = () => show(0, roundUp(view.end_time / 100));
  document.getElementById('xt_log').onclick = () => show(0, roundUp(view.end_time), true);
  document.getElementById('xt_whole').onclick = () => {
    c.data.datasets = wholeRunXt.datasets;
    c.options.scales.y.type = 'linear';
    c.options.scales.y.ticks = {};
    delete c.options.scales.x.min;
    delete c.options.scales.x.max;
    c.options.scales.y.min = wholeRunXt.min;
    c.options.scales.y.max = wholeRunXt.max;
    c.update('none');
    note.textContent = '';
  };
  // For tests: the page opened at #xt-early shows the first 1% at once.
  if (location.hash === '#xt-early') show(0, roundUp(view.end_time / 100));
  if (location.hash === '#xt-log') show(0, roundUp(view.end_time), true);
}

// ---- Text alternatives: each plot as a table ----
// Under each plot, a "the numbers" disclosure holds the plotted points as a table (series,
// x, y with the axes' titles and units), built when opened; the CSV downloads have every
// value in full precision.
const TABLE_MAX_ROWS = 2000;
function plotTable(c) {
  const xTitle = c.options.scales.x.title.text, yTitle = c.options.scales.y.title.text;
  const table = el('table');
  const head = el('tr');
  for (const h of ['series', xTitle, yTitle]) head.appendChild(el('th', h));
  table.appendChild(head);
  let rows = 0, total = 0, series = '';
  c.data.datasets.forEach((d) => {
    series = d.label || series;  // a body's later segments carry no label of their own
    d.data.forEach((q, k) => {
      ++total;
      if (rows >= TABLE_MAX_ROWS) return;
      const tr = el('tr');
      tr.appendChild(el('td', series));
      // A bar chart's values are plain numbers under its labels.
      tr.appendChild(el('td', q !== null && typeof q === 'object' ? fmt(q.x, 9) : c.data.labels[k]));
      tr.appendChild(el('td', fmt(q !== null && typeof q === 'object' ? q.y : q, 9)));
      table.appendChild(tr);
      ++rows;
    });
  });
  const note = el('p', total > rows ? 'The first ' + fmt(rows) + ' of ' + fmt(total) + ' plotted points; the CSV downloads hold every value.'
                                    : fmt(total) + ' plotted points.', {class: 'muted'});
  return [note, table];
}

function addPlotTables() {
  Object.keys(charts).forEach((id) => {
    const box = document.getElementById(id + '_box');
    if (!box || box.querySelector('details.plot_table')) return;
    const details = el('details', null, {class: 'plot_table'});
    details.appendChild(el('summary', 'The numbers of this plot, as a table'));
    details.addEventListener('toggle', () => {
      if (details.open) details.replaceChildren(details.firstChild, ...plotTable(charts[id]));
    });
    box.appendChild(details);
  });
}

// For tests (the page opened at #check-png): <body> gets data-png, "<plot>:<width>x<height>:
// opaque|transparent" for each plot's slide.
function checkSlideImages() {
  document.body.dataset.png = Object.keys(charts).map((id) => {
    const slide = slideCanvas(charts[id], id);
    const corner = slide.getContext('2d').getImageData(0, 0, 1, 1).data;
    return id + ':' + slide.width + 'x' + slide.height + ':' + (corner[3] === 255 ? 'opaque' : 'transparent');
  }).join(' ');
}

// Printed, the plots are redrawn at the paper's width (one column) instead of shrunk.
window.addEventListener('beforeprint', () => Object.values(charts).forEach((c) => c.resize()));
window.addEventListener('afterprint', () => Object.values(charts).forEach((c) => c.resize()));

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
    place.textContent = 'Waiting: place ' + fmt(waiting.indexOf(mine) + 1) + ' of ' + fmt(waiting.length) + ' in the ' + mine.lane + ' lane.';
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
  // The web server is restarting: go on by polling, which its next start answers.
  source.addEventListener('restart', () => { source.close(); setTimeout(poll, 1000); });
  // 503 (too many live streams) or a dropped connection: reload the run every second.
  source.onerror = () => { if (document.body.dataset.final !== 'true') { source.close(); poll(); } };
}

main();
