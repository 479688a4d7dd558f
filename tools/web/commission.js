// The identification tab: identification, anti-cogging and bring-up, their
// progress and their results (firmware/PROTOCOL.md, "Commissioning").
// What it shows always belongs to the run it names: the results table is
// emptied when a run starts and filled from `ident result` once that run has
// ended; the feed-forward's state is asked again after everything that can
// change it; a ripple measurement that the drive's state or the
// feed-forward changed under is discarded, not shown.
'use strict';

(() => {
  const P = window.pmsm;
  const { S, $ } = P;
  const RIPPLE_S = 2;            // firmware seconds of speed a ripple measurement takes
  S.cm = null;                   // {which, verdict, step, progress, text}: the last status shown
  S.cmRun = null;                // {line, which}: the run started from here, until it ends
  S.cmStarts = 0;                // runs started (the firmware's ok to a start)
  S.results = null;              // {ended, rows: {key: {value, unit}}}: the last run's results
  S.cog = null;                  // 'on' | 'off' | 'none' (no table), null while unknown
  S.ripple = [];                 // [{mean, sd, n, ref, ctrl, cog} | {error}]
  S.rippleRun = null;

  const STARTS = /^(ident (run|resume|step|cogging)|bringup (?!status\b)\S)/;
  // Commands after which the feed-forward's state may differ (a new table,
  // a table dropped with a new encoder direction, another configuration).
  const MAY_CHANGE_COG = /^(ident apply|config (default|save)|param set (enc|m)\.|ctrl select)/;

  function setResultsNote(text) { $('cm-results-note').textContent = text; }

  function clearResults(why) {
    S.results = null;
    $('cm-results').tBodies[0].textContent = '';
    setResultsNote(why);
  }

  function onStatus(which, first) {
    // 'ok running step=rs progress=40% ...' / 'ok pass step=...' / 'ok fail step=... error=...'
    const w = first.split(/\s+/);
    const verdict = w[1] || '';
    const step = (first.match(/step=(\S+)/) || [])[1] || '';
    if (verdict === 'idle' && S.cm && S.cm.which !== which) return;
    const prog = +((first.match(/progress=([\d.]+)/) || [])[1] || (verdict === 'pass' ? 100 : 0));
    S.cm = { which, verdict, step, progress: prog, text: first.replace(/^ok\s+/, '') };
    $('cm-bar').style.width = Math.min(100, prog) + '%';
    $('cm-status').textContent = which.split(' ')[0] + ': ' + S.cm.text;
    $('cm-status').style.color = verdict === 'fail' ? '#b71c1c' : verdict === 'pass' ? '#2e7d32' : '';
    const run = S.cmRun;
    if (run && run.which === which && ['pass', 'fail', 'stopped'].includes(verdict)) {
      // The run ended: its results (what it measured, also after a failure),
      // and the feed-forward's state (a calibration leaves a new table).
      S.cmRun = null;
      // The anti-cogging step measures the table, not the motor: the
      // identification's results stay as they were, under their own run's name.
      if (which === 'ident status' && !run.line.startsWith('ident cogging')) {
        S.cmEnded = S.cm.text;
        P.command('ident result', { quiet: true });
      }
      P.command('cogging status', { quiet: true });
    }
  }

  function showResults(lines) {
    const tb = $('cm-results').tBodies[0];
    tb.textContent = '';
    const rows = {};
    for (const l of lines) {
      const p = l.trim().split(/\s+/);
      if (p.length < 2) continue;
      rows[p[0]] = { value: +p[1], text: p[1], unit: p[2] === '-' ? '' : (p[2] || '') };
      const tr = document.createElement('tr');
      tr.dataset.key = p[0];
      for (const c of [p[0], p[1], rows[p[0]].unit]) {
        const td = document.createElement('td'); td.textContent = c; tr.appendChild(td);
      }
      tb.appendChild(tr);
    }
    const running = S.cmRun !== null && !S.cmRun.line.startsWith('ident cogging');
    S.results = { ended: running ? null : (S.cmEnded || null), running, rows };
    setResultsNote(!lines.length ? 'nothing measured yet' : running
      ? 'measured so far (the identification is still running)'
      : 'measured by the identification that ended: ' + (S.cmEnded || 'before this page opened'));
  }

  // ---- speed ripple: the plotted speed's mean and standard deviation over
  // RIPPLE_S firmware seconds, in the conditions they were taken in.
  function rippleStart() {
    const s = S.charts.series;
    const k = s ? s.names.indexOf('speed') : -1;
    if (S.status.state !== 'running' || k < 0 || !s.t.length) {
      S.ripple.push({ error: S.status.state !== 'running' ? 'the drive is not running'
        : 'the telemetry does not stream speed' });
      renderRipple();
      return;
    }
    S.rippleRun = { t0: s.t[s.t.length - 1], k, cog: S.cog, ref: S.status.speed_ref_rpm,
      mode: S.status.mode, ctrl: S.status.ctrl };
    renderRipple();
  }

  function rippleCheck() {
    const r = S.rippleRun;
    if (!r) return;
    const s = S.charts.series;
    const st = S.status;
    let error = null;
    if (!s || s.names.indexOf('speed') !== r.k) error = 'the telemetry stream changed';
    else if (st.state !== 'running') error = 'the drive left the running state';
    else if (S.cog !== r.cog) error = 'the feed-forward changed';
    else if (st.speed_ref_rpm !== r.ref || st.mode !== r.mode || st.ctrl !== r.ctrl) {
      error = 'the reference or the controller changed';
    }
    if (error) {
      S.rippleRun = null;
      S.ripple.push({ error: error + ' during the measurement' });
      renderRipple();
      return;
    }
    if (s.t[s.t.length - 1] < r.t0 + RIPPLE_S) return;
    let n = 0, sum = 0, sum2 = 0;
    for (let i = s.indexAt(r.t0) + 1; i < s.t.length && s.t[i] <= r.t0 + RIPPLE_S; i++) {
      const v = s.v[r.k][i];
      n++; sum += v; sum2 += v * v;
    }
    S.rippleRun = null;
    if (n < 2) {
      S.ripple.push({ error: 'no speed samples in the window' });
    } else {
      const mean = sum / n;
      S.ripple.push({ mean, sd: Math.sqrt(Math.max(sum2 / n - mean * mean, 0)), n, ref: +r.ref,
        ctrl: r.ctrl, cog: r.cog || 'none' });
    }
    renderRipple();
  }

  function renderRipple() {
    const tb = $('ripple').tBodies[0];
    tb.textContent = '';
    for (const x of S.ripple.slice(-6)) {
      const tr = document.createElement('tr');
      const cells = x.error ? [x.error] : [x.mean.toFixed(2) + ' r/min', x.sd.toFixed(2) + ' r/min',
        'ref ' + x.ref + ', ' + x.ctrl + ', feed-forward ' + x.cog];
      for (const c of cells) {
        const td = document.createElement('td'); td.textContent = c; tr.appendChild(td);
      }
      if (x.error) { tr.firstChild.colSpan = 3; tr.firstChild.className = 'err'; }
      tb.appendChild(tr);
    }
    $('ripple-run').textContent = S.rippleRun ? 'measuring ' + RIPPLE_S + ' s…' : '';
  }

  P.onReply((m) => {
    const first = m.lines[0] || '';
    const w = m.line.split(/\s+/);
    if (m.ok && STARTS.test(m.line)) {
      const which = m.line.startsWith('bringup') ? 'bringup status' : 'ident status';
      S.cmRun = { line: m.line, which };
      S.cmStarts++;
      S.cmWhich = which;
      if (which === 'ident status' && !m.line.startsWith('ident cogging')) {
        clearResults('running: the results when it ends');
      }
      if (m.line.startsWith('ident cogging')) { S.cog = null; $('cog-status').textContent = 'calibrating…'; }
    }
    if (m.line === 'ident status' || m.line === 'bringup status') {
      // Both describe the one commissioning engine (the server polls both while
      // it runs): the page shows the one of what was started.
      if (m.ok && m.line === (S.cmWhich || 'ident status')) onStatus(m.line, first);
    } else if (m.line === 'ident result' && m.ok) {
      showResults(P.listLines(m));
    } else if (w[0] === 'cogging' && S.cmRun && S.cmRun.line.startsWith('ident cogging')) {
      // the table is being measured: the calibration's end asks again
    } else if (w[0] === 'cogging' && m.ok) {
      S.cog = first.replace(/^ok\s+(cogging\s+)?/, '').trim() || null;
      $('cog-status').textContent = 'feed-forward ' + S.cog + (S.cog === 'none' ? ' (no table)' : '');
    } else if (w[0] === 'cogging') {
      $('cog-status').textContent = first;
    }
    if (m.ok && MAY_CHANGE_COG.test(m.line)) {
      P.command('cogging status', { quiet: true });
    }
  });
  P.onMessage('hello', () => P.command('cogging status', { quiet: true }));
  P.onMessage('samples', rippleCheck);
  P.onMessage('status', rippleCheck);

  document.addEventListener('DOMContentLoaded', () => {
    for (const b of document.querySelectorAll('[data-cm]')) b.onclick = () => P.command(b.dataset.cm);
    $('cm-step-run').onclick = () => P.command('ident step ' + $('cm-step').value);
    $('bu-run').onclick = () => P.command('bringup ' + $('bu-step').value);
    $('ripple-measure').onclick = rippleStart;
    setResultsNote('nothing measured yet');
  });
})();
