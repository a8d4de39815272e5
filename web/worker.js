// The playground's worker (issue 55): the WebAssembly module (plate_web.js, built by the target `web`)
// answers the page's requests one at a time, off the page's thread. A request is
// {id, request: the JSON API's request (web/plate_web.cpp)}; the answer {id, answer}. The page drops
// answers whose id is no longer its latest (a slider moved on meanwhile).
'use strict';
importScripts('plate_web.js');
let call = null;
const queue = [];
function serve() {
  while (call && queue.length) {
    const m = queue.shift();
    let answer;
    try {
      answer = JSON.parse(call(JSON.stringify(m.request)));
    } catch (e) {
      answer = {ok: false, error: 'the module failed: ' + e};
    }
    postMessage({id: m.id, answer});
  }
}
createPlateModule().then(M => {
  call = req => M.ccall('plate_call', 'string', ['string'], [req]);
  postMessage({ready: true});
  serve();
});
onmessage = e => {
  queue.push(e.data);
  serve();
};
