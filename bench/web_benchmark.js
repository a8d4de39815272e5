#!/usr/bin/env node
// The playground's speed (issue 55; a benchmark, not a test): web/index.html in headless Chromium, a
// slider moved ROUNDS times through the page's own control, each time timed from the slider's input
// event to the new field in the page (round trip) and inside the worker (the module's call).
//   fig1_point (a point part), 25 x 25, the first harmonic's amplitude;  target <= 100 ms
//   fig4 (a rigid part), the 9 x 9 slice, the theta slider;                target <= 300 ms
//   node bench/web_benchmark.js SITE_DIR [ROUNDS]    (SITE_DIR: build/web/site, the target `web`)
'use strict';
const {execFileSync} = require('child_process');
const fs = require('fs');
const os = require('os');
const {serve, open, until} = require('../tests/web/browser.js');

const [site, rounds = '7'] = process.argv.slice(2);
const idle = "document.body.dataset.state === 'idle'";
const median = a => [...a].sort((x, y) => x - y)[Math.floor(a.length / 2)];

async function bench(base, scene, n, slider, next) {
  const page = await open(`${base}/index.html?scene=${scene}`);
  try {
    await page.evaluate(until(`playground.lastField && ${idle}`));
    await page.evaluate(`(async () => {
      const g = document.getElementById('grid-n'), before = playground.lastField;
      if (+g.value === ${n}) return;
      g.value = ${n};
      g.dispatchEvent(new Event('change', {bubbles: true}));
      await ${until(`playground.lastField !== before && ${idle}`)};
    })()`);
    const trip = [], worker = [];
    for (let k = 0; k < +rounds; ++k) {
      const r = await page.evaluate(`(async () => {
        const s = document.getElementById(${JSON.stringify(slider)}), before = playground.lastField;
        const t0 = performance.now();
        s.value = (${next})(+s.value, ${k});
        s.dispatchEvent(new Event('input', {bubbles: true}));
        await ${until('playground.lastField !== before')};
        const trip = performance.now() - t0;
        await ${until(idle)};
        return {trip, worker: playground.lastFieldMilliseconds, points: playground.lastField.points.length};
      })()`);
      if (r.points !== n * n) throw new Error(`${scene}: ${r.points} points, not ${n * n}`);
      trip.push(r.trip);
      worker.push(r.worker);
    }
    return {trip, worker};
  } finally {
    await page.close();
  }
}

serve(site).then(async server => {
  const base = `http://127.0.0.1:${server.address().port}`;
  const cpu = (fs.readFileSync('/proc/cpuinfo', 'utf8').match(/model name\s*:\s*(.*)/) || [])[1] || 'unknown CPU';
  console.log(`machine: ${cpu}, ${os.cpus().length} hardware threads; ${execFileSync('chromium', ['--version'], {stdio: ['ignore', 'pipe', 'ignore']}).toString().trim()}; ` +
              `load average ${os.loadavg()[0].toFixed(2)}`);
  for (const [scene, n, slider, next, target] of [['fig1_point', 25, 'h0-amp', '(a, k) => a * (k % 2 ? 1.01 : 0.99)', 100],
                                                    ['fig4', 9, 'theta', '(t, k) => 0.1 * (k + 1)', 300]]) {
    const r = await bench(base, scene, n, slider, next);
    console.log(`${scene} ${n} x ${n}: median ${median(r.trip).toFixed(0)} ms from the slider to the drawn field ` +
                `(${median(r.worker).toFixed(0)} ms in the module; target <= ${target} ms); ` +
                `each: ${r.trip.map(t => t.toFixed(0)).join(' ')} ms`);
  }
  server.close();
});
