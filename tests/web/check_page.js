#!/usr/bin/env node
// The playground as a person uses it (issue 55): web/index.html opened in headless Chromium (over the
// DevTools protocol, browser.js), a slider moved through the page's own control, and the field the page
// then computed (in its worker) compared with `plate field` on the scene the page now holds, to 1e-9;
// no exception, console.error or failed load in the page; a part dropped on the field and its
// trajectory drawn; screenshots kept in OUT_DIR. Two scenes: fig1_point (a point part; the first
// harmonic's amplitude slider) and fig4 (a rigid part; the theta slider, so the slice at a new theta).
//   check_page.js PLATE_EXE SITE_DIR OUT_DIR
'use strict';
const {execFileSync} = require('child_process');
const fs = require('fs');
const path = require('path');
const {serve, open, until} = require('./browser.js');

const [exe, site, out] = process.argv.slice(2);
const TOL = 1e-9;   // as check_field.js (the module's field is the program's to 3e-13 there)
fs.mkdirSync(out, {recursive: true});
let failed = 0;
const fail = msg => { console.log('FAIL: ' + msg); failed++; };
const idle = "document.body.dataset.state === 'idle'";

// Moves the slider `id` through its input event three times in a row, as a dragging hand does, the last
// time to value(old); waits for the field. Returns the value and how many fields the page drew meanwhile:
// one, the last slider position's (the first request is in flight when the others come; the second is
// replaced by the third before it is sent, and the first one's answer is stale, dropped).
async function moveSlider(page, id, value) {
  return page.evaluate(`(async () => {
    const s = document.getElementById(${JSON.stringify(id)}), before = playground.lastField, shown = playground.fieldsShown;
    const last = (${value})(+s.value), first = +s.value;
    for (const v of [first + 0.5 * (last - first), first + 0.75 * (last - first), last]) {
      s.value = v;
      s.dispatchEvent(new Event('input', {bubbles: true}));
    }
    await ${until(`playground.lastField !== before && ${idle}`)};
    return {value: +s.value, drawn: playground.fieldsShown - shown};
  })()`);
}

async function check(base, name, slider, value) {
  const page = await open(`${base}/index.html?scene=${name}`);
  try {
    await page.evaluate(until(`playground.lastField && ${idle}`));
    const {value: moved, drawn} = await moveSlider(page, slider, value);
    if (drawn !== 1) fail(`${name}: ${drawn} fields drawn for three quick slider moves, not only the last one's`);
    const got = await page.evaluate(`({scene: JSON.stringify(playground.scene), field: playground.lastField,
                                       theta: +document.getElementById('theta').value})`);
    // the field is the slice the page's theta control shows (a point part's: theta 0)
    if (name !== 'fig1_point' && got.field.grid.theta0 !== got.theta)
      fail(`${name}: the field is the slice at theta ${got.field.grid.theta0}, the page's control says ${got.theta}`);
    // the native program on the page's scene and grid
    const tmp = fs.mkdtempSync('/tmp/plate-page-'), file = path.join(tmp, name + '.json');
    fs.writeFileSync(file, got.scene);
    const g = got.field.grid;
    const native = JSON.parse(execFileSync(exe, ['field', file, '--nx', String(g.nx), '--ny', String(g.ny), '--ntheta', '1',
                                                 '--x', String(g.x[0]), String(g.x[1]), '--y', String(g.y[0]), String(g.y[1]),
                                                 '--theta0', String(g.theta0), '--threads', '1'], {encoding: 'utf8'}));
    fs.rmSync(tmp, {recursive: true});
    let worst = 0, mismatched = 0;
    native.points.forEach((p, i) => {
      const w = got.field.points[i];
      if (!w || JSON.stringify(w.at) !== JSON.stringify(p.at) || w.converged !== p.converged) { mismatched++; return; }
      if (p.converged) p.twist.forEach((v, k) => { worst = Math.max(worst, Math.abs(v - w.twist[k])); });
    });
    if (native.points.length !== got.field.points.length || mismatched)
      fail(`${name}: ${mismatched} points differ in place or convergence (${got.field.points.length} vs ${native.points.length})`);
    if (!(worst <= TOL)) fail(`${name}: the page's field differs from plate field by ${worst}`);
    console.log(`${name}: ${slider} moved (three quick moves, ${drawn} field drawn) to ${moved}; the page's ${got.field.points.length}-point field against plate field: ` +
                `largest difference ${worst.toExponential(3)}`);
    // drop a part at (30 %, 30 %) of the plot and let the trajectory draw
    await page.evaluate(`(async () => {
      const svg = document.getElementById('plot'), box = svg.getBoundingClientRect(), before = playground.lastTrajectory;
      svg.dispatchEvent(new MouseEvent('click', {clientX: box.left + 0.3 * box.width, clientY: box.top + 0.3 * box.height, bubbles: true}));
      await ${until(`playground.lastTrajectory !== before && ${idle}`)};
      await new Promise(r => setTimeout(r, 2500));
    })()`);
    const samples = await page.evaluate('playground.lastTrajectory.t.length');
    if (!(samples > 1)) fail(`${name}: the dropped part's trajectory has ${samples} samples`);
    const shot = path.join(out, `playground_${name}.png`);
    await page.screenshot(shot);
    console.log(`${name}: trajectory of ${samples} samples drawn; screenshot ${shot}`);
    const errors = await page.evaluate('document.body.dataset.errors');
    if (errors !== 'none') fail(`${name}: the page states errors: ${errors}`);
    if (page.problems.length) fail(`${name}: errors in the page: ${page.problems.join(' | ')}`);
  } finally {
    await page.close();
  }
}

serve(site).then(async server => {
  const base = `http://127.0.0.1:${server.address().port}`;
  try {
    await check(base, 'fig1_point', 'h0-amp', 'a => 0.9 * a');
    await check(base, 'fig4', 'theta', '() => 0.5');
  } catch (e) {
    fail(String(e));
  }
  server.close();
  console.log(failed ? `${failed} failure(s)` : 'the page computes the native field and shows no error');
  process.exit(failed ? 1 : 0);
});
