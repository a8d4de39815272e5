// Headless Chromium for the playground's checks, driven over the DevTools protocol through a pipe
// (--remote-debugging-pipe: JSON messages separated by NUL on fds 3 and 4), with node's built-ins only;
// and a static server for the site (the page's worker and module need http, not file:).
'use strict';
const {spawn} = require('child_process');
const fs = require('fs');
const http = require('http');
const path = require('path');

const TYPES = {'.html': 'text/html', '.js': 'text/javascript', '.css': 'text/css', '.json': 'application/json'};
function serve(site) {
  const root = path.resolve(site);
  const server = http.createServer((req, res) => {
    const file = path.join(root, path.normalize(decodeURIComponent(new URL(req.url, 'http://x').pathname)));
    if (!file.startsWith(root)) { res.writeHead(403).end(); return; }
    fs.readFile(file, (err, data) => {
      if (err) { res.writeHead(404).end(); return; }
      res.writeHead(200, {'Content-Type': TYPES[path.extname(file)] || 'application/octet-stream'}).end(data);
    });
  });
  return new Promise(resolve => server.listen(0, '127.0.0.1', () => resolve(server)));
}

// Opens URL in a fresh headless Chromium; returns {evaluate(expr), screenshot(file), problems, close()}.
// `problems` collects what a person would call an error: exceptions, console.error, failed loads.
async function open(url, {width = 1400, height = 1000} = {}) {
  const profile = fs.mkdtempSync('/tmp/plate-chromium-');
  const proc = spawn('chromium', ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
                                  '--disable-background-networking', '--disable-component-update', '--disable-sync',
                                  `--user-data-dir=${profile}`, `--window-size=${width},${height}`,
                                  '--remote-debugging-pipe', 'about:blank'],
                     {stdio: ['ignore', 'ignore', 'pipe', 'pipe', 'pipe']});
  proc.stderr.on('data', () => {});
  const pending = new Map(), problems = [];
  let nextId = 1, buffer = '', session = null;
  proc.stdio[4].on('data', chunk => {
    buffer += chunk.toString();
    let end;
    while ((end = buffer.indexOf('\0')) >= 0) {
      const m = JSON.parse(buffer.slice(0, end));
      buffer = buffer.slice(end + 1);
      if (m.id && pending.has(m.id)) {
        const {resolve, reject} = pending.get(m.id);
        pending.delete(m.id);
        m.error ? reject(new Error(JSON.stringify(m.error))) : resolve(m.result);
      } else if (m.method === 'Runtime.exceptionThrown') {
        problems.push('exception: ' + (m.params.exceptionDetails.exception || {}).description);
      } else if (m.method === 'Runtime.consoleAPICalled' && m.params.type === 'error') {
        problems.push('console.error: ' + m.params.args.map(a => a.value !== undefined ? a.value : a.description).join(' '));
      } else if (m.method === 'Log.entryAdded' && m.params.entry.level === 'error') {
        problems.push('log: ' + m.params.entry.text + (m.params.entry.url ? ' ' + m.params.entry.url : ''));
      }
    }
  });
  const send = (method, params = {}, sessionId = session) => new Promise((resolve, reject) => {
    const id = nextId++;
    pending.set(id, {resolve, reject});
    proc.stdio[3].write(JSON.stringify(Object.assign({id, method, params}, sessionId ? {sessionId} : {})) + '\0');
  });
  const {targetId} = await send('Target.createTarget', {url: 'about:blank'}, null);
  session = (await send('Target.attachToTarget', {targetId, flatten: true}, null)).sessionId;
  await send('Runtime.enable');
  await send('Log.enable');
  await send('Page.enable');
  await send('DOM.enable');
  await send('Page.navigate', {url});
  return {
    problems,
    // The value of an expression in the page (a promise is awaited).
    async evaluate(expression) {
      const r = await send('Runtime.evaluate', {expression, awaitPromise: true, returnByValue: true});
      if (r.exceptionDetails) throw new Error('in the page: ' + (r.exceptionDetails.exception || {}).description);
      return r.result.value;
    },
    // Chooses `files` in the page's file input `selector`, as a person does in the file dialog (the input's
    // change event follows).
    async chooseFiles(selector, files) {
      const r = await send('Runtime.evaluate', {expression: `document.querySelector(${JSON.stringify(selector)})`});
      await send('DOM.setFileInputFiles', {files, objectId: r.result.objectId});
    },
    // Downloads the page starts (a link's click) land in `dir`.
    downloadTo(dir) {
      return send('Browser.setDownloadBehavior', {behavior: 'allow', downloadPath: dir}, null);
    },
    async screenshot(file) {
      const r = await send('Page.captureScreenshot', {format: 'png', captureBeyondViewport: true});
      fs.writeFileSync(file, Buffer.from(r.data, 'base64'));
    },
    close() {   // (Chromium asked to close, so that it leaves its profile; then the profile removed)
      return new Promise(resolve => {
        proc.on('exit', () => {
          fs.rmSync(profile, {recursive: true, force: true, maxRetries: 20, retryDelay: 100});
          resolve();
        });
        send('Browser.close', {}, null).catch(() => proc.kill());
      });
    },
  };
}

// A page-side wait: the expression polled every 5 ms until true (a promise for evaluate()).
const until = (cond, ms = 60000) => `new Promise((resolve, reject) => {
  const t0 = performance.now();
  (function poll() {
    let ok = false;
    try { ok = (${cond}); } catch (e) {}
    if (ok) resolve(performance.now() - t0);
    else if (performance.now() - t0 > ${ms}) reject(new Error('timed out waiting for ' + ${JSON.stringify(cond)}));
    else setTimeout(poll, 5);
  })();
})`;

module.exports = {serve, open, until};
