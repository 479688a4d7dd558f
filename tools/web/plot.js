// Stacked strip charts on canvas, one per signal, sharing one time axis.
// Written here (no plotting library): the page must work with nothing fetched.
// Data: a Series holds firmware time t (s) and one array per signal; the view
// is [t0, t1]. Live: t1 follows the newest sample, t1 - t0 = the window.
// Paused: the view stays; the wheel zooms about the cursor, a drag pans.
'use strict';

class Series {
  // scales: SI per raw count of each signal (the META frame), for the axes' least span.
  constructor(names, units, keepS, scales) {
    this.names = names; this.units = units; this.keepS = keepS;
    this.scales = scales || names.map(() => 1);
    this.t = []; this.v = names.map(() => []);
  }
  push(rows) {
    for (const r of rows) {
      this.t.push(r[0]);
      for (let k = 0; k < this.v.length; k++) this.v[k].push(r[k + 1]);
    }
    // Keep the last keepS seconds (drop in chunks: cheaper than per sample).
    const n = this.t.length;
    if (n > 2048 && this.t[n - 1] - this.t[1024] > this.keepS) {
      let cut = 0;
      while (cut < n - 1 && this.t[n - 1] - this.t[cut] > this.keepS) cut++;
      this.t.splice(0, cut);
      for (const a of this.v) a.splice(0, cut);
    }
  }
  // Index of the last sample with t <= x (binary search), -1 if none.
  indexAt(x) {
    let lo = 0, hi = this.t.length - 1, r = -1;
    while (lo <= hi) {
      const m = (lo + hi) >> 1;
      if (this.t[m] <= x) { r = m; lo = m + 1; } else hi = m - 1;
    }
    return r;
  }
}

class StripCharts {
  constructor(area, onCursor) {
    this.area = area; this.onCursor = onCursor;
    this.series = null; this.canvases = [];
    this.windowS = 2; this.paused = false; this.view = null; this.cursor = null;
    this.frames = 0; this.fps = 0; this.fpsT0 = performance.now(); this.drag = null;
    this.drawn = 0;  // frames rendered since the page opened
    this.drawMs = 0; // milliseconds spent drawing them
    this.axes = [];  // the y axis each chart was last drawn with ({lo, hi, step}; tests read it)
  }
  setSeries(series) {
    this.series = series;
    this.area.textContent = '';
    // A reference shares the chart of its signal (speed_ref with speed, ...).
    this.groups = [];
    series.names.forEach((name, k) => {
      const base = name.endsWith('_ref') ? series.names.indexOf(name.slice(0, -4)) : -1;
      const g = base >= 0 ? this.groups.find((x) => x[0] === base) : null;
      if (g) g.push(k); else if (!this.groups.some((x) => x.includes(k))) this.groups.push([k]);
    });
    // A signal listed after its reference: move the reference into its group.
    for (const g of this.groups) {
      const name = series.names[g[0]];
      const ref = series.names.indexOf(name + '_ref');
      if (ref >= 0 && !g.includes(ref)) {
        const other = this.groups.findIndex((x) => x.length === 1 && x[0] === ref);
        if (other >= 0) { this.groups.splice(other, 1); g.push(ref); }
      }
    }
    this.canvases = this.groups.map((group) => {
      const c = document.createElement('canvas');
      c.dataset.signal = series.names[group[0]];
      this.area.appendChild(c);
      c.addEventListener('mousemove', (e) => this._move(e, c));
      c.addEventListener('mouseleave', () => { this.cursor = null; this.onCursor(null); });
      c.addEventListener('wheel', (e) => this._wheel(e, c), { passive: false });
      c.addEventListener('mousedown', (e) => { this.drag = { x: e.clientX, view: this.currentView() }; });
      c.addEventListener('dblclick', () => this.goLive());
      return c;
    });
    window.addEventListener('mouseup', () => { this.drag = null; });
  }
  goLive() { this.paused = false; this.view = null; }
  pause() { this.paused = true; this.view = this.currentView(); }
  currentView() {
    if (this.paused && this.view) return this.view;
    const t = this.series ? this.series.t : [];
    const t1 = t.length ? t[t.length - 1] : this.windowS;
    return [t1 - this.windowS, t1];
  }
  _xToT(e, c) {
    const r = c.getBoundingClientRect();
    const [t0, t1] = this.currentView();
    return t0 + (e.clientX - r.left) / r.width * (t1 - t0);
  }
  _move(e, c) {
    if (this.drag && this.paused) {
      const r = c.getBoundingClientRect();
      const [a, b] = this.drag.view;
      const dt = (this.drag.x - e.clientX) / r.width * (b - a);
      this.view = [a + dt, b + dt];
    }
    this.cursor = this._xToT(e, c);
    this.onCursor(this.cursor);
  }
  _wheel(e, c) {
    e.preventDefault();
    const f = e.deltaY > 0 ? 1.25 : 0.8;
    if (!this.paused) {
      this.windowS = Math.min(600, Math.max(0.001, this.windowS * f));
      return;
    }
    const x = this._xToT(e, c);
    const [a, b] = this.view;
    this.view = [x - (x - a) * f, x + (b - x) * f];
  }
  valuesAt(x) {
    const s = this.series;
    if (!s) return null;
    const i = s.indexAt(x);
    if (i < 0) return null;
    return { t: s.t[i], v: s.v.map((a) => a[i]) };
  }
  draw() {
    this.frames++; this.drawn++;
    const now = performance.now();
    if (now - this.fpsT0 >= 1000) {
      this.fps = this.frames * 1000 / (now - this.fpsT0);
      this.frames = 0; this.fpsT0 = now;
    }
    const s = this.series;
    if (!s) return;
    const [t0, t1] = this.currentView();
    const i0 = Math.max(0, s.indexAt(t0)), i1 = s.indexAt(t1);
    this.canvases.forEach((c, j) => this._drawOne(c, this.groups[j], t0, t1, i0, i1));
    this.drawMs += performance.now() - now;  // the plots' own share of each frame
  }
  _drawOne(c, group, t0, t1, i0, i1) {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(10, c.clientWidth), h = Math.max(10, c.clientHeight);
    if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) {
      c.width = Math.round(w * dpr); c.height = Math.round(h * dpr);
    }
    const g = c.getContext('2d');
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, w, h);
    const s = this.series, t = s.t;
    const L = 52, R = 6, T = 16, B = 14, pw = w - L - R, ph = h - T - B;
    // y range over the visible samples, widened to at least the group's least span.
    let lo = Infinity, hi = -Infinity;
    for (const k of group) {
      const v = s.v[k];
      for (let i = i0; i <= i1; i++) { const y = v[i]; if (y < lo) lo = y; if (y > hi) hi = y; }
    }
    const ax = niceAxis(lo, hi, Math.max(...group.map((k) => leastSpan(s.scales[k]))));
    this.axes[this.canvases.indexOf(c)] = ax;
    lo = ax.lo; hi = ax.hi;
    const X = (x) => L + (x - t0) / (t1 - t0) * pw;
    const Y = (y) => T + (hi - y) / (hi - lo) * ph;
    g.strokeStyle = '#e3e6ea'; g.fillStyle = '#666'; g.font = '10px sans-serif';
    g.lineWidth = 1;
    for (let yv = lo; yv <= hi + ax.step * 1e-6; yv += ax.step) {
      const yy = Y(yv);
      g.beginPath(); g.moveTo(L, yy); g.lineTo(L + pw, yy); g.stroke();
      g.fillText(fmt(Math.abs(yv) < ax.step * 1e-6 ? 0 : yv), 2, yy + 3);
    }
    g.fillText(fmt(t0) + ' s', L, h - 2);
    const tr = fmt(t1) + ' s';
    g.fillText(tr, L + pw - g.measureText(tr).width, h - 2);
    const labels = [];
    const ci = this.cursor !== null && this.cursor >= t0 && this.cursor <= t1 ? s.indexAt(this.cursor) : -1;
    if (ci >= 0) {
      const cx = X(this.cursor);
      g.strokeStyle = '#999'; g.beginPath(); g.moveTo(cx, T); g.lineTo(cx, T + ph); g.stroke();
    }
    group.forEach((k, n) => {
      const v = s.v[k], color = n === 0 ? COLORS[group[0] % COLORS.length] : '#777';
      this._trace(g, t, v, i0, i1, X, Y, L, color, n > 0);
      const at = ci >= 0 ? ci : i1;
      const unit = s.units[k] ? ' ' + s.units[k] : '';
      labels.push([s.names[k] + (at >= 0 ? ' = ' + fmt(v[at]) : '') + unit, color]);
    });
    g.font = '11px sans-serif';
    let lx = L;
    for (const [text, color] of labels) {
      g.fillStyle = color; g.fillText(text, lx, 11); lx += g.measureText(text).width + 14;
    }
  }
  _trace(g, t, v, i0, i1, X, Y, L, color, dashed) {
    // One vertical min/max segment per pixel column: cost bounded by the width.
    g.setLineDash(dashed ? [4, 3] : []);
    g.strokeStyle = color; g.beginPath();
    let col = -1, mn = 0, mx = 0, first = true;
    const flush = () => {
      if (col < 0) return;
      const x = L + col + 0.5;
      if (first) { g.moveTo(x, Y(mn)); first = false; } else g.lineTo(x, Y(mn));
      g.lineTo(x, Y(mx));
    };
    for (let i = i0; i <= i1 && i < t.length; i++) {
      const cx = Math.floor(X(t[i]) - L);
      if (cx !== col) { flush(); col = cx; mn = mx = v[i]; } else {
        if (v[i] < mn) mn = v[i]; if (v[i] > mx) mx = v[i];
      }
    }
    flush(); g.stroke();
    g.setLineDash([]);
  }
}

const COLORS = ['#1565c0', '#c62828', '#2e7d32', '#6a1b9a', '#ef6c00', '#00838f', '#4e342e',
  '#ad1457'];

// The least span a chart shows: 2 % of one per-unit step of a signal sent in
// Q24 per unit (2^24 counts), one count of an integer-coded one (scale 1: the
// vector, the state, ...). A flat or quiet signal then gets an axis of its
// own size, not one that magnifies its last bit (or +-1e-9 around zero).
function leastSpan(scale) {
  const s = Math.abs(scale);
  if (!(s > 0) || s === 1) return 1;
  return 0.02 * s * 16777216;
}

// An axis over [lo, hi] at least minSpan wide, centred on the data when it is
// narrower, with a 5 % margin, at round ticks (1, 2, 2.5 or 5 x 10^n) and
// about four steps: {lo, hi, step}. No data (lo > hi): around 0.
function niceAxis(lo, hi, minSpan) {
  if (!(lo <= hi)) { lo = 0; hi = 0; }
  if (hi - lo < minSpan) { const mid = (lo + hi) / 2; lo = mid - minSpan / 2; hi = mid + minSpan / 2; }
  const margin = (hi - lo) * 0.05;
  lo -= margin; hi += margin;
  const raw = (hi - lo) / 4;
  const mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((x) => x >= raw * (1 - 1e-9));
  return { lo: Math.floor(lo / step) * step, hi: Math.ceil(hi / step) * step, step };
}

function fmt(x) {
  if (!isFinite(x)) return String(x);
  const a = Math.abs(x);
  if (a !== 0 && (a >= 1e5 || a < 1e-3)) return x.toExponential(2);
  return Number(x.toPrecision(4)).toString();
}
