// The firmware page: flash a connected board through tools/flash (the server
// runs it; this page asks, confirms and shows its phases, its output and its
// verdict). The server sends what it would write (image, command, or why it
// cannot) with its hello and on request.
'use strict';

(() => {
  const P = window.pmsm;
  const { S, $ } = P;
  S.flash = { info: null, running: false, pct: 0, phase: '', lines: [], done: false, ok: null,
    verdict: '' };

  function showInfo(info) {
    S.flash.info = info;
    const sel = $('fw-board');
    const boards = (info && info.boards) || [];
    if (sel.dataset.boards !== boards.join(' ')) {
      sel.dataset.boards = boards.join(' ');
      sel.textContent = '';
      for (const b of boards) {
        const o = document.createElement('option');
        o.value = o.textContent = b;
        sel.appendChild(o);
      }
    }
    if (info && info.board) sel.value = info.board;
    const img = info && info.image;
    let t = img ? img : '(no image)';
    if (img && info.bytes !== null) {
      t += ' · ' + info.bytes + ' bytes · built ' + new Date(info.mtime * 1000).toLocaleString();
    } else if (img) t += ' · not built yet';
    $('fw-image').textContent = t;
    const c = $('fw-cmd');
    c.textContent = info && info.command ? 'runs: ' + info.command
      : info && info.problem ? info.problem : '';
    c.className = 'readout ' + (info && info.problem ? 'errtext' : 'hint');
  }

  function draw() {
    const f = S.flash;
    $('fw-bar').style.width = f.pct + '%';
    $('fw-bar').className = f.done ? (f.ok ? 'ok' : 'bad') : '';
    const v = $('fw-verdict');
    v.textContent = f.done ? (f.ok ? 'written and verified' : 'failed: ' + f.verdict)
      : f.running ? (f.phase || 'starting') + ' · ' + f.pct + ' %' : '';
    v.className = 'readout ' + (f.done ? (f.ok ? 'oktext' : 'errtext') : '');
    $('fw-log').textContent = f.lines.join('\n');
    $('fw-flash').disabled = f.running || S.role !== 'control';
    $('fw-board').disabled = f.running || S.role !== 'control';
  }

  P.onMessage('hello', (m) => { if (m.flash) showInfo(m.flash); });
  P.onMessage('flash_info', (m) => showInfo(m.info));
  P.onMessage('flash', (m) => {
    const f = S.flash;
    if (m.start) {
      Object.assign(f, { running: true, pct: 0, phase: '', lines: [], done: false, ok: null,
        verdict: '' });
      if (m.info) showInfo(m.info);
      P.log('firmware: flashing (page ' + m.page + ')', 'info');
    }
    if (m.line) {
      f.lines.push(m.line);
      if (f.lines.length > 400) f.lines.shift();
    }
    if (m.phase) f.phase = m.phase;
    if (typeof m.pct === 'number') f.pct = m.pct;
    if (m.done) {
      Object.assign(f, { running: false, done: true, ok: m.ok, verdict: m.verdict, rc: m.rc });
      P.log('firmware: ' + (m.ok ? 'written and verified' : 'flash failed: ' + m.verdict),
        m.ok ? 'info' : 'err');
    }
    draw();
  });
  P.onMessage('refused', (m) => {
    if (m.line === 'flash') { S.flash.verdict = m.why; draw(); }
  });
  P.onRender(draw);

  document.addEventListener('DOMContentLoaded', () => {
    const board = () => $('fw-board').value;
    $('fw-board').onchange = () => P.send({ type: 'flash_info', board: board() });
    $('fw-refresh').onclick = () => P.send({ type: 'flash_info', board: board() });
    $('fw-flash').onclick = () => {
      const img = S.flash.info && S.flash.info.image ? S.flash.info.image : 'the image';
      const b = board();
      P.confirmThen('Flash ' + img + ' onto the ' + b + ' on the ST-LINK? The drive is ' +
        'stopped first and the board restarts with the new firmware.',
      () => P.send({ type: 'flash', confirm: true, board: b }));
    };
  });
})();
