// The leaderboard page: a sortable table of score reports whose receipts name the same
// ground truth. data/leaderboard.js calls NSG.receive("leaderboard", doc) (browsers refuse
// fetch() from file://). Every string from the reports is set as text, never as HTML.
// #sort=<column>[:asc|desc] sorts; #selftest=sort:<column> writes the row order into
// <pre id="selftest"> for headless checks.
'use strict';
const NSG = (() => {
  let doc = null;
  const errors = [];
  window.addEventListener('error', (e) => errors.push(String(e.message)));

  function params() {
    const out = {};
    for (const part of location.hash.replace(/^#/, '').split('&'))
      if (part) { const [k, v] = part.split('='); out[decodeURIComponent(k)] = decodeURIComponent(v || ''); }
    return out;
  }
  const column = (name) => doc.columns.find((c) => c.name === name);

  // Better first (higher or lower by the column), undefined last, ties by name.
  function order(sort, dir) {
    const col = column(sort) || column(doc.columns[0].name);
    const sign = (dir || (col.better === 'lower' ? 'asc' : 'desc')) === 'asc' ? 1 : -1;
    const idx = doc.entries.map((_, i) => i);
    idx.sort((a, b) => {
      const x = doc.entries[a].values[col.name], y = doc.entries[b].values[col.name];
      const xn = x === null || x === undefined, yn = y === null || y === undefined;
      if (xn !== yn) return xn ? 1 : -1;
      if (!xn && x !== y) return sign * (x < y ? -1 : 1);
      const na = doc.entries[a].name, nb = doc.entries[b].name;
      return na < nb ? -1 : na > nb ? 1 : 0;
    });
    return { col, idx };
  }

  function cell(tr, text, cls) {
    const td = document.createElement('td');
    td.textContent = text;
    if (cls) td.className = cls;
    tr.appendChild(td);
  }
  const shown = (v, digits) => (v === null || v === undefined ? '—' : Number(v).toFixed(digits));

  function render() {
    const p = params();
    const [sort, dir] = (p.sort || '').split(':');
    const { col, idx } = order(sort, dir);
    const head = document.querySelector('#board thead'), body = document.querySelector('#board tbody');
    head.textContent = '';
    body.textContent = '';
    const hr = document.createElement('tr');
    const th = (text, cls, onclick, title) => {
      const h = document.createElement('th');
      h.textContent = text;
      if (cls) h.className = cls;
      if (title) h.title = title;
      if (onclick) h.addEventListener('click', onclick);
      hr.appendChild(h);
    };
    th('#', null);
    th('submission', 'name');
    for (const c of doc.columns)
      th(c.label + (c.better === 'lower' ? ' ↓' : ' ↑'), c.name === col.name ? 'sorted' : null,
         () => { location.hash = 'sort=' + encodeURIComponent(c.name); }, c.name);
    th('tiles', null);
    th('missing', null);
    th('submission sha256', 'name');
    th('toolkit', 'name');
    head.appendChild(hr);
    idx.forEach((i, rank) => {
      const e = doc.entries[i];
      const tr = document.createElement('tr');
      tr.className = 'row';
      tr.dataset.name = e.name;
      cell(tr, String(rank + 1));
      cell(tr, e.name, 'name');
      for (const c of doc.columns) cell(tr, shown(e.values[c.name], c.digits));
      cell(tr, String(e.n_tiles));
      cell(tr, String(e.n_missing_predictions));
      cell(tr, e.submission_sha256.slice(0, 12), 'digest');
      cell(tr, e.toolkit, 'name');
      body.appendChild(tr);
    });
    return col.name;
  }

  function start() {
    if (!doc) { errors.push('data/leaderboard.js did not load'); return; }
    const gt = doc.ground_truth;
    document.getElementById('about').textContent =
        doc.entries.length + ' submission(s) scored on ' + gt.kind + ' ' + (gt.manifest_sha256 || gt.sha256 || '').slice(0, 12) +
        (gt.split ? ', split ' + gt.split : '') + ' (metrics v' + doc.metrics_version + ', ' + doc.tool + ')';
    const list = document.getElementById('rejected');
    for (const r of doc.rejected) {
      const li = document.createElement('li');
      li.textContent = r.file + ': ' + r.reason;
      list.appendChild(li);
    }
    document.getElementById('rejected-section').hidden = doc.rejected.length === 0;
    window.addEventListener('hashchange', render);
    render();
    const spec = params().selftest;
    if (spec) {
      const out = { errors };
      try {
        const [, col, dir] = spec.split(':');
        location.hash = 'sort=' + col + (dir ? ':' + dir : '');
        out.sorted_by = render();
        out.rows = Array.from(document.querySelectorAll('#board tr.row')).map((r) => r.dataset.name);
        out.columns = document.querySelectorAll('#board th').length;
        out.rejected = document.querySelectorAll('#rejected li').length;
      } catch (e) {
        errors.push('selftest: ' + (e && e.stack || e));
      }
      const pre = document.getElementById('selftest');
      pre.textContent = JSON.stringify(out);
      pre.dataset.done = '1';
    }
  }

  window.addEventListener('DOMContentLoaded', start);
  return { receive(name, data) { if (name === 'leaderboard') doc = data; } };
})();
