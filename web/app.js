// The start page (a scene form, the presets) and the teacher's page. Every text from the
// server goes into the page with textContent, never as HTML.
'use strict';

function el(tag, text, attrs) {
  const node = document.createElement(tag);
  if (text !== undefined && text !== null) node.textContent = String(text);
  for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
  return node;
}

// Body names and colours as every view has them: core::bodyName ("A".."Z", then "#26",
// ...) and rviz's palette from the server (GET /api/body_colours), never a list of our own.
// The views colour by index only while the palette has a colour for every body; above that
// they colour each body by its start velocity (RunView), so the form names them uncoloured.
let bodyPalette = [];
const bodyLetter = (i) => (i < 26 ? String.fromCharCode(65 + i) : '#' + i);

function nameCell(td, i, bodies) {
  td.textContent = bodyLetter(i);
  td.className = 'body_name';
  const byVelocity = bodyPalette.length > 0 && bodies > bodyPalette.length;
  td.style.color = bodyPalette.length > 0 && !byVelocity ? bodyPalette[i] : '';
  td.title = 'body ' + bodyLetter(i) + ' (masses[' + i + '])' +
      (byVelocity ? ': with more than ' + bodyPalette.length + ' bodies the views colour each body by its start velocity' : '');
}

function bodyRow(mass, position, velocity) {
  const rows = document.querySelector('#bodies tbody');
  const tr = el('tr');
  tr.appendChild(el('td'));
  for (const [name, value] of [['mass', mass], ['position', position], ['velocity', velocity]]) {
    const td = el('td');
    td.appendChild(el('input', null, {type: 'text', name: name, value: value === undefined ? '' : String(value)}));
    tr.appendChild(td);
  }
  const remove = el('button', 'remove', {type: 'button'});
  remove.onclick = () => { tr.remove(); renumber(); };
  const td = el('td');
  td.appendChild(remove);
  tr.appendChild(td);
  rows.appendChild(tr);
  renumber();
}

function renumber() {
  const rows = document.querySelectorAll('#bodies tbody tr');
  rows.forEach((tr, i) => nameCell(tr.firstChild, i, rows.length));
  const byVelocity = bodyPalette.length > 0 && rows.length > bodyPalette.length;
  document.getElementById('colour_note').textContent = byVelocity
    ? 'More than ' + bodyPalette.length + ' bodies: the run\'s views colour each body by its start velocity (blue: moving left, purple: at rest, red: moving right).'
    : '';
}

let loadedPreset = null;  // a preset too large for the form is sent by name

function loadPreset(p) {
  document.querySelector('#bodies tbody').replaceChildren();
  loadedPreset = null;
  const note = document.getElementById('preset_note');
  note.textContent = '';
  if (!p.scene) {
    loadedPreset = p.name;
    note.textContent = 'Preset ' + p.name + ' (' + counted(p.bodies, 'body', 'bodies') + ') is sent as it is; edit a smaller one to change it.';
  } else {
    const s = p.scene;
    s.masses.forEach((m, i) => bodyRow(m, s.positions[i], s.velocities[i]));
    document.getElementById('restitution').value = (s.restitution || []).join(', ');
    document.getElementById('max_collisions').value = s.max_collisions || '';
  }
  // The model and ring are the preset's (or none): nothing typed before stays behind.
  const s = p.scene || {};
  const model = s.restitution_model || '';
  document.getElementById('restitution_model').value = model;
  const parameter = {tc: s.tc, threshold: s.elastic_below, viscoelastic: s.viscoelastic_speed}[model];
  document.getElementById('model_parameter').value = parameter === undefined ? '' : parameter;
  document.getElementById('ring').value = s.ring || '';
}

function numberOrText(text) {
  const t = text.trim();
  const x = Number(t);
  return t !== '' && Number.isFinite(x) ? x : t;
}

function sceneFromForm() {
  const scene = {masses: [], positions: [], velocities: []};
  document.querySelectorAll('#bodies tbody tr').forEach((tr) => {
    scene.masses.push(numberOrText(tr.querySelector('[name=mass]').value));
    scene.positions.push(numberOrText(tr.querySelector('[name=position]').value));
    scene.velocities.push(numberOrText(tr.querySelector('[name=velocity]').value));
  });
  const e = document.getElementById('restitution').value.trim();
  if (e !== '') scene.restitution = e.split(/[ ,;]+/).filter((t) => t !== '').map(numberOrText);
  const cap = document.getElementById('max_collisions').value.trim();
  if (cap !== '') scene.max_collisions = Number(cap);
  // The restitution model and its one parameter, under the key the lab reads for it.
  const model = document.getElementById('restitution_model').value;
  const parameter = document.getElementById('model_parameter').value.trim();
  if (model !== '') {
    scene.restitution_model = model;
    const key = {tc: 'tc', threshold: 'elastic_below', viscoelastic: 'viscoelastic_speed'}[model];
    if (parameter !== '') scene[key] = numberOrText(parameter);
  }
  const ring = document.getElementById('ring').value.trim();
  if (ring !== '') scene.ring = numberOrText(ring);
  return scene;
}

async function sendScene() {
  const result = document.getElementById('result');
  const student = document.getElementById('student').value.trim();
  const code = document.getElementById('code').value.trim();
  localStorage.setItem('collision_lab_student', student);
  const body = loadedPreset ? {preset: loadedPreset} : sceneFromForm();
  body.student = student;
  if (code) body.code = code;
  result.className = '';
  result.textContent = 'Sending...';
  let answer;
  let status;
  try {
    const res = await fetch('/api/runs', {method: 'POST', headers: {'Content-Type': 'application/json'}, body: JSON.stringify(body)});
    status = res.status;
    answer = await res.json();
  } catch (err) {
    result.className = 'error';
    result.textContent = 'The lab did not answer: ' + err;
    return;
  }
  if (status === 202) {
    // The student's own key to stop the run (POST /api/runs/<run_id>/stop), kept in this browser.
    localStorage.setItem('collision_lab_stop_' + answer.run_id, answer.stop_token);
    result.textContent = 'Accepted as run ' + answer.run_id + ', place in the queue ' + answer.queue_position + '.';
    window.location.href = '/runs/' + encodeURIComponent(answer.run_id);
    return;
  }
  result.className = 'error';
  if (answer.rejected) {
    const r = answer.rejected;
    result.textContent = 'Rejected (' + r.reason_name + ', field ' + r.field + '): ' + r.message;
  } else {
    result.textContent = 'HTTP ' + status + ': ' + answer.error + (answer.field ? ' (field ' + answer.field + ')' : '');
  }
}

/// "My runs": the runs sent from this browser (each kept with its stop token in
/// localStorage), newest first, with their state from GET /api/runs and a Stop for the
/// unfinished ones. Refreshes every 5 s while one is unfinished.
async function myRuns() {
  const mine = Object.keys(localStorage).filter((k) => k.startsWith('collision_lab_stop_'))
    .map((k) => k.slice('collision_lab_stop_'.length));
  const box = document.getElementById('my_runs');
  document.body.dataset.myRuns = String(mine.length);
  if (!mine.length) {
    box.replaceChildren(el('p', 'None yet: the runs you send from this browser are listed here.', {class: 'muted'}));
    return;
  }
  // A run_id is "<student>.<the id asked for>", and a student's name has no '.'.
  const students = [...new Set(mine.map((id) => id.slice(0, id.indexOf('.'))).filter((s) => s))];
  const listed = new Map();
  for (const student of students) {
    try {
      const runs = await (await fetch('/api/runs?student=' + encodeURIComponent(student))).json();
      for (const r of runs) listed.set(r.run_id, r);
    } catch (err) {
      // The list stays as far as it was read; the next refresh tries again.
    }
  }
  const table = el('table', null, {'data-my-runs': ''});
  const head = el('tr');
  for (const h of ['run', 'state', 'collisions', 'model', 'sent', '']) head.appendChild(el('th', h));
  table.appendChild(head);
  const rows = mine.map((id) => listed.get(id) || {run_id: id, state: 'not listed (older than the lab\'s list)'});
  rows.sort((a, b) => (b.accepted_stamp || 0) - (a.accepted_stamp || 0));
  let unfinished = false;
  for (const r of rows) {
    const tr = el('tr');
    const td = el('td');
    td.appendChild(el('a', r.run_id, {href: '/runs/' + encodeURIComponent(r.run_id)}));
    tr.appendChild(td);
    tr.appendChild(el('td', listed.has(r.run_id) ? stateText(r) : r.state));
    tr.appendChild(el('td', r.collisions === undefined ? '' : countText(r.collisions)));
    tr.appendChild(el('td', r.model || ''));
    tr.appendChild(el('td', r.accepted_stamp ? new Date(r.accepted_stamp * 1000).toLocaleTimeString() : ''));
    const stop = el('td');
    if (r.state === 'queued' || r.state === 'running') {
      unfinished = true;
      const button = el('button', 'Stop', {type: 'button'});
      button.onclick = async () => {
        button.disabled = true;
        button.textContent = await stopRun(r.run_id, localStorage.getItem('collision_lab_stop_' + r.run_id));
      };
      stop.appendChild(button);
    }
    tr.appendChild(stop);
    table.appendChild(tr);
  }
  box.replaceChildren(table);
  if (unfinished) setTimeout(myRuns, 5000);
}

async function startPage() {
  document.getElementById('student').value = localStorage.getItem('collision_lab_student') || '';
  document.getElementById('add').onclick = () => { loadedPreset = null; document.getElementById('preset_note').textContent = ''; bodyRow('1', '', '0'); };
  document.getElementById('send').onclick = sendScene;
  bodyPalette = (await (await fetch('/api/body_colours')).json()).palette;
  renumber();
  const presets = await (await fetch('/api/presets')).json();
  const tbody = document.querySelector('#presets tbody');
  for (const p of presets) {
    const tr = el('tr');
    tr.appendChild(el('td', p.name));
    tr.appendChild(el('td', p.bodies));
    tr.appendChild(el('td', p.description));
    const td = el('td');
    const load = el('button', 'Load', {type: 'button', 'data-preset': p.name});
    load.onclick = () => loadPreset(p);
    td.appendChild(load);
    tr.appendChild(td);
    tbody.appendChild(tr);
  }
  const pi = presets.find((p) => p.name === 'pi_digits_2');  // 31 impacts: the first two digits of pi
  loadPreset(pi || presets[0]);
  await myRuns();
  document.body.dataset.ready = 'true';
}

/// Asks the lab node to stop a run: with the run's stop_token (the student's own run) or, on
/// the teacher page, with the teacher's login. Returns the server's answer as one line.
async function stopRun(runId, stopToken) {
  return (await stopAnswer(runId, stopToken)).text;
}

/// The same as {ok, text}: ok when the lab node took the stop.
async function stopAnswer(runId, stopToken) {
  const body = stopToken ? {stop_token: stopToken} : {};
  try {
    const res = await fetch('/api/runs/' + encodeURIComponent(runId) + '/stop',
      {method: 'POST', headers: {'Content-Type': 'application/json'}, body: JSON.stringify(body)});
    const answer = await res.json();
    if (res.status === 200) return {ok: answer.ok === true, text: answer.message};
    return {ok: false, text: 'HTTP ' + res.status + ': ' + answer.error};
  } catch (err) {
    return {ok: false, text: 'the lab did not answer: ' + err};
  }
}

function queueTable(queue) {
  const section = el('section');
  section.appendChild(el('h2', 'Queue: ' + counted(queue.runs.length, 'run', 'runs') + ', ' +
                         counted(queue.workers, 'worker', 'workers')));
  const table = el('table');
  const head = el('tr');
  for (const h of ['run', 'student', 'lane', 'state', '']) head.appendChild(el('th', h));
  table.appendChild(head);
  for (const r of queue.runs) {
    const tr = el('tr');
    const td = el('td');
    td.appendChild(el('a', r.run_id, {href: '/runs/' + encodeURIComponent(r.run_id)}));
    tr.appendChild(td);
    tr.appendChild(el('td', r.student));
    tr.appendChild(el('td', r.lane));
    tr.appendChild(el('td', (r.running ? 'running' : 'waiting') + (stopReplies.has(r.run_id) ? ', stopping' : '')));
    tr.appendChild(stopCell(r.run_id));
    table.appendChild(tr);
  }
  section.appendChild(table);
  return section;
}

/// The lab node's answer to each Stop sent from this page, by run_id: kept across the
/// page's refreshes, which redraw every table.
const stopReplies = new Map();

function stopCell(runId) {
  const td = el('td');
  if (stopReplies.has(runId)) {
    td.appendChild(el('span', stopReplies.get(runId), {'data-stop-reply': runId}));
    return td;
  }
  const button = el('button', 'Stop', {type: 'button', 'data-stop': runId});
  button.onclick = async () => {
    button.disabled = true;
    const answer = await stopAnswer(runId, null);
    if (!answer.ok) {  // not taken: the button stays, with the reason beside it
      button.disabled = false;
      button.title = answer.text;
      td.appendChild(el('span', ' ' + answer.text));
      return;
    }
    stopReplies.set(runId, answer.text);
    td.replaceChildren(el('span', answer.text, {'data-stop-reply': runId}));
  };
  td.appendChild(button);
  return td;
}

/// A run's state as the teacher reads it: how it ended (not simulated, cancelled and by
/// whom, collapsed, cut short, not recorded), or "stopping" once a Stop was answered.
function stateText(r) {
  if (r.state === 'queued' || r.state === 'running') return stopReplies.has(r.run_id) ? r.state + ', stopping' : r.state;
  const parts = [r.state];
  if (r.cancelled) parts.push(r.cancel_reason || 'cancelled');
  else if (r.simulated === false) parts.push('not simulated: the model\'s count');
  else if (r.truncated) parts.push('truncated');
  if (r.collapsed) parts.push('collapsed');
  if (r.recorded === false) parts.push('not recorded');
  return parts.join(', ');
}

/// A count as people read it: "31,415".
function countText(n) { return Number(n).toLocaleString('en-US'); }
/// "1 run", "2 runs", "31,415 collisions".
function counted(n, one, many) { return countText(n) + ' ' + (Number(n) === 1 ? one : many); }

/// The teacher's view of one student: their runs, then their rejected inputs (who, when,
/// the reason, the field and the message), each with its count.
function studentSection(name, runs, rejections) {
  const section = el('section', null, {'data-student': name});
  section.appendChild(el('h2', name + ' (' + counted(runs.length, 'run', 'runs') + ', ' +
                         counted(rejections.length, 'rejected input', 'rejected inputs') + ')'));
  const unfinished = runs.filter((r) => r.state === 'queued' || r.state === 'running').length;
  if (unfinished > 1) {
    const all = el('button', 'Stop all ' + unfinished + ' of ' + name + "'s runs", {type: 'button', 'data-stop-student': name});
    all.onclick = async () => {
      all.disabled = true;
      const res = await fetch('/api/students/' + encodeURIComponent(name) + '/stop',
        {method: 'POST', headers: {'Content-Type': 'application/json'}, body: '{}'});
      const answer = await res.json();
      all.textContent = res.status === 200 ? counted(answer.stopped.length, 'run', 'runs') + ' stopped'
                                           : 'HTTP ' + res.status + ': ' + answer.error;
    };
    section.appendChild(all);
  }
  if (runs.length) {
    const table = el('table', null, {'data-runs': name});
    const head = el('tr');
    for (const h of ['run', 'state', 'bodies', 'collisions', 'model', 'accepted', '']) head.appendChild(el('th', h));
    table.appendChild(head);
    for (const r of runs) {
      const tr = el('tr');
      const td = el('td');
      td.appendChild(el('a', r.run_id, {href: '/runs/' + encodeURIComponent(r.run_id)}));
      tr.appendChild(td);
      tr.appendChild(el('td', stateText(r), {'data-state': r.state}));
      tr.appendChild(el('td', r.bodies === undefined ? '' : countText(r.bodies)));
      tr.appendChild(el('td', r.collisions === undefined ? '' : countText(r.collisions)));
      tr.appendChild(el('td', r.model || ''));
      tr.appendChild(el('td', r.accepted_stamp ? new Date(r.accepted_stamp * 1000).toLocaleTimeString() : ''));
      tr.appendChild(r.state === 'finished' || r.state === 'interrupted' ? el('td') : stopCell(r.run_id));
      table.appendChild(tr);
    }
    section.appendChild(table);
  }
  if (rejections.length) {
    section.appendChild(el('h3', 'Rejected inputs, newest first'));
    const table = el('table', null, {'data-rejections': name});
    const head = el('tr');
    for (const h of ['when', 'run_id asked for', 'refused by', 'reason', 'field', 'message']) head.appendChild(el('th', h));
    table.appendChild(head);
    for (const r of rejections) {
      const tr = el('tr');
      tr.appendChild(el('td', new Date(r.at * 1000).toLocaleTimeString()));
      tr.appendChild(el('td', r.run_id));  // only what the student typed: empty for the page's own numbering
      tr.appendChild(el('td', r.by || 'lab node'));
      tr.appendChild(el('td', r.reason_name));
      tr.appendChild(el('td', r.field));
      tr.appendChild(el('td', r.message));
      table.appendChild(tr);
    }
    section.appendChild(table);
  }
  return section;
}

async function teacherPage() {
  const box = document.getElementById('students');
  async function refresh() {
    const runs = await (await fetch('/api/runs')).json();
    const rejections = await (await fetch('/api/rejections')).json();
    const queue = await (await fetch('/api/queue')).json();
    const byStudent = new Map();
    const of = (student) => {
      const name = student || '(no name)';
      if (!byStudent.has(name)) byStudent.set(name, {runs: [], rejections: []});
      return byStudent.get(name);
    };
    for (const r of runs) of(r.student).runs.push(r);
    for (const r of rejections) of(r.student).rejections.push(r);
    const parts = [];
    for (const name of [...byStudent.keys()].sort()) {
      parts.push(studentSection(name, byStudent.get(name).runs, byStudent.get(name).rejections));
    }
    if (parts.length === 0) parts.push(el('p', 'No runs yet.'));
    parts.unshift(queueTable(queue));
    box.replaceChildren(...parts);
    document.body.dataset.runs = String(runs.length);
    document.body.dataset.rejections = String(rejections.length);
  }
  await refresh();
  setInterval(refresh, 5000);
}

// Each page says which it is (body data-page): no inline script (Content-Security-Policy).
if (document.body.dataset.page === 'start') startPage();
if (document.body.dataset.page === 'teacher') teacherPage();
