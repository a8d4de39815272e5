// The playground's drawing (issue 55): the field as arrows (on a canvas under the SVG) with axes in mm, a
// rigid part's angular rate theta' as the colour under them, the fixed points and lines marked by their stability,
// and a dropped part's trajectory coloured by its contact mode. No library: plain SVG elements and a canvas.
'use strict';
const PlateDraw = (() => {
  const NS = 'http://www.w3.org/2000/svg';
  const SIZE = 640, M = {left: 70, right: 20, top: 20, bottom: 60};
  const W = SIZE - M.left - M.right, H = SIZE - M.top - M.bottom;
  const STABILITY = {stable: '#1a9850', unstable: '#d73027', saddle: '#f46d43', centre: '#4575b4'};
  const MODE = {slide: '#2166ac', stuck: '#d6604d', pivot: '#e08214'};

  function el(name, attrs, parent) {
    const e = document.createElementNS(NS, name);
    for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
    if (parent) parent.appendChild(e);
    return e;
  }
  // The plot's frame for a grid: metres to pixels and back.
  function frame(grid) {
    const [x0, x1] = grid.x, [y0, y1] = grid.y;
    const sx = W / Math.max(x1 - x0, 1e-12), sy = H / Math.max(y1 - y0, 1e-12);
    return {
      x0, x1, y0, y1,
      px: x => M.left + (x - x0) * sx,
      py: y => M.top + H - (y - y0) * sy,
      fromPixel: (px, py) => [x0 + (px - M.left) / sx, y0 + (M.top + H - py) / sy],
    };
  }
  function ticks(a, b, n) {
    const step = Math.pow(10, Math.floor(Math.log10((b - a) / n)));
    const s = [1, 2, 5, 10].map(k => k * step).find(k => (b - a) / k <= n) || step * 10;
    const out = [];
    for (let v = Math.ceil(a / s) * s; v <= b + 1e-12 * s; v += s) out.push(v);
    return out;
  }
  function axes(svg, f) {
    const g = el('g', {class: 'axes', 'font-size': 12}, svg);
    el('rect', {x: M.left, y: M.top, width: W, height: H, fill: 'none', stroke: '#888'}, g);
    for (const v of ticks(f.x0 * 1e3, f.x1 * 1e3, 8)) {
      const x = f.px(v / 1e3);
      el('line', {x1: x, x2: x, y1: M.top + H, y2: M.top + H + 5, stroke: '#444'}, g);
      el('text', {x, y: M.top + H + 18, 'text-anchor': 'middle'}, g).textContent = +v.toFixed(6);
    }
    for (const v of ticks(f.y0 * 1e3, f.y1 * 1e3, 8)) {
      const y = f.py(v / 1e3);
      el('line', {x1: M.left - 5, x2: M.left, y1: y, y2: y, stroke: '#444'}, g);
      el('text', {x: M.left - 8, y: y + 4, 'text-anchor': 'end'}, g).textContent = +v.toFixed(6);
    }
    el('text', {x: M.left + W / 2, y: SIZE - 18, 'text-anchor': 'middle'}, g).textContent = 's_x [mm]';
    el('text', {x: 18, y: M.top + H / 2, 'text-anchor': 'middle', transform: `rotate(-90 18 ${M.top + H / 2})`}, g)
        .textContent = 's_y [mm]';
  }
  // A diverging colour for r in [-1, 1]: blue (negative), white, red (positive).
  function diverging(r) {
    const t = Math.max(-1, Math.min(1, r));
    const c = t < 0 ? [69, 117, 180] : [215, 48, 39];
    const a = Math.abs(t);
    return `rgb(${c.map(k => Math.round(255 + (k - 255) * a)).join(',')})`;
  }

  // The canvas `id` under the SVG (the same 640 x 640 frame), cleared and scaled to the screen's pixels.
  function canvas(id) {
    const c = document.getElementById(id), ratio = window.devicePixelRatio || 1;
    if (c.width !== SIZE * ratio) c.width = c.height = SIZE * ratio;
    const ctx = c.getContext('2d');
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    ctx.clearRect(0, 0, SIZE, SIZE);
    return ctx;
  }
  // The field (the program's JSON, output.cpp) with its fixed points (or null). Returns the frame. The
  // many marks -- theta' cells and arrows, one per grid point -- go on two canvases under the SVG (625 SVG
  // arrows cost the page about 8 ms a field: docs/decisions/web.md), the arrows on their own (transparent
  // elsewhere: the page check reads their ink back); axes, fixed points and trajectories stay SVG.
  function field(svg, fld, fixed) {
    svg.replaceChildren();
    let ctx = canvas('plot-cells');
    const grid = fld.grid, f = frame(grid), pts = fld.points;
    const nx = grid.nx, ny = grid.ny;
    const dx = nx > 1 ? (f.x1 - f.x0) / (nx - 1) : f.x1 - f.x0 || 1, dy = ny > 1 ? (f.y1 - f.y0) / (ny - 1) : f.y1 - f.y0 || 1;
    const rigid = pts.length && pts[0].twist && pts[0].twist.length === 3;
    const omegaMax = rigid ? Math.max(1e-12, ...pts.filter(p => p.converged).map(p => Math.abs(p.twist[2]))) : 0;
    if (rigid) {   // theta' as the colour of each point's cell
      for (const p of pts) {
        if (!p.converged) continue;
        const [x, y] = p.at;
        const xa = f.px(Math.max(f.x0, x - dx / 2)), xb = f.px(Math.min(f.x1, x + dx / 2));
        const ya = f.py(Math.min(f.y1, y + dy / 2)), yb = f.py(Math.max(f.y0, y - dy / 2));
        ctx.fillStyle = diverging(p.twist[2] / omegaMax);
        ctx.fillRect(xa, ya, xb - xa, yb - ya);
      }
    }
    axes(svg, f);
    ctx = canvas('plot-arrows');
    const speeds = pts.filter(p => p.converged).map(p => Math.hypot(p.twist[0], p.twist[1]));
    const vmax = Math.max(1e-300, ...speeds);
    const cell = Math.min(W / Math.max(nx - 1, 1), H / Math.max(ny - 1, 1));
    const lines = new Path2D(), heads = new Path2D();
    ctx.font = '10px sans-serif';
    ctx.textAlign = 'center';
    ctx.fillStyle = '#999';
    for (const p of pts) {
      const x = f.px(p.at[0]), y = f.py(p.at[1]);
      if (!p.converged) {
        ctx.fillText('×', x, y + 4);
        continue;
      }
      const v = Math.hypot(p.twist[0], p.twist[1]), len = 0.85 * cell * v / vmax;
      if (len < 0.5) {
        heads.moveTo(x + 1.2, y);
        heads.arc(x, y, 1.2, 0, 2 * Math.PI);
        continue;
      }
      const ux = p.twist[0] / v, uy = -p.twist[1] / v, hx = x + ux * len, hy = y + uy * len, h = Math.min(5, len / 2);
      lines.moveTo(x, y);
      lines.lineTo(hx, hy);
      heads.moveTo(hx, hy);
      heads.lineTo(hx - ux * h - uy * h / 2, hy - uy * h + ux * h / 2);
      heads.lineTo(hx - ux * h + uy * h / 2, hy - uy * h - ux * h / 2);
      heads.closePath();
    }
    ctx.strokeStyle = ctx.fillStyle = '#222';
    ctx.lineWidth = 1.2;
    ctx.stroke(lines);
    ctx.fill(heads);
    if (fixed) fixedPoints(svg, f, fixed);
    return {frame: f, vmax, omegaMax, rigid};
  }

  function fixedPoints(svg, f, fixed) {
    const g = el('g', {class: 'fixed'}, svg);
    for (const l of fixed.lines || []) {
      el('polyline', {points: l.points.map(q => `${f.px(q[0])},${f.py(q[1])}`).join(' '), fill: 'none',
                      stroke: STABILITY[l.stability] || '#000', 'stroke-width': 4, opacity: 0.7}, g);
    }
    for (const p of fixed.points || []) {
      el('circle', {cx: f.px(p.at[0]), cy: f.py(p.at[1]), r: 7, fill: STABILITY[p.stability] || '#000', stroke: '#000'}, g);
    }
  }

  // The legend below the plot: arrow scale, theta' colours, fixed-point classes, trajectory modes.
  function legend(div, info) {
    const items = [`arrows: longest ${(info.vmax * 1e3).toPrecision(3)} mm/s`];
    if (info.rigid) items.push(`colour: theta' from <span style="background:${diverging(-1)}">&nbsp;-${info.omegaMax.toPrecision(3)}&nbsp;</span>` +
                               ` to <span style="background:${diverging(1)}">&nbsp;+${info.omegaMax.toPrecision(3)}&nbsp;</span> rad/s`);
    for (const [k, c] of Object.entries(STABILITY)) items.push(`<b style="color:${c}">●</b> ${k}`);
    for (const [k, c] of Object.entries(MODE)) items.push(`<b style="color:${c}">━</b> ${k}`);
    items.push('× no cycle');
    div.innerHTML = items.map(s => `<span>${s}</span>`).join(' ');
  }

  // A trajectory ({t, q, mode}) drawn segment by segment over `seconds` of wall time; returns a stop function.
  function trajectory(svg, f, tr, seconds) {
    const g = el('g', {class: 'trajectory', 'stroke-width': 2.5, fill: 'none'}, svg);
    const n = tr.t.length;
    let i = 1, stopped = false;
    const start = performance.now();
    function step(now) {
      if (stopped) return;
      const upto = Math.min(n, 1 + Math.ceil((n - 1) * Math.min(1, (now - start) / (1000 * seconds))));
      for (; i < upto; ++i) {
        const a = tr.q[i - 1], b = tr.q[i], mode = tr.mode[i].replace(/[0-9]/g, '');
        el('line', {x1: f.px(a[0]), y1: f.py(a[1]), x2: f.px(b[0]), y2: f.py(b[1]), stroke: MODE[mode] || '#000'}, g);
      }
      if (i < n) requestAnimationFrame(step);
      else el('circle', {cx: f.px(tr.q[n - 1][0]), cy: f.py(tr.q[n - 1][1]), r: 4, fill: '#000'}, g);
    }
    if (n) el('circle', {cx: f.px(tr.q[0][0]), cy: f.py(tr.q[0][1]), r: 4, fill: '#fff', stroke: '#000'}, g);
    requestAnimationFrame(step);
    return () => { stopped = true; };
  }

  return {field, legend, trajectory, frame};
})();
