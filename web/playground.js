// The playground's page (issue 55): the scene's controls, the worker that computes, the drawing.
// The scene is held in the scene file's own form (scene_io.hpp) and every control edits it in place;
// each edit asks the worker for the field again. At most one request of a kind is in flight: an edit
// made meanwhile replaces the one waiting, and an answer to anything but the latest request is dropped.
// The page states what a check needs on <body>: data-state (loading, busy, idle, failed), data-errors
// (every script error, rejected promise, console.error and worker error; "none" when there were none).
'use strict';
const SCENES = ['fig1_point', 'heave_yaw_point', 'fig4', 'fig1', 'fig5', 'fig6', 'heave_yaw', 'foot', 'fig3_random'];
const AXES = ['x', 'y', 'z', 'rx', 'ry', 'rz'];
const $ = id => document.getElementById(id);

// --- errors, stated on the page for a person and for the browser check ---------------------------
const errors = [];
function noteError(what) {
  errors.push(String(what));
  document.body.dataset.errors = errors.join(' | ');
}
document.body.dataset.errors = 'none';
window.addEventListener('error', e => noteError(e.message));
window.addEventListener('unhandledrejection', e => noteError('unhandled rejection: ' + e.reason));
const consoleError = console.error.bind(console);
console.error = (...a) => { noteError(a.join(' ')); consoleError(...a); };

// --- the worker and its requests --------------------------------------------------------------
const playground = {scene: null, source: '', lastField: null, lastFixed: null, lastTrajectory: null, requests: 0, fieldsShown: 0};
window.playground = playground;
const worker = new Worker('worker.js');
const lanes = {};   // kind -> {latest, inFlight, waiting}
let nextId = 1;
worker.onerror = e => { noteError('worker: ' + e.message); setState('failed', 'the worker failed: ' + e.message); };
function setState(state, text) {
  document.body.dataset.state = state;
  $('status').className = state;
  $('status').textContent = text;
}
function busy() { return Object.values(lanes).some(l => l.inFlight || l.waiting); }
// Asks the worker (kind: a lane, one request in flight each); onAnswer gets the answer to the latest only.
function ask(kind, request, onAnswer) {
  const lane = lanes[kind] || (lanes[kind] = {latest: 0, inFlight: 0, waiting: null});
  const id = nextId++;
  lane.latest = id;
  lane.waiting = {id, request, onAnswer};
  playground.requests++;
  send(lane);
  setState('busy', 'computing...');
}
function send(lane) {
  if (lane.inFlight || !lane.waiting || !playground.ready) return;
  lane.inFlight = lane.waiting.id;
  lane.pending = lane.waiting;
  lane.waiting = null;
  worker.postMessage({id: lane.pending.id, request: lane.pending.request});
}
worker.onmessage = e => {
  if (e.data.ready) {
    playground.ready = true;
    ask('about', {op: 'about'}, PlateDesign.about);   // (whether this module designs)
    Object.values(lanes).forEach(send);
    return;
  }
  const lane = Object.values(lanes).find(l => l.inFlight === e.data.id);
  if (!lane) return;
  const mine = lane.pending;
  lane.inFlight = 0;
  lane.pending = null;
  if (mine.id === lane.latest) mine.onAnswer(e.data.answer);   // (else stale: a newer request waits)
  send(lane);
  if (!busy()) setState('idle', 'ready');
};

// --- the scene's controls ---------------------------------------------------------------------
function sceneText() { return JSON.stringify(playground.scene, null, 1); }
function isPoint() { return !('contacts' in playground.scene.part); }
function numberInput(value, step, onChange, attrs = {}) {
  const i = Object.assign(document.createElement('input'), {type: 'number', value, step});
  Object.assign(i, attrs);
  i.addEventListener('input', () => { if (i.value !== '' && isFinite(+i.value)) onChange(+i.value); });
  return i;
}
// A slider with its number beside it, kept together; `id` names the slider for the browser check.
function sliderInput(id, value, min, max, step, onChange) {
  const span = document.createElement('span');
  const r = Object.assign(document.createElement('input'), {type: 'range', id, min, max, step, value});
  const n = numberInput(value, 'any', v => { r.value = v; onChange(v); });
  r.addEventListener('input', () => { n.value = r.value; onChange(+r.value); });
  span.append(r, n);
  return span;
}
function harmonicRows() {
  const body = $('harmonics').querySelector('tbody');
  body.replaceChildren();
  playground.scene.plate.harmonics.forEach((h, k) => {
    const tr = document.createElement('tr');
    const axis = document.createElement('select');
    axis.id = `h${k}-axis`;
    for (const a of AXES) axis.add(new Option(a, a, false, a === h.axis));
    axis.addEventListener('change', () => { h.axis = axis.value; unitCell.textContent = unit(h); changed(); });
    const unit = h => (h.axis.startsWith('r') ? 'rad/s²' : 'm/s²');
    const unitCell = document.createElement('span');
    unitCell.textContent = unit(h);
    const n = numberInput(h.n, 1, v => { h.n = Math.max(1, Math.round(v)); changed(); }, {min: 1, id: `h${k}-n`});
    const amax = Math.max(10, 2 * Math.abs(h.amp));
    const amp = sliderInput(`h${k}-amp`, h.amp, 0, amax, amax / 1000, v => { h.amp = v; changed(); });
    amp.append(unitCell);
    const phase = sliderInput(`h${k}-phase`, h.phase, 0, 2 * Math.PI, 0.001, v => { h.phase = v; changed(); });
    const del = Object.assign(document.createElement('button'), {type: 'button', textContent: 'remove'});
    del.addEventListener('click', () => { playground.scene.plate.harmonics.splice(k, 1); harmonicRows(); changed(); });
    for (const c of [axis, n, amp, phase, del]) tr.appendChild(document.createElement('td')).appendChild(c);
    body.appendChild(tr);
  });
}
function partControls() {
  const part = playground.scene.part;
  $('mass').value = part.mass;
  const fr = $('friction');
  fr.replaceChildren('friction ');
  const mus = Array.isArray(part.friction) ? part.friction : [part.friction];
  mus.forEach((mu, i) => {
    const label = document.createElement('label');
    label.append(mus.length > 1 ? `contact ${i + 1} ` : 'mu ');
    label.append(sliderInput(`mu${i}`, mu, 0, 1.5, 0.001, v => {
      if (Array.isArray(part.friction)) part.friction[i] = v; else part.friction = v;
      changed();
    }));
    fr.appendChild(label);
  });
  const ct = $('contacts');
  ct.replaceChildren();
  if (!part.contacts) return;
  ct.innerHTML = '<tr><th>contact</th><th>x [m]</th><th>y [m]</th><th>z [m]</th></tr>';
  part.contacts.forEach((c, i) => {
    const tr = ct.insertRow();
    tr.insertCell().textContent = i + 1;
    c.forEach((v, k) => tr.insertCell().appendChild(numberInput(v, 0.001, x => { c[k] = x; changed(); }, {id: `c${i}-${k}`})));
  });
}
function showScene() {
  const sc = playground.scene;
  $('period').value = sc.plate.period;
  harmonicRows();
  partControls();
  $('theta-row').hidden = isPoint();
  changed();
}
// The program's warnings on the scene (outside the intended regime), listed under the scene's controls.
function showWarnings(warnings) {
  $('scene-warnings').replaceChildren(...warnings.map(w => Object.assign(document.createElement('li'), {textContent: w})));
}
// A scene file's text, read and judged by the module (the program's reader and messages): shown when
// admissible, its message (and the current scene kept) when not; the program's warnings listed.
function loadScene(text, source) {
  ask('scene', {op: 'scene', scene: text, source}, answer => {
    if (!sceneAnswer(answer)) return;
    playground.scene = answer.scene;
    playground.source = source;
    showWarnings(answer.warnings);
    $('grid-n').value = isPoint() ? 25 : 13;   // (a rigid part's cycles cost more: a coarser slice)
    showScene();
  });
}

// --- what the page computes on every change ------------------------------------------------------
function grid() {
  const n = Math.max(2, Math.min(41, Math.round(+$('grid-n').value) || 25)), h = +$('grid-half').value || 0.05;
  return {nx: n, ny: n, x: [-h, h], y: [-h, h], theta: isPoint() ? 0 : +$('theta').value};
}
let stopAnimation = () => {};
function changed() {
  PlateDesign.sceneChanged(isPoint());   // (a design running for the old scene is dropped)
  const request = {scene: sceneText(), source: playground.source, grid: grid()};
  ask('field', Object.assign({op: 'field'}, request), answer => {
    if (!sceneAnswer(answer)) return;
    showWarnings(answer.warnings);
    playground.lastField = answer.field;
    playground.fieldsShown++;
    playground.lastFieldMilliseconds = answer.milliseconds;
    stopAnimation();
    const info = PlateDraw.field($('plot'), answer.field, null);
    PlateDraw.legend($('legend'), info);
    $('timing').textContent = `field of ${answer.field.points.length} points: ${answer.milliseconds.toFixed(0)} ms in the worker`;
    // then its fixed points (a point part's; a slice of a rigid part's field holds none to search)
    if (!isPoint()) { $('fixed-summary').textContent = 'fixed points: searched on the full (s_x, s_y, theta) grid only (`plate fixed-points`), not on a slice'; return; }
    ask('fixed', Object.assign({op: 'fixed_points'}, request), fp => {
      if (!fp.ok) return;
      playground.lastFixed = fp.fixed_points;
      PlateDraw.field($('plot'), fp.field, fp.fixed_points);
      $('fixed-summary').textContent = 'fixed points: ' + fp.fixed_points.summary;
    });
  });
}
function sceneAnswer(answer) {
  $('scene-error').hidden = answer.ok;
  if (!answer.ok) { $('scene-error').textContent = answer.error; return false; }
  return true;
}

// --- wiring -----------------------------------------------------------------------------------
for (const s of SCENES) $('scene-pick').add(new Option(s + (s.endsWith('_point') ? ' (point part)' : ''), s));
$('scene-pick').addEventListener('change', () => pickScene($('scene-pick').value));
function pickScene(name) {
  $('scene-pick').value = name;
  fetch(`scenes/${name}.json`).then(r => r.text()).then(t => loadScene(t, `scenes/${name}.json`))
      .catch(e => noteError(`scenes/${name}.json: ${e}`));
}
$('scene-load').addEventListener('change', e => {
  const file = e.target.files[0];
  if (file) file.text().then(t => loadScene(t, file.name));
});
$('scene-save').addEventListener('click', () => {
  const a = Object.assign(document.createElement('a'), {download: (playground.scene.name || 'scene') + '.json',
                                                          href: URL.createObjectURL(new Blob([sceneText() + '\n'], {type: 'application/json'}))});
  a.click();
});
$('period').addEventListener('input', () => { if (+$('period').value > 0) { playground.scene.plate.period = +$('period').value; changed(); } });
$('mass').addEventListener('input', () => { if (+$('mass').value > 0) { playground.scene.part.mass = +$('mass').value; changed(); } });
$('harmonic-add').addEventListener('click', () => {
  playground.scene.plate.harmonics.push({axis: 'x', n: 1, amp: 0, phase: 0});
  harmonicRows();
  changed();
});
for (const id of ['grid-n', 'grid-half']) $(id).addEventListener('change', changed);
$('theta').addEventListener('input', () => { $('theta-out').textContent = $('theta').value; changed(); });
$('plot').addEventListener('click', e => {
  if (!playground.lastField) return;
  const svg = $('plot'), box = svg.getBoundingClientRect();
  const f = PlateDraw.frame(playground.lastField.grid);
  const [x, y] = f.fromPixel((e.clientX - box.left) * 640 / box.width, (e.clientY - box.top) * 640 / box.height);
  const duration = Math.max(0.01, +$('duration').value || 2);
  ask('trajectory', {op: 'trajectory', scene: sceneText(), source: playground.source, q0: [x, y, grid().theta], duration,
                     dt: playground.scene.plate.period / 4}, answer => {
    if (!sceneAnswer(answer)) return;
    playground.lastTrajectory = answer.trajectory;
    stopAnimation();
    stopAnimation = PlateDraw.trajectory(svg, f, answer.trajectory, Math.min(8, duration));
    const stop = answer.trajectory.stop_words;
    $('timing').textContent = `trajectory of ${duration} s (full dynamics): ${answer.milliseconds.toFixed(0)} ms` + (stop ? `; stopped: ${stop}` : '');
  });
});
Object.assign(PlateDesign, {sceneText, noteError, useScene: sc => loadScene(JSON.stringify(sc, null, 1), 'the designed sink')});
PlateDesign.init();
setState('loading', 'loading the module...');
pickScene(new URLSearchParams(location.search).get('scene') || SCENES[0]);
