#!/usr/bin/env node
// The playground as a person uses it (issue 55): web/index.html opened in headless Chromium (over the
// DevTools protocol, browser.js), a slider moved through the page's own control, and the field the page
// then computed (in its worker) compared with `plate field` on the scene the page now holds, to 1e-9;
// no exception, console.error or failed load in the page; a part dropped on the field and its
// trajectory drawn; screenshots kept in OUT_DIR. Two scenes: fig1_point (a point part; the first
// harmonic's amplitude slider) and fig4 (a rigid part; the theta slider, so the slice at a new theta).
// Then a scene file loaded and saved through the page's controls (loadAndSave).
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

// The drawing read back: the field's arrows are painted on their own canvas under the plot (draw.js;
// transparent elsewhere, so its alpha is ink). For the ten fastest points and ten at about 0.6 of their
// speed (at least 10 px long), the ink in a 5 x 5 pixel
// window about the arrow's head (its centroid, 2/3 of the head's length back from the tip) against the
// same window about the shaft's middle: a filled head of 5 px holds 12.5 px^2 of ink, the 1.2 px shaft
// 6 px^2 in the window, so the head's window must hold at least 1.5 times the shaft's (measured: at least
// 2.14 on fig1_point, 2.18 on fig4; arrows drawn backwards 0.42, without heads 0.91-1). The slower ten:
// 1.48 and 1.88; every arrow drawn at full length 1.0 and 0.94.
// The arrow's length and head follow draw.js (0.85 of the cell at the fastest speed; head min(5, length / 2) px).
const drawnHeads = `(() => {
  const fld = playground.lastField, f = PlateDraw.frame(fld.grid), c = document.getElementById('plot-arrows');
  const ctx = c.getContext('2d'), ratio = c.width / 640;
  const ink = (x, y) => {
    const d = ctx.getImageData(Math.round((x - 2.5) * ratio), Math.round((y - 2.5) * ratio), Math.round(5 * ratio), Math.round(5 * ratio)).data;
    let sum = 0;
    for (let k = 3; k < d.length; k += 4) sum += d[k] / 255;
    return sum / (ratio * ratio);
  };
  const pts = fld.points.filter(p => p.converged).map(p => ({p, v: Math.hypot(p.twist[0], p.twist[1])})).sort((a, b) => b.v - a.v);
  const cell = Math.min(550 / Math.max(fld.grid.nx - 1, 1), 560 / Math.max(fld.grid.ny - 1, 1)), vmax = pts[0].v;
  // The ten fastest, and ten at 0.5-0.7 of the fastest speed (at least 10 px long; their heads sit at that
  // share of the full length, so an arrow drawn at the wrong length puts its head where the window sees
  // shaft only). A shorter head (up to 5 px) holds less ink: those need 1.25.
  const ratio_at = ({p, v}) => {
    const len = 0.85 * cell * v / vmax, h = Math.min(5, len / 2), ux = p.twist[0] / v, uy = -p.twist[1] / v;
    const x = f.px(p.at[0]), y = f.py(p.at[1]);
    return ink(x + ux * (len - 2 * h / 3), y + uy * (len - 2 * h / 3)) / ink(x + ux * len / 2, y + uy * len / 2);
  };
  const middling = pts.filter(q => q.v <= 0.7 * vmax && q.v >= 0.5 * vmax && 0.85 * cell * q.v / vmax >= 10).slice(0, 10);
  return {fast: Math.min(...pts.slice(0, 10).map(ratio_at)), middling: middling.length >= 5 ? Math.min(...middling.map(ratio_at)) : 0,
          count: middling.length};
})()`;

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
    const heads = await page.evaluate(drawnHeads);
    if (!(heads.fast >= 1.5)) fail(`${name}: the 10 fastest arrows' heads hold only ${heads.fast} times their shaft's ink on the canvas`);
    if (!(heads.middling >= 1.25))
      fail(`${name}: ${heads.count} arrows at 0.5-0.7 of the fastest speed: heads hold ${heads.middling} times their shaft's ink`);
    else console.log(`${name}: arrows drawn on the canvas, heads where the field points and as long: the 10 fastest ink ` +
                     `${heads.fast.toFixed(2)} x the shaft's, ${heads.count} at 0.5-0.7 of their speed ${heads.middling.toFixed(2)}`);
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

// The field `plate field` computes from a scene file on a small grid over (s_x, s_y, theta): what the
// program makes of the file, to compare two files' meaning by.
function meaning(file) {
  const f = JSON.parse(execFileSync(exe, ['field', file, '--grid', '3', '--ntheta', '2', '--threads', '1'], {encoding: 'utf8'}));
  return JSON.stringify(f.points);
}

// Load and save through the page's own controls: fig4's file chosen in the page's file input (the page
// started on fig1_point), its controls then show fig4's part; an amplitude typed in; "save scene JSON"
// downloads a file whose meaning is the loaded file's with that edit -- `plate field` on both the same to
// the bit (the page holds the program's reading of the file, and JSON carries doubles exactly) -- and
// whose name is the file's. A negative
// control: the saved file with one friction coefficient changed by 1e-9 relative must differ.
async function loadAndSave(base) {
  const page = await open(`${base}/index.html?scene=fig1_point`);
  const downloads = fs.mkdtempSync('/tmp/plate-save-');
  try {
    await page.evaluate(until(`playground.lastField && ${idle}`));
    await page.downloadTo(downloads);
    const file = path.resolve(site, 'scenes/fig4.json'), original = JSON.parse(fs.readFileSync(file, 'utf8'));
    const before = await page.evaluate('playground.lastField');
    await page.chooseFiles('#scene-load', [file]);
    await page.evaluate(until(`playground.source === 'fig4.json' && playground.lastField && playground.lastField.points.length !== ${before.points.length} && ${idle}`));
    const shown = await page.evaluate(`({contacts: document.querySelectorAll('#contacts tr').length - 1,
                                         harmonics: document.querySelectorAll('#harmonics tbody tr').length, name: playground.scene.name})`);
    if (shown.contacts !== original.part.contacts.length || shown.harmonics !== original.plate.harmonics.length)
      fail(`loaded fig4.json: the page shows ${shown.contacts} contacts and ${shown.harmonics} harmonics, the file has ` +
           `${original.part.contacts.length} and ${original.plate.harmonics.length}`);
    // An edit before the save, typed into the first harmonic's amplitude box (beside its slider): the
    // saved file must carry it (a save that wrote back the loaded text would not).
    const edited = 17.25;
    const fieldBefore = await page.evaluate('playground.lastField');
    await page.evaluate(`(() => { const n = document.getElementById('h0-amp').nextElementSibling;
      n.value = '${edited}'; n.dispatchEvent(new Event('input', {bubbles: true})); })()`);
    await page.evaluate(until(`JSON.stringify(playground.lastField.points) !== ${JSON.stringify(JSON.stringify(fieldBefore.points))} && ${idle}`));
    const expected = path.join(downloads, 'expected.json');
    const edit = JSON.parse(fs.readFileSync(file, 'utf8'));
    edit.plate.harmonics[0].amp = edited;
    fs.writeFileSync(expected, JSON.stringify(edit));
    await page.evaluate("document.getElementById('scene-save').click()");
    const saved = path.join(downloads, `${shown.name}.json`);
    for (let t = 0; t < 200 && !fs.existsSync(saved); ++t) await new Promise(r => setTimeout(r, 50));
    if (!fs.existsSync(saved)) return fail(`saved: no ${path.basename(saved)} downloaded (${fs.readdirSync(downloads)})`);
    const text = fs.readFileSync(saved, 'utf8'), copy = JSON.parse(text), failedBefore = failed;
    if (copy.name !== original.name) fail(`saved: named '${copy.name}', the file '${original.name}'`);
    if (meaning(saved) !== meaning(expected)) fail("saved: plate field on the saved file differs from the loaded file's with the typed edit");
    if (meaning(saved) === meaning(file)) fail('saved: the typed edit is not in the saved file');
    copy.part.friction = [].concat(copy.part.friction).map((mu, i) => (i === 0 ? mu * (1 + 1e-9) : mu));
    const wrong = path.join(downloads, 'wrong.json');
    fs.writeFileSync(wrong, JSON.stringify(copy));
    if (meaning(wrong) === meaning(expected)) fail('saved: the comparison did not see a friction coefficient changed by 1e-9');
    if (failed === failedBefore) console.log(`load and save: fig4.json loaded through the page's file input (${shown.contacts} contacts, ${shown.harmonics} harmonics shown), ` +
                `the first amplitude typed as ${edited}, saved as ${path.basename(saved)}: plate field the same to the bit as on the file with that edit; with a friction coefficient x (1 + 1e-9), not`);
    const errors = await page.evaluate('document.body.dataset.errors');
    if (errors !== 'none') fail(`load and save: the page states errors: ${errors}`);
    if (page.problems.length) fail(`load and save: errors in the page: ${page.problems.join(' | ')}`);
  } finally {
    await page.close();
    fs.rmSync(downloads, {recursive: true, force: true});
  }
}

serve(site).then(async server => {
  const base = `http://127.0.0.1:${server.address().port}`;
  try {
    await check(base, 'fig1_point', 'h0-amp', 'a => 0.9 * a');
    await check(base, 'fig4', 'theta', '() => 0.5');
    await loadAndSave(base);
  } catch (e) {
    fail(String(e));
  }
  server.close();
  console.log(failed ? `${failed} failure(s)` : 'the page computes the native field and shows no error');
  process.exit(failed ? 1 : 0);
});
