// The playground's design (issue 55): a point part's sink designed in the page, as `plate design PART
// --target sink X Y` designs it (the module's op "design", web/plate_web_design.cpp). It takes seconds, so it
// runs in a worker of its own -- the field's worker stays free for the sliders -- and when the scene or the
// design's inputs change while it runs, that worker is ended (the stale design dropped, no time spent on
// it) and a fresh one started for the next design. The page states the design's state on <body> for the
// browser check: data-design = unavailable, ready, running, done, dropped.
'use strict';
const PlateDesign = (() => {
  const $ = id => document.getElementById(id);
  let worker = null, running = 0, nextId = 1, last = null;
  const state = (s, text) => {
    document.body.dataset.design = s;
    $('design-status').textContent = text;
  };

  function startWorker() {
    worker = new Worker('worker.js');
    worker.onerror = e => { PlateDesign.noteError('design worker: ' + e.message); };
    worker.onmessage = e => {
      if (e.data.ready || e.data.id !== running) return;
      running = 0;
      show(e.data.answer);
    };
  }
  function show(answer) {
    if (!answer.ok) {
      state('done', 'the design was refused: ' + answer.error);
      return;
    }
    const d = answer.design, s = d.summary;
    last = d;
    playground.lastDesign = d;
    const mm = v => (v * 1e3).toFixed(3);
    const where = s.fixed_point ? `stable fixed point at (${mm(s.fixed_point[0])}, ${mm(s.fixed_point[1])}) mm, ` : '';
    state('done', (d.verified ? 'verified: ' : 'not verified (' + s.failure + '): ') + where +
                      `convergence rate ${s.convergence_rate_per_s.toPrecision(3)} 1/s; ${s.evaluations} evaluations, ` +
                      `${s.limit_cycles} limit cycles, ${(answer.milliseconds / 1e3).toFixed(1)} s in the worker`);
    $('design-apply').hidden = !d.verified;
  }

  // Designs for the page's scene and the design's inputs.
  function run() {
    drop('');
    if (!worker) startWorker();
    running = nextId++;
    const request = {op: 'design', scene: PlateDesign.sceneText(), source: playground.source,
                     target: [+$('design-x').value, +$('design-y').value],
                     starts: Math.max(1, Math.round(+$('design-starts').value)),
                     evaluations: Math.max(1, Math.round(+$('design-evaluations').value))};
    playground.designs++;
    worker.postMessage({id: running, request});
    state('running', 'designing (plate design in the page; seconds to a minute)...');
  }
  // A running design dropped (its worker ended) because `why`; nothing when none runs.
  function drop(why) {
    $('design-apply').hidden = true;
    if (!running) return;
    // (ended while it loads the module, the worker reports its importScripts as failed: that report,
    // about a worker the page no longer wants, is silenced)
    worker.onmessage = null;
    worker.onerror = e => e.preventDefault();
    worker.terminate();
    worker = null;
    running = 0;
    playground.designsDropped++;
    if (why) state('dropped', `design dropped: ${why} while it ran; design again for the new inputs`);
  }
  // The page's scene changed: a running design is stale; a point part can be designed for, a rigid one not here.
  function sceneChanged(point) {
    drop('the scene changed');
    $('design-run').disabled = !point || document.body.dataset.design === 'unavailable';
    $('design-note').textContent = point ? '' : 'a rigid part: plate design designs it natively (minutes); the page designs point parts';
  }
  // The module says whether it designs (it does not when NLopt's source could not be fetched at its build).
  function about(answer) {
    if (answer.ok && answer.design) {
      if (!document.body.dataset.design) state('ready', '');
      return;
    }
    state('unavailable', answer.why || answer.error);
    $('design-run').disabled = true;
  }
  function init() {
    playground.designs = 0;
    playground.designsDropped = 0;
    $('design-run').addEventListener('click', run);
    $('design-apply').addEventListener('click', () => PlateDesign.useScene(last.scene));
    for (const id of ['design-x', 'design-y', 'design-starts', 'design-evaluations'])
      $(id).addEventListener('input', () => drop('its inputs changed'));
  }
  // (sceneText, useScene and noteError are the page's: playground.js sets them)
  return {init, about, sceneChanged, noteError: () => {}, sceneText: () => '', useScene: () => {}};
})();
