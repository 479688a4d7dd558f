// The live console page (served by tools/console --web, tools/console_web.py).
// Everything the page knows is in `S` (also window.consoleState, which the
// browser test reads): the firmware's status, the telemetry series as plotted,
// the replies. Commands go to the server as lines; the server owns the link.
'use strict';

const $ = (id) => document.getElementById(id);
const TOKEN = new URLSearchParams(location.search).get('token') || '';
const HEARTBEAT_MS = 250;
const KEEP_S = 120;           // firmware seconds of telemetry kept for the plots
const DEFAULT_SIGNALS = ['speed', 'speed_ref', 'torque', 'torque_ref', 'i_d', 'i_q'];
// Streamed too in sensorless mode (est.sensorless > 0) where the image has them
// (`tel list`): the sensorless start's state and the injection's angle error.
const SENSORLESS_SIGNALS = ['sl_state', 'angle_err'];
// Signals the page shows in other units than the firmware's SI ones.
const DISPLAY = { angle_err: { unit: 'deg', k: 180 / Math.PI } };  // electrical degrees

const S = {
  ws: null, connected: false, role: null, page: null, gone: null, target: '',
  status: {}, counters: { frames: 0, bad: 0, lost: 0 }, meta: null, signals: [],
  ctrls: [], replies: [], autostarted: false,
  recording: null, history: [], histPos: 0,
};
window.consoleState = S;

// Extension points for the page's other scripts (params.js, firmware.js, and
// any later view): replyHooks get every command reply, msgHooks[type] every
// server message of that type, renderHooks run after each render.
const replyHooks = [];
const msgHooks = {};
const renderHooks = [];
window.pmsm = {
  S, $, command: (l, o) => command(l, o), log: (t, c) => log(t, c), send: (m) => send(m),
  confirmThen: (t, a) => confirmThen(t, a), listLines: (m) => listLines(m),
  onReply: (fn) => replyHooks.push(fn),
  onMessage: (type, fn) => { (msgHooks[type] = msgHooks[type] || []).push(fn); },
  onRender: (fn) => renderHooks.push(fn),
};

const charts = new StripCharts($('plotarea'), (t) => {
  const r = t === null ? null : charts.valuesAt(t);
  $('cursor').textContent = r ? 't = ' + fmt(r.t) + ' s' : '';
});
S.charts = charts;

// ---------------------------------------------------------------- log
function log(text, cls) {
  const el = $('log');
  const line = document.createElement('div');
  if (cls) line.className = cls;
  line.textContent = text;
  el.appendChild(line);
  while (el.childNodes.length > 2000) el.removeChild(el.firstChild);
  el.scrollTop = el.scrollHeight;
}

// ---------------------------------------------------------------- link to the server
function connect() {
  const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
  const ws = new WebSocket(proto + '//' + location.host + '/ws?token=' + encodeURIComponent(TOKEN));
  S.ws = ws;
  ws.onopen = () => { S.connected = true; render(); };
  ws.onclose = () => {
    S.connected = false; S.role = null; render();
    log('console: connection to the console server lost', 'err');
  };
  ws.onmessage = (e) => onMessage(JSON.parse(e.data));
  setInterval(() => send({ type: 'heartbeat' }), HEARTBEAT_MS);
}

function send(m) {
  if (S.ws && S.ws.readyState === WebSocket.OPEN) S.ws.send(JSON.stringify(m));
}

// Energising commands are confirmed by the user in a dialog first.
const ENERGISING = /^(arm\b|ident (run|resume|step|cogging)\b|bringup (?!status\b)\S)/;

function command(line, opts) {
  line = line.trim();
  if (!line) return;
  if (ENERGISING.test(line) && !(opts && opts.confirmed)) {
    confirmThen('"' + line + '" puts voltage on the motor. Is the motor free to turn and the ' +
      'supply current-limited?', () => command(line, { confirmed: true }));
    return;
  }
  send({ type: 'cmd', line: line, confirm: !!(opts && opts.confirmed) });
  if (!(opts && opts.quiet)) log('> ' + line, 'sent');
}

function confirmThen(text, action) {
  $('modal-text').textContent = text;
  $('modal').classList.remove('hidden');
  $('modal-ok').onclick = () => { $('modal').classList.add('hidden'); action(); };
  $('modal-cancel').onclick = () => { $('modal').classList.add('hidden'); };
}

function onMessage(m) {
  switch (m.type) {
    case 'hello':
      S.target = m.target; S.pageTimeout = m.page_timeout_s; S.targetPid = m.target_pid;
      if (m.status) S.status = m.status;
      if (m.meta) onMeta(m.meta);
      if (m.gone) onGone(m.gone);
      command('tel list', { quiet: true }); command('ctrl list', { quiet: true });
      command('param list', { quiet: true });
      break;
    case 'role':
      S.role = m.role; S.page = m.page; S.pages = m.pages;
      break;
    case 'status':
      S.status = m.status; S.counters = m.counters;
      maybeAutostart();
      break;
    case 'meta': onMeta(m); break;
    case 'samples':
      S.counters = m.counters;
      toDisplay(m.rows);
      lastSensorless(m.rows);
      if (charts.series) charts.series.push(m.rows);
      if (S.recording) for (const r of m.rows) S.recording.rows.push(r);
      break;
    case 'reply': onReply(m); break;
    case 'refused': log('refused: ' + (m.line ? m.line + ': ' : '') + m.why, 'err'); break;
    case 'text': log(m.line, 'info'); break;
    case 'gone': onGone(m.reason); break;
  }
  for (const fn of msgHooks[m.type] || []) fn(m);
  render();
}

function onGone(reason) {
  S.gone = reason;
  $('gone').textContent = 'target gone: ' + reason + ' — restart the console to reconnect';
  $('gone').classList.remove('hidden');
}

function onMeta(m) {
  // The page's units (DISPLAY): the samples are converted as they arrive, so the
  // plots, the cursor, the recordings and their CSV all say the same.
  const d = m.signals.map((n) => DISPLAY[n] || null);
  S.meta = Object.assign({}, m, {
    units: m.units.map((u, i) => (d[i] ? d[i].unit : u)),
    scales: m.scales.map((sc, i) => (d[i] ? sc * d[i].k : sc)),
  });
  S.displayK = d.some((x) => x) ? d.map((x) => (x ? x.k : 1)) : null;
  charts.setSeries(new Series(m.signals, S.meta.units, KEEP_S, S.meta.scales));
}

// The sensorless start's state of the last sample (telemetry sl_state, firmware/PROTOCOL.md):
// bits 0-1 the angle's source, 2-4 the start's phase, 5-6 where the polarity came from.
const SL_MODE = ['forced angle', 'observer', 'initial-angle pulses', 'injection'];
const SL_PHASE = ['', 'angle mod π', 'polarity pulse', 'angle mod π again', 'lock',
  'saturation pulses'];
const SL_POL = ['polarity not yet known', 'polarity from saturation', 'polarity from motion'];

function lastSensorless(rows) {
  const k = S.meta ? S.meta.signals.indexOf('sl_state') : -1;
  if (k < 0 || !rows.length) return;
  const v = rows[rows.length - 1][k + 1] | 0;
  const phase = (v >> 2) & 7;
  S.sl = { value: v, mode: SL_MODE[v & 3], phase: SL_PHASE[phase] === undefined ? 'phase ' + phase
    : SL_PHASE[phase], pol: SL_POL[(v >> 5) & 3] || 'polarity source ' + ((v >> 5) & 3),
  t: rows[rows.length - 1][0] };
}

// Shown only while the gates are on in sensorless mode (est.sensorless > 0, from the
// parameter tree) and sl_state streams: never a stopped drive's last state.
function sensorlessText() {
  const st = S.status.state;
  const p = (S.params || []).find((x) => x.name === 'est.sensorless');
  if (!S.sl || !p || !(+p.value > 0) || (st !== 'running' && st !== 'commission')) return null;
  if (!S.meta || S.meta.signals.indexOf('sl_state') < 0) return null;
  return 'sensorless: ' + S.sl.mode + (S.sl.phase ? ' · ' + S.sl.phase : '') + ' · ' + S.sl.pol;
}

function toDisplay(rows) {
  const K = S.displayK;
  if (!K) return rows;
  for (const r of rows) for (let i = 0; i < K.length; i++) r[i + 1] *= K[i];
  return rows;
}

function maybeAutostart() {
  // The controlling page starts a default stream once the target is past its
  // calibration and streams nothing; any page can change it afterwards.
  const st = S.status.state;
  if (S.autostarted || S.role !== 'control' || !st || st === 'boot' || st === 'calib') return;
  if (!S.signals.length) return;  // `tel list` not answered yet: what the image streams
  S.autostarted = true;
  if ((S.status.tel_mask || '').startsWith('0x00000000')) telStart();
}

function listLines(m) { return m.lines.slice(1).map((l) => l.replace(/^ {2}/, '')); }

function onReply(m) {
  const first = m.lines[0] || '';
  const mine = m.origin === 'page' + S.page;
  if (m.origin !== 'poll' && mine && !QUIET.has(m.line) && !/^param get /.test(m.line)) {
    for (const l of m.lines) log(l, m.ok ? '' : 'err');
  } else if (m.origin !== 'poll' && !mine && m.origin !== 'page-loss') {
    log('[' + m.origin + '] > ' + m.line + '  → ' + first, m.ok ? 'info' : 'err');
  }
  S.replies.push({ line: m.line, ok: m.ok, lines: m.lines, origin: m.origin });
  if (S.replies.length > 200) S.replies.shift();
  for (const fn of replyHooks) fn(m);
  if (!m.ok) return;
  const w = m.line.split(/\s+/);
  if (m.line === 'param list') addSensorlessSignals();
  if (m.line === 'tel list') {
    S.signals = listLines(m).map((l) => {
      const p = l.trim().split(/\s+/);
      return { bit: +p[0], name: p[1], unit: p[2] === '-' ? '' : p[2] };
    });
    buildSignals();
  } else if (m.line === 'ctrl list') {
    S.ctrls = listLines(m).map((l) => { const p = l.trim().split(/\s+/); return { sel: p[0] === '*', name: p[1] }; });
    buildCtrls();
  } else if ((w[0] === 'ctrl' && w[1] === 'select') || m.line === 'ident apply') {
    command('ctrl list', { quiet: true });
  }
}

// Replies the page asks for itself: not echoed in the command log.
const QUIET = new Set(['tel list', 'ctrl list', 'param list', 'ident result', 'cogging status']);

// ---------------------------------------------------------------- building the panels
function buildSignals() {
  const box = $('signals');
  box.textContent = '';
  const active = S.meta ? S.meta.signals : defaultSignals();
  for (const s of S.signals) {
    const lab = document.createElement('label');
    const cb = document.createElement('input');
    cb.type = 'checkbox'; cb.value = s.name; cb.checked = active.includes(s.name);
    lab.appendChild(cb);
    const unit = DISPLAY[s.name] ? DISPLAY[s.name].unit : s.unit;
    lab.appendChild(document.createTextNode(' ' + s.name + (unit ? ' (' + unit + ')' : '')));
    box.appendChild(lab);
  }
}

function buildCtrls() {
  const sel = $('ctrl');
  sel.textContent = '';
  for (const c of S.ctrls) {
    const o = document.createElement('option');
    o.value = o.textContent = c.name; o.selected = c.sel;
    sel.appendChild(o);
  }
}

function sensorlessOn() {
  const p = (S.params || []).find((x) => x.name === 'est.sensorless');
  return !!p && +p.value > 0;
}

// The default stream, and in sensorless mode the sensorless signals the image has.
function defaultSignals() {
  const have = new Set(S.signals.map((x) => x.name));
  return DEFAULT_SIGNALS.concat(sensorlessOn() ? SENSORLESS_SIGNALS.filter((n) => have.has(n)) : []);
}

function telStart() {
  const names = [...document.querySelectorAll('#signals input:checked')].map((c) => c.value);
  const use = names.length ? names : defaultSignals();
  command('tel start ' + use.join(' ') + ' every ' + $('every').value.trim());
}

// Once the drive is sensorless (the parameter tree read again after a change, or
// at the start), a running stream gets the sensorless signals it lacks.
function addSensorlessSignals() {
  if (S.role !== 'control' || !S.meta || !sensorlessOn()) return;
  const have = new Set(S.signals.map((x) => x.name));
  const missing = SENSORLESS_SIGNALS.filter((n) => have.has(n) && !S.meta.signals.includes(n));
  if (!missing.length) return;
  command('tel start ' + S.meta.signals.concat(missing).join(' ') + ' every ' + S.meta.every);
  for (const cb of document.querySelectorAll('#signals input')) {
    if (missing.includes(cb.value)) cb.checked = true;
  }
}

// ---------------------------------------------------------------- header and readouts
function render() {
  const st = S.status;
  $('target').textContent = S.target || '—';
  const link = $('link');
  link.textContent = S.gone ? 'target gone' : S.connected ? 'connected' : 'disconnected';
  link.className = 'chip ' + (S.gone || !S.connected ? 'bad' : 'ok');
  $('st-state').textContent = st.state || '—';
  $('st-ctrl').textContent = st.ctrl || '—';
  $('st-mode').textContent = st.mode || '—';
  const fault = st.fault || '';
  const f = $('st-fault');
  f.textContent = 'fault ' + (fault || '—');
  f.className = 'chip ' + (fault && !fault.startsWith('0') ? 'bad' : '');
  const warns = Object.keys(st).filter((k) => k.startsWith('warn')).map((k) => k + '=' + st[k])
    .filter((s) => !/=(0|none)$/.test(s));
  const sl = sensorlessText();
  $('st-sl').textContent = sl || '';
  $('st-sl').className = 'chip' + (sl ? (S.sl.value & 3) === 3 ? ' ok' : '' : ' hidden');
  $('st-warn').textContent = warns.join(' ');
  $('st-warn').className = 'chip warn' + (warns.length ? '' : ' hidden');
  $('st-speed').textContent = st.speed_rpm || '—';
  $('st-speedref').textContent = st.speed_ref_rpm || '—';
  $('st-torque').textContent = st.torque_nm || '—';
  // status's torque_ref_nm is the last controlled period's reference: with the
  // gates off (after a run or a calibration) it would be a stale number.
  const gatesOn = st.state === 'running' || st.state === 'commission';
  $('st-torqueref').textContent = gatesOn ? st.torque_ref_nm || '—' : '—';
  $('c-frames').textContent = S.counters.frames;
  $('c-lost').textContent = S.counters.lost;
  $('c-bad').textContent = S.counters.bad;
  const role = $('role');
  role.textContent = S.role === 'control' ? 'controlling' : S.role === 'watch' ? 'watching' : '—';
  role.className = 'chip ' + (S.role === 'control' ? 'ok' : '');
  $('take').classList.toggle('hidden', S.role !== 'watch');
  $('rec-info').textContent = S.recording ? S.recording.rows.length + ' samples' : '';
  for (const fn of renderHooks) fn();
}

function frame() {
  charts.draw();
  $('c-fps').textContent = charts.fps.toFixed(0);
  requestAnimationFrame(frame);
}

// ---------------------------------------------------------------- files
function download(name, blob) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob); a.download = name;
  document.body.appendChild(a); a.click(); a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

function csvText(rec) {
  const head = ['time_s'].concat(rec.names.map((n, k) => n + (rec.units[k] ? ' (' + rec.units[k] + ')' : '')));
  return head.join(',') + '\n' + rec.rows.map((r) => r.map((x) => Number(x.toPrecision(9))).join(',')).join('\n') + '\n';
}

function plotPng(cb) {
  const cs = charts.canvases;
  if (!cs.length) return;
  const w = cs[0].width, h = cs.reduce((a, c) => a + c.height, 0);
  const out = document.createElement('canvas');
  out.width = w; out.height = h;
  const g = out.getContext('2d');
  g.fillStyle = '#fff'; g.fillRect(0, 0, w, h);
  let y = 0;
  for (const c of cs) { g.drawImage(c, 0, y); y += c.height; }
  out.toBlob(cb, 'image/png');
}

// ---------------------------------------------------------------- wiring
function wire() {
  $('stop').onclick = () => { send({ type: 'stop' }); log('STOP', 'sent'); };
  $('take').onclick = () => send({ type: 'take_control' });
  $('arm').onclick = () => command('arm');
  $('disarm').onclick = () => command('disarm');
  $('fault-clear').onclick = () => command('fault clear');
  $('ctrl-set').onclick = () => command('ctrl select ' + $('ctrl').value);
  $('ref-set').onclick = () => command('ref ' + $('mode').value + ' ' + $('ref').value.trim());
  $('tel-start').onclick = telStart;
  $('tel-stop').onclick = () => command('tel stop');
  $('win').onchange = () => { const v = +$('win').value; if (v > 0) charts.windowS = v; };
  $('pause').onclick = () => charts.pause();
  $('live').onclick = () => charts.goLive();
  $('rec').onclick = () => {
    if (S.recording) { S.recording.stopped = true; S.lastRecording = S.recording; S.recording = null; $('rec').textContent = 'record'; } else if (S.meta) {
      S.recording = { names: S.meta.signals, units: S.meta.units, rows: [] };
      $('rec').textContent = 'stop recording';
    }
    render();
  };
  $('csv').onclick = () => {
    const rec = S.recording || S.lastRecording;
    if (rec) download('pmsm-telemetry.csv', new Blob([csvText(rec)], { type: 'text/csv' }));
  };
  $('png').onclick = () => plotPng((b) => download('pmsm-plot.png', b));
  for (const b of document.querySelectorAll('.tabs button')) {
    b.onclick = () => {
      for (const x of document.querySelectorAll('.tabs button')) x.classList.toggle('on', x === b);
      for (const t of document.querySelectorAll('.tab')) t.classList.toggle('hidden', t.id !== b.dataset.tab);
    };
  }
  const cmd = $('cmd');
  cmd.addEventListener('keydown', (e) => {
    if (e.key === 'Enter') {
      const line = cmd.value.trim();
      if (line) { S.history.push(line); S.histPos = S.history.length; command(line); }
      cmd.value = '';
    } else if (e.key === 'ArrowUp' && S.histPos > 0) {
      cmd.value = S.history[--S.histPos]; e.preventDefault();
    } else if (e.key === 'ArrowDown') {
      S.histPos = Math.min(S.history.length, S.histPos + 1);
      cmd.value = S.history[S.histPos] || ''; e.preventDefault();
    }
  });
}

// After every script of the page has registered its hooks (they are deferred).
document.addEventListener('DOMContentLoaded', () => {
  wire();
  connect();
  requestAnimationFrame(frame);
});
