// The parameter tree (the page's "parameters" tab): everything `param list`
// gives - the selected controller's tunables and the firmware's own
// parameters - grouped by the prefix of their names, with unit, range, help
// text and whether the firmware changes them while the drive runs.
// The firmware is the only source: nothing here knows a parameter, its range
// or its unit; only the groups' titles are the page's (a prefix it does not
// know shows as itself).
'use strict';

(() => {
  const P = window.pmsm;
  const { S, $ } = P;
  S.params = [];      // [{name, value, unit, min, max, range, ro, live, help}] in listing order
  S.paramMsg = {};    // name -> {ok, text}: the firmware's answer to the last set

  // Titles of the firmware's groups (firmware/PROTOCOL.md, "Parameters").
  const GROUPS = {
    m: 'machine', enc: 'encoder', inv: 'inverter', est: 'estimation', speed: 'speed loop',
    lim: 'limits', prot: 'protections', throttle: 'throttle', thr: 'throttle', b: 'board',
    hfi: 'high-frequency injection (sensorless at standstill: est.sensorless 2)',
  };
  const CTRL_GROUP = '';  // names without a dot: the selected controller's tunables

  // `  <name> <value> <unit|-> [<min>, <max>][ ro| live] <help>`
  function parseParam(l) {
    const m = /^\s*(\S+) (\S+) (\S+) \[([^,\]]*), ([^\]]*)\](?: (ro|live)(?= |$))? ?(.*)$/.exec(l);
    if (!m) return null;
    return {
      name: m[1], value: m[2], unit: m[3] === '-' ? '' : m[3], min: m[4], max: m[5],
      range: m[6] === 'ro' ? '' : '[' + m[4] + ', ' + m[5] + ']', ro: m[6] === 'ro',
      live: m[6] === 'live', help: m[7].trim(),
    };
  }

  function groupOf(name) {
    const dot = name.indexOf('.');
    return dot < 0 ? CTRL_GROUP : name.slice(0, dot);
  }

  function groupTitle(g) {
    if (g === CTRL_GROUP) return 'controller ' + (S.status.ctrl || '') + ' (tunables)';
    return GROUPS[g] || g;
  }

  function running() { return S.status.armed === '1' || S.status.state === 'commission'; }

  function setParam(p, inp) {
    const v = inp.value.trim();
    if (!v) return;
    delete inp.dataset.edited; // sent: the firmware's answer decides what it shows
    P.command('param set ' + p.name + ' ' + v);
  }

  function row(p) {
    const tr = document.createElement('tr');
    tr.dataset.param = p.name;
    const name = document.createElement('td');
    name.className = 'pname';
    name.textContent = p.name;
    if (p.help) {
      const h = document.createElement('div');
      h.className = 'phelp';
      h.textContent = p.help;
      name.appendChild(h);
    }
    const val = document.createElement('td');
    const inp = document.createElement('input');
    inp.value = p.value;
    inp.disabled = p.ro || S.role !== 'control';
    inp.title = p.help || '';
    inp.addEventListener('keydown', (e) => { if (e.key === 'Enter') setParam(p, inp); });
    // Edited and not yet sent: a listing's value must not overwrite it.
    const edited = () => { inp.dataset.edited = '1'; };
    inp.addEventListener('input', edited);
    inp.addEventListener('change', edited);
    val.appendChild(inp);
    const unit = document.createElement('td');
    unit.textContent = p.unit;
    const range = document.createElement('td');
    range.textContent = p.range;
    const when = document.createElement('td');
    when.className = 'when ' + (p.ro ? 'ro' : p.live ? 'live' : 'off');
    when.textContent = p.ro ? 'read-only' : p.live ? 'live' : 'gates off';
    when.title = p.ro ? 'the firmware reports it; it cannot be set'
      : p.live ? 'changes while the drive runs (bumpless where the firmware says so)'
        : 'changes only with the gates off: refused while running';
    const msg = document.createElement('td');
    msg.className = 'msg';
    for (const td of [name, val, unit, range, when, msg]) tr.appendChild(td);
    return tr;
  }

  // The tree anew when the names change (another controller, another
  // firmware); otherwise the values in place, except in the box being edited.
  function build() {
    const tree = $('ptree');
    const names = S.params.map((p) => p.name).join(' ');
    if (tree.dataset.names === names && tree.dataset.role === S.role) {
      for (const p of S.params) {
        const inp = tree.querySelector('tr[data-param="' + CSS.escape(p.name) + '"] input');
        if (inp && document.activeElement !== inp && !inp.dataset.edited) inp.value = p.value;
      }
      return;
    }
    tree.dataset.names = names;
    tree.dataset.role = S.role;
    const open = {};
    for (const d of tree.querySelectorAll('details')) open[d.dataset.group] = d.open;
    tree.textContent = '';
    const order = [];
    for (const p of S.params) if (!order.includes(groupOf(p.name))) order.push(groupOf(p.name));
    for (const g of order) {
      const d = document.createElement('details');
      d.dataset.group = g;
      d.open = g in open ? open[g] : true;
      const sum = document.createElement('summary');
      const ps = S.params.filter((p) => groupOf(p.name) === g);
      sum.textContent = groupTitle(g) + ' · ' + ps.length;
      d.appendChild(sum);
      const t = document.createElement('table');
      t.className = 'params';
      const tb = document.createElement('tbody');
      for (const p of ps) tb.appendChild(row(p));
      t.appendChild(tb);
      d.appendChild(t);
      tree.appendChild(d);
    }
    for (const p of S.params) if (S.paramMsg[p.name]) mark(p.name);
    // An image built without help text (PMSM_HELP_TEXT=OFF, the B-G431B-ESC1's)
    // sends none: say where the descriptions are instead of showing blanks.
    const noHelp = S.params.length > 0 && S.params.every((p) => !p.help);
    S.noHelpText = noHelp;
    $('params-nohelp').classList.toggle('hidden', !noHelp);
  }

  function mark(name) {
    const m = S.paramMsg[name];
    const tr = document.querySelector('#ptree tr[data-param="' + CSS.escape(name) + '"]');
    if (!tr || !m) return;
    const td = tr.querySelector('td.msg');
    td.textContent = m.text;
    td.classList.toggle('err', !m.ok);
    td.classList.toggle('ok', m.ok);
  }

  // The firmware's value into the box (after a refusal: the box reverts).
  function showValue(name, value) {
    const p = S.params.find((x) => x.name === name);
    if (p) p.value = value;
    const inp = document.querySelector('#ptree tr[data-param="' + CSS.escape(name) + '"] input');
    if (inp) { inp.value = value; delete inp.dataset.edited; }
  }

  P.onReply((m) => {
    const w = m.line.split(/\s+/);
    const first = m.lines[0] || '';
    if (m.line === 'param list' && m.ok) {
      S.params = P.listLines(m).map(parseParam).filter((p) => p);
      build();
    } else if (w[0] === 'param' && w[1] === 'set' && w.length >= 3) {
      S.paramMsg[w[2]] = { ok: m.ok, text: first };
      mark(w[2]);
      if (m.ok) {
        // Others may follow from it (the machine re-initialises the tunables).
        P.command('param list', { quiet: true });
      } else {
        // Refused: the box shows the firmware's value again, the reason stays.
        P.command('param get ' + w[2], { quiet: true });
      }
    } else if (w[0] === 'param' && w[1] === 'get' && m.ok) {
      const r = first.split(/\s+/);  // ok NAME VALUE UNIT
      if (r.length >= 3) showValue(r[1], r[2]);
    } else if (m.ok && ((w[0] === 'ctrl' && w[1] === 'select') || m.line === 'ident apply' ||
               (w[0] === 'config' && w[1] === 'default'))) {
      P.command('param list', { quiet: true });
    }
  });

  P.onRender(() => {
    const tree = $('ptree');
    tree.classList.toggle('running', running());
    if (tree.dataset.role !== S.role) build();
    const ctrl = tree.querySelector('details[data-group=""] summary');
    if (ctrl && S.status.ctrl && !ctrl.textContent.includes(S.status.ctrl)) {
      ctrl.textContent = groupTitle(CTRL_GROUP) + ' · ' +
        S.params.filter((p) => groupOf(p.name) === CTRL_GROUP).length;
    }
  });

  document.addEventListener('DOMContentLoaded', () => {
    $('params-load').onclick = () => P.command('param list', { quiet: true });
  });
  P.parseParam = parseParam;  // for the browser test
})();
