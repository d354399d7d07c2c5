// nsgraph report page: plain JavaScript and SVG, no network. Data files are scripts that
// call NSG.receive(name, data) (browsers refuse fetch() from file://); per-tile data and
// images load only when a tile is opened, the per-tile table renders one page at a time.
'use strict';
(function () {
  const S = {
    summary: null, tiles: null, tileData: {}, waiting: {}, errors: [],
    order: null, orderKey: '', page: 0, pageSize: 100,
    t0: performance.now(), marks: {},
  };

  // Errors of scripts and of files that fail to load, for the page and its self-test.
  window.addEventListener('error', (e) => {
    const t = e.target;
    if (t && t !== window && (t.src || t.href)) S.errors.push('failed to load ' + (t.src || t.href));
    else S.errors.push(String(e.message || e.error || e));
  }, true);
  window.addEventListener('unhandledrejection', (e) => S.errors.push('unhandled rejection: ' + e.reason));
  const consoleError = console.error.bind(console);
  console.error = (...args) => { S.errors.push(args.join(' ')); consoleError(...args); };

  // ---------- data loading ----------
  const NSG = {
    receive(name, data) {
      if (name === 'summary') S.summary = data;
      else if (name === 'tiles') S.tiles = data;
      else if (name.startsWith('tile:')) S.tileData[name.slice(5)] = data;
      const w = S.waiting[name];
      if (w) { delete S.waiting[name]; w.resolve(data); }
      if (name === 'summary') start();
    },
  };
  window.NSG = NSG;

  function need(name, src) {
    if (name === 'tiles' && S.tiles) return Promise.resolve(S.tiles);
    if (name.startsWith('tile:') && S.tileData[name.slice(5)]) return Promise.resolve(S.tileData[name.slice(5)]);
    if (S.waiting[name]) return S.waiting[name].promise;
    const w = {};
    w.promise = new Promise((resolve, reject) => { w.resolve = resolve; w.reject = reject; });
    S.waiting[name] = w;
    const s = document.createElement('script');
    s.src = src;
    s.onerror = () => { delete S.waiting[name]; w.reject(new Error('cannot load ' + src)); };
    document.body.appendChild(s);
    return w.promise;
  }
  const needTiles = () => need('tiles', 'data/tiles.js');
  const needTile = (key) => need('tile:' + key, 'data/tile/' + encodeURIComponent(key) + '.js');

  // ---------- small helpers ----------
  const SVGNS = 'http://www.w3.org/2000/svg';
  function el(tag, attrs, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === 'text') e.textContent = v;
      else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
      else e.setAttribute(k, v);
    }
    for (const c of children) if (c != null) e.append(c);
    return e;
  }
  function sv(tag, attrs, ...children) {
    const e = document.createElementNS(SVGNS, tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === 'text') e.textContent = v;
      else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
      else e.setAttribute(k, v);
    }
    for (const c of children) if (c != null) e.append(c);
    return e;
  }
  function fmt(v) {
    if (v === null || v === undefined) return '—';
    if (Number.isInteger(v)) return String(v);
    const a = Math.abs(v);
    // Three significant digits below 0.001 (a small area in km² was 0.0000).
    return a >= 1000 ? v.toFixed(0) : a >= 10 ? v.toFixed(2) : a >= 0.001 || a === 0 ? v.toFixed(4) : v.toPrecision(3);
  }
  const cmpStr = (a, b) => (a < b ? -1 : a > b ? 1 : 0);  // byte order, like the C++ side
  // A baseline's or a difference's column is better low when its metric is.
  const lowerIsBetter = (col) => (S.summary.lower_is_better || []).includes(col.replace(/^(baseline|delta)\./, ''));
  // The graph overlays by name (gt, missed, pred, wrong_direction, unmatched, baseline): colour, label, dashed.
  const overlay = (name) => (S.summary.legends.overlay || []).find((o) => o.name === name) || { color: '#ff00ff', label: name };
  function params() {
    const p = new URLSearchParams(location.hash.slice(1));
    return Object.fromEntries(p.entries());
  }
  function go(changes) {
    const p = Object.assign(params(), changes);
    for (const k of Object.keys(p)) if (p[k] === undefined || p[k] === null || p[k] === '') delete p[k];
    location.hash = new URLSearchParams(p).toString();
  }
  function status(text) { document.getElementById('status').textContent = text; }

  // ---------- sort order of the per-tile table (shared by the tile view's prev/next) ----------
  function sortState() {
    const p = params();
    return { col: p.sort || 'key', dir: p.dir === 'desc' ? 'desc' : 'asc' };
  }
  // Rows ordered by the column; undefined values last whatever the direction; ties by key.
  function sortedOrder(col, dir) {
    const T = S.tiles, n = T.keys.length, idx = Array.from({ length: n }, (_, i) => i);
    const sign = dir === 'desc' ? -1 : 1;
    if (col === 'key') return idx.sort((a, b) => sign * cmpStr(T.keys[a], T.keys[b]));
    const vals = col === 'split' ? T.split : col === 'location' ? T.location : T.values[col];
    if (!vals) throw new Error('no column ' + col);
    return idx.sort((a, b) => {
      const x = vals[a], y = vals[b];
      if (x === null && y === null) return cmpStr(T.keys[a], T.keys[b]);
      if (x === null) return 1;
      if (y === null) return -1;
      if (x !== y) return sign * (x < y ? -1 : 1);
      return cmpStr(T.keys[a], T.keys[b]);
    });
  }
  function currentOrder() {
    const s = sortState(), id = s.col + ':' + s.dir;
    if (S.orderKey !== id) { S.order = sortedOrder(s.col, s.dir); S.orderKey = id; }
    return S.order;
  }

  // ---------- zoom and pan of an SVG by its viewBox ----------
  function zoomable(svg, box, onZoom) {
    let vb = box.slice();
    const apply = () => {
      svg.setAttribute('viewBox', vb.join(' '));
      const w = svg.clientWidth || 600, h = svg.clientHeight || 600;
      onZoom(Math.max(vb[2] / w, vb[3] / h));  // user units per screen pixel
    };
    const toUser = (ev) => {
      const r = svg.getBoundingClientRect(), w = r.width || 1, h = r.height || 1;
      const s = Math.max(vb[2] / w, vb[3] / h);
      const ox = vb[0] + (vb[2] - w * s) / 2, oy = vb[1] + (vb[3] - h * s) / 2;  // xMidYMid meet
      return [ox + (ev.clientX - r.left) * s, oy + (ev.clientY - r.top) * s, s];
    };
    svg.addEventListener('wheel', (ev) => {
      ev.preventDefault();
      const [ux, uy] = toUser(ev);
      const f = ev.deltaY > 0 ? 1.25 : 0.8;
      const w = Math.min(box[2] * 4, Math.max(box[2] / 64, vb[2] * f)), k = w / vb[2];
      vb = [ux - (ux - vb[0]) * k, uy - (uy - vb[1]) * k, vb[2] * k, vb[3] * k];
      apply();
    }, { passive: false });
    let drag = null;
    svg.addEventListener('pointerdown', (ev) => { drag = { x: ev.clientX, y: ev.clientY, vb: vb.slice(), moved: false }; });
    svg.addEventListener('pointermove', (ev) => {
      if (!drag) return;
      const s = toUser(ev)[2], dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
      if (Math.abs(dx) + Math.abs(dy) > 3) drag.moved = true;
      vb = [drag.vb[0] - dx * s, drag.vb[1] - dy * s, vb[2], vb[3]];
      apply();
    });
    const end = () => { svg.dataset.dragged = drag && drag.moved ? '1' : ''; drag = null; };
    svg.addEventListener('pointerup', end);
    svg.addEventListener('pointerleave', () => { drag = null; });
    svg.addEventListener('dblclick', () => { vb = box.slice(); apply(); });
    return {
      reset() { vb = box.slice(); apply(); },
      zoom(f) { const cx = vb[0] + vb[2] / 2, cy = vb[1] + vb[3] / 2; vb = [cx - vb[2] * f / 2, cy - vb[3] * f / 2, vb[2] * f, vb[3] * f]; apply(); },
      apply,
    };
  }

  // ---------- colour ramp for per-tile values ----------
  const RAMP = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];  // viridis stops
  function ramp(t) {
    t = Math.max(0, Math.min(1, t)) * (RAMP.length - 1);
    const i = Math.min(RAMP.length - 2, Math.floor(t)), f = t - i, a = RAMP[i], b = RAMP[i + 1];
    return 'rgb(' + a.map((x, k) => Math.round(x + (b[k] - x) * f)).join(',') + ')';
  }
  function extent(vals) {
    let lo = Infinity, hi = -Infinity;
    for (const v of vals) if (v !== null) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    return lo <= hi ? [lo, hi] : null;
  }

  // ---------- pages ----------
  function setActive(view) {
    for (const a of document.querySelectorAll('nav a')) a.classList.toggle('active', a.dataset.view === view);
  }

  function summaryPage(main) {
    const s = S.summary;
    main.append(el('h2', { text: s.mode === 'submission' ? 'Scores (macro mean over tiles)' : 'Dataset figures per split' }));
    if (s.mode === 'submission') {
      const base = !!s.baseline;
      const head = ['metric', base ? 'submission' : 'mean', 'defined', 'undefined'];
      if (base) head.push('baseline', 'difference', 'paired Δ', '± SE', 'pairs');
      const t = el('table', { id: 'summary-table' }, el('tr', {}, ...head.map((h, i) => el('th', { class: i ? '' : 'key', text: h }))));
      for (const r of s.summary) {
        // Headline metrics by their leaderboard names (the id beside), then every other by its id.
        const name = r.label ? el('td', { class: 'key' }, el('strong', { text: r.label }), el('span', { class: 'muted', text: ' ' + r.metric }))
          : el('td', { class: 'key', text: r.metric });
        const cells = [name, el('td', { text: fmt(r.mean) }),
          el('td', { text: fmt(r.n_defined) }), el('td', { text: fmt(r.n_undefined) })];
        if (base) cells.push(el('td', { text: fmt(r.baseline_mean) }), el('td', { text: fmt(r.difference) }),
          el('td', { text: fmt(r.paired_mean) }), el('td', { text: fmt(r.paired_se) }), el('td', { text: fmt(r.paired_n) }));
        t.append(el('tr', { class: r.label ? 'headline' : '' }, ...cells));
      }
      main.append(el('div', { class: 'table-wrap' }, t));
      const facts = el('table', { class: 'facts' });
      const sc = s.score;
      const add = (k, v) => facts.append(el('tr', {}, el('td', { text: k }), el('td', { text: v })));
      add('submission', sc.submission);
      if (base) add('baseline', s.baseline.submission);
      add('tiles scored', fmt(sc.n_tiles));
      add('missing predictions (scored as empty)', fmt(sc.n_missing_predictions));
      add('extra keys (ignored)', fmt(sc.n_extra_predictions));
      for (const [k, v] of Object.entries(sc.pooled)) add('pooled ' + k, fmt(v));
      main.append(el('h2', { text: 'Facts' }), facts);
      if (s.rungs && window.NSG_LADDER) main.append(...window.NSG_LADDER(s, { el, sv, fmt }));
    } else {
      const splits = Object.keys(s.stats.splits || s.stats);
      const data = s.stats.splits || s.stats;
      const names = [];
      for (const sp of splits) for (const k of Object.keys(data[sp])) if (!names.includes(k)) names.push(k);
      const t = el('table', { id: 'summary-table' }, el('tr', {}, el('th', { class: 'key', text: 'figure' }), ...splits.map((x) => el('th', { text: x }))));
      for (const k of names) {
        t.append(el('tr', {}, el('td', { class: 'key', text: k }), ...splits.map((sp) => {
          const v = data[sp][k];
          const show = Array.isArray(v) ? v.join(', ') : typeof v === 'number' ? fmt(v)
            : v && typeof v === 'object' ? Object.entries(v).map(([a, b]) => a + ' ' + fmt(b)).join(', ') : String(v ?? '—');
          return el('td', { text: show });
        })));
      }
      main.append(el('div', { class: 'table-wrap' }, t));
    }
    const hists = el('div', { class: 'hists', id: 'hists' }, el('p', { class: 'muted', text: 'loading the tiles…' }));
    main.append(el('h2', { text: 'Histograms over tiles' }), hists);
    needTiles().then(() => {
      hists.textContent = '';
      for (const col of s.main) hists.append(histogram(col));
    });
  }

  function histogram(col) {
    const vals = S.tiles.values[col] || [], W = 260, H = 150, B = 20;
    const defined = vals.filter((v) => v !== null), ex = extent(defined);
    const svg = sv('svg', { width: W, height: H, class: 'hist-svg' });
    const box = el('div', { class: 'hist' }, el('div', { text: col + ' (' + defined.length + ' defined, ' + (vals.length - defined.length) + ' undefined)' }), svg);
    if (!ex) return box;
    const [lo, hi] = ex, span = hi - lo || 1, counts = new Array(B).fill(0);
    for (const v of defined) counts[Math.min(B - 1, Math.floor((v - lo) / span * B))]++;
    const top = Math.max(...counts), pw = (W - 20) / B, ph = H - 30;
    counts.forEach((c, i) => svg.append(sv('rect', { class: 'bar', x: 10 + i * pw, y: 5 + ph - (c / top) * ph, width: Math.max(1, pw - 1), height: (c / top) * ph },
      sv('title', { text: fmt(lo + i * span / B) + ' … ' + fmt(lo + (i + 1) * span / B) + ': ' + c }))));
    svg.append(sv('text', { x: 10, y: H - 8, text: fmt(lo) }), sv('text', { x: W - 10, y: H - 8, 'text-anchor': 'end', text: fmt(hi) }));
    return box;
  }

  // The per-tile table's columns the reader chose (#hide=<col>,<col>; "-" = none hidden).
  // By default only the headline metrics (summary.main) and their differences from a baseline
  // are shown of the metric columns, beside the prediction's and tile's facts: every metric
  // with its baseline and Δ is over 50 columns, which pushed the Δ columns off-screen. A
  // baseline's own values stay hidden; the chooser shows the rest.
  function hiddenColumns() {
    const h = params().hide;
    if (h === undefined) {
      const metrics = new Set((S.summary.summary || []).map((r) => r.metric));
      const main = new Set(S.summary.main || []);
      const bare = (c) => c.replace(/^(baseline|delta)\./, '');
      return new Set(S.summary.columns.filter((c) => c.startsWith('baseline.') ||
        (metrics.has(bare(c)) && !main.has(bare(c)))));
    }
    return new Set(h.split(',').filter((c) => c && c !== '-'));
  }
  function setHidden(hidden) { go({ hide: hidden.size ? Array.from(hidden).join(',') : '-' }); }

  function columnChooser(hidden) {
    const all = S.summary.columns;
    const box = el('details', { id: 'column-chooser', class: 'chooser' },
      el('summary', { text: 'Columns: ' + (all.length - hidden.size) + ' of ' + all.length + ' shown' }));
    if (S.chooserOpen) box.open = true;
    box.addEventListener('toggle', () => { S.chooserOpen = box.open; });
    const group = (label, pred) => el('button', { text: label, onclick: () => {
      const cols = all.filter(pred), showing = cols.some((c) => !hidden.has(c));
      for (const c of cols) { if (showing) hidden.add(c); else hidden.delete(c); }
      setHidden(hidden);
    } });
    const metrics = new Set((S.summary.summary || []).map((r) => r.metric));
    box.append(el('div', {}, el('button', { text: 'all', onclick: () => setHidden(new Set()) }), ' ',
      el('button', { text: 'none', onclick: () => setHidden(new Set(all)) }), ' ',
      metrics.size ? group('metrics', (c) => metrics.has(c)) : null, ' ',
      all.some((c) => c.startsWith('baseline.')) ? group('baseline', (c) => c.startsWith('baseline.')) : null, ' ',
      all.some((c) => c.startsWith('delta.')) ? group('Δ', (c) => c.startsWith('delta.')) : null));
    const list = el('div', { class: 'chooser-list' });
    for (const c of all) {
      const cb = el('input', { type: 'checkbox', 'data-col': c });
      cb.checked = !hidden.has(c);
      cb.addEventListener('change', () => { if (cb.checked) hidden.delete(c); else hidden.add(c); setHidden(hidden); });
      list.append(el('label', {}, cb, ' ' + c));
    }
    box.append(list);
    return box;
  }

  function tilesPage(main) {
    const T = S.tiles, s = sortState(), order = currentOrder(), n = order.length;
    const pages = Math.max(1, Math.ceil(n / S.pageSize));
    const page = Math.min(pages - 1, Math.max(0, parseInt(params().page || '0', 10) || 0));
    const hidden = hiddenColumns();
    const shown = S.summary.columns.filter((c) => !hidden.has(c));
    const cols = ['key', 'split', ...shown];
    const head = el('tr', {}, el('th', { text: '#' }), ...cols.map((c) => {
      const cls = 'sortable' + (c === 'key' ? ' key' : '') + (s.col === c ? ' sorted-' + s.dir : '');
      return el('th', { class: cls, 'data-col': c, text: c, title: 'sort by ' + c,
        onclick: () => go({ sort: c, dir: s.col === c && s.dir === 'asc' ? 'desc' : 'asc', page: 0 }) });
    }));
    const table = el('table', { id: 'tile-table' }, head);
    for (let r = page * S.pageSize; r < Math.min(n, (page + 1) * S.pageSize); ++r) {
      const i = order[r], key = T.keys[i];
      const cells = [el('td', { text: String(r + 1) }),
        el('td', { class: 'key' }, el('a', { href: '#' + new URLSearchParams({ view: 'tile', key, sort: s.col, dir: s.dir }), text: key })),
        el('td', { class: 'text', text: T.split[i] })];
      for (const c of shown) cells.push(el('td', { text: fmt(T.values[c][i]) }));
      table.append(el('tr', { class: 'row', 'data-key': key }, ...cells));
    }
    const pager = el('div', { class: 'pager' },
      el('button', { text: '◀ previous', onclick: () => go({ page: Math.max(0, page - 1) }) }),
      el('span', { text: 'page ' + (page + 1) + ' of ' + pages + ' (' + n + ' tiles, ' + S.pageSize + ' per page)' }),
      el('button', { text: 'next ▶', onclick: () => go({ page: Math.min(pages - 1, page + 1) }) }));
    main.append(el('h2', { text: 'Tiles — click a column to sort (undefined values last), a key to open the tile' }),
      columnChooser(hidden), pager, el('div', { class: 'table-wrap' }, table));
  }

  function overviewPage(main) {
    const s = S.summary, T = S.tiles, p = params();
    const colorBy = p.color || 'split';
    const pick = el('select', { onchange: (e) => go({ color: e.target.value }) },
      ...['split', ...s.columns].map((c) => { const o = el('option', { value: c, text: c }); if (c === colorBy) o.selected = true; return o; }));
    main.append(el('h2', { text: 'Overview: tile footprints in map metres (wheel: zoom, drag: pan, double-click: reset)' }),
      el('p', {}, 'Colour by ', pick));
    const vals = colorBy === 'split' ? null : T.values[colorBy];
    const ex = vals ? extent(vals) : null;
    const colour = (i) => {
      if (!vals) return s.legends.splits[T.split[i]] || '#999';
      const v = vals[i];
      if (v === null || !ex) return '#bbbbbb';
      let t = (v - ex[0]) / ((ex[1] - ex[0]) || 1);
      if (lowerIsBetter(colorBy)) t = 1 - t;
      return ramp(t);
    };
    const legend = el('div', { class: 'legend' });
    if (!vals) for (const [k, c] of Object.entries(s.legends.splits)) legend.append(el('span', {}, el('span', { class: 'swatch', style: 'background:' + c }), k + ' region / tile'));
    else if (ex) {
      const good = lowerIsBetter(colorBy) ? ex[0] : ex[1], bad = lowerIsBetter(colorBy) ? ex[1] : ex[0];
      for (let k = 0; k <= 4; ++k) legend.append(el('span', {}, el('span', { class: 'swatch', style: 'background:' + ramp(k / 4) }), fmt(bad + (good - bad) * k / 4)));
      legend.append(el('span', {}, el('span', { class: 'swatch', style: 'background:#bbbbbb' }), 'undefined'));
    }
    legend.append(el('span', {}, el('span', { class: 'line-swatch dashed', style: 'border-color:#555' }), 'buffer around a region'));
    main.append(legend);
    for (const loc of s.locations) {
      const idx = [];
      T.location.forEach((l, i) => { if (l === loc.name) idx.push(i); });
      if (!idx.length) continue;
      let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
      const grow = (b) => { x0 = Math.min(x0, b[0]); y0 = Math.min(y0, b[1]); x1 = Math.max(x1, b[2]); y1 = Math.max(y1, b[3]); };
      for (const i of idx) grow(T.bounds_m[i]);
      for (const r of loc.regions) grow(r.bounds_m.map((x, k) => x + (k < 2 ? -1 : 1) * loc.buffer_m));
      const pad = 0.03 * Math.max(x1 - x0, y1 - y0);
      const box = [x0 - pad, -y1 - pad, x1 - x0 + 2 * pad, y1 - y0 + 2 * pad];  // SVG y = −map y (north up)
      const svg = sv('svg', { class: 'map', 'data-location': loc.name, preserveAspectRatio: 'xMidYMid meet' });
      const g = sv('g', {});
      const ov = loc.overview;
      if (ov) g.append(sv('image', { href: ov.image, x: ov.x_west_m, y: -ov.y_north_m, width: ov.width_px * ov.m_per_px, height: ov.height_px * ov.m_per_px, opacity: 0.8 }));
      const lines = [];
      for (const r of loc.regions) {
        const b = r.bounds_m, bb = loc.buffer_m;
        if (bb > 0) lines.push(sv('rect', { class: 'buffer', x: b[0] - bb, y: -b[3] - bb, width: b[2] - b[0] + 2 * bb, height: b[3] - b[1] + 2 * bb }));
        lines.push(sv('rect', { class: 'region', x: b[0], y: -b[3], width: b[2] - b[0], height: b[3] - b[1], stroke: s.legends.splits[r.split] || '#999' }));
        lines.push(sv('text', { x: b[0], y: -b[3], class: 'label', text: r.name + ' (' + r.split + ')' }));
      }
      g.append(...lines);
      const tiles = sv('g', { class: 'tiles' });
      for (const i of idx) {
        const b = T.bounds_m[i], key = T.keys[i];
        tiles.append(sv('rect', { class: 'tile', x: b[0], y: -b[3], width: b[2] - b[0], height: b[3] - b[1], fill: colour(i), 'fill-opacity': 0.55, 'data-key': key,
          onclick: () => { if (!svg.dataset.dragged) go({ view: 'tile', key }); } }, sv('title', { text: key + (vals ? ': ' + colorBy + ' ' + fmt(vals[i]) : '') })));
      }
      g.append(tiles);
      svg.append(g);
      main.append(el('h2', { text: loc.name + ' — ' + idx.length + ' tile(s)' }), svg);
      const z = zoomable(svg, box, (upp) => {
        tiles.setAttribute('stroke-width', upp);  // inherited by every footprint
        g.querySelectorAll('rect.region').forEach((r) => r.setAttribute('stroke-width', 3 * upp));
        g.querySelectorAll('rect.buffer').forEach((r) => { r.setAttribute('stroke-width', 1.5 * upp); r.setAttribute('stroke-dasharray', 6 * upp + ' ' + 4 * upp); });
        g.querySelectorAll('text.label').forEach((t) => { t.setAttribute('font-size', 12 * upp); t.setAttribute('dy', 14 * upp); t.setAttribute('dx', 4 * upp); });
      });
      requestAnimationFrame(z.apply);
    }
  }

  // The tile view: one layer image, the two graphs over it, the tile's figures.
  function tilePage(main, key) {
    const p = params(), s = S.summary;
    let layer = s.layers.includes(p.layer) ? p.layer : 'lidar';
    main.append(el('p', { class: 'muted', id: 'tile-loading', text: 'loading ' + key + '…' }));
    Promise.all([needTiles(), needTile(key)]).then(([T, d]) => {
      if (params().key !== key) return;
      main.textContent = '';
      const order = currentOrder(), st = sortState();
      const pos = order.findIndex((i) => T.keys[i] === key);
      const keyAt = (r) => (r >= 0 && r < order.length ? T.keys[order[r]] : null);
      const prev = keyAt(pos - 1), next = keyAt(pos + 1);
      main.append(el('div', { class: 'nav-buttons' },
        el('button', { id: 'prev', text: '◀ previous', onclick: () => prev && go({ key: prev }) }),
        el('button', { id: 'next', text: 'next ▶', onclick: () => next && go({ key: next }) }),
        el('span', { text: key + ' — ' + (pos + 1) + ' of ' + order.length + ' by ' + st.col + ' ' + (st.dir === 'desc' ? '▼' : '▲') })));
      if (!prev) main.querySelector('#prev').disabled = true;
      if (!next) main.querySelector('#next').disabled = true;

      const N = d.size_px, box = [-0.5, -0.5, N, N];
      const svg = sv('svg', { class: 'viewer', id: 'viewer', preserveAspectRatio: 'xMidYMid meet', 'data-key': key });
      const defs = sv('defs', {});
      for (const o of s.legends.overlay || [])
        defs.append(sv('marker', { id: 'a-' + o.name, viewBox: '0 0 10 10', refX: 5, refY: 5, markerWidth: 4, markerHeight: 4, orient: 'auto', markerUnits: 'strokeWidth' },
          sv('path', { d: 'M0,1 L10,5 L0,9 z', fill: o.color, stroke: 'none' })));
      const img = sv('image', { id: 'layer-image', x: -0.5, y: -0.5, width: N, height: N, href: 'img/' + key + '.' + layer + '.png' });
      const overlay = sv('g', { class: 'overlay', id: 'overlay' });
      // Each edge twice: a wider casing beneath the coloured line, so the line stands out on
      // every layer's colours (preview.h: the colours and their contrast).
      const drawGraph = (gr, cls, edgeClass, lineWidth) => {
        const g = sv('g', { class: cls, id: cls + '-layer' }), casing = sv('g', {}), lines = sv('g', {});
        gr.edges.forEach(([i, j], e) => {
          const a = gr.nodes[i], b = gr.nodes[j];
          const m = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2], path = 'M' + a + 'L' + m + 'L' + b;
          casing.append(sv('path', { d: path, class: 'casing' }));
          lines.append(sv('path', { d: path, class: ('line ' + edgeClass(e)).trim() }));
        });
        g.append(casing, lines);
        return { g, zoom: (upp) => { casing.setAttribute('stroke-width', (lineWidth + 2) * upp); lines.setAttribute('stroke-width', lineWidth * upp); } };
      };
      const graphs = [];
      const gtG = drawGraph(d.gt, 'gt', (e) => (d.gt.missed && d.gt.missed[e] ? 'missed' : ''), 3);
      graphs.push(gtG);
      let baseG = null, predG = null, shownKey = key;
      if (d.base) {
        baseG = drawGraph(d.base, 'base', () => '', 2);
        baseG.g.style.display = params().base === '1' ? '' : 'none';
        graphs.push(baseG);
      }
      if (d.pred) {
        predG = drawGraph(d.pred, 'pred', (e) => 'm' + d.pred.marks[e], 2);
        graphs.push(predG);
      }
      // The ground truth's lane changes (dashed rungs) and junction nodes (rings), each a layer
      // the side panel toggles: off at first, so the graphs read as before.
      const attrG = drawAttributes(d);
      if (attrG) { for (const a of [attrG.changes, attrG.junctions]) a.g.style.display = 'none'; graphs.push(attrG.changes, attrG.junctions); }
      for (const gr of graphs) overlay.append(gr.g);
      svg.append(defs, img, overlay);
      const z = zoomable(svg, box, (upp) => {
        overlay.style.setProperty('--dash', 6 * upp + ' ' + 4 * upp);
        for (const gr of graphs) gr.zoom(upp);
      });
      // A ladder tile's rung r in the viewer: its layer image, its prediction and the ground
      // truth's edges that prediction missed (ladder.js draws the rungs side by side).
      const showRung = (r) => {
        shownKey = r.key;
        img.setAttribute('href', 'img/' + r.key + '.' + layer + '.png');
        if (d.pred !== undefined) {
          gtG.g.querySelectorAll('path.line').forEach((path, e) => path.classList.toggle('missed', !!(r.missed && r.missed[e])));
          const pr = r.pred || { nodes: [], edges: [], marks: [] };
          const fresh = drawGraph(pr, 'pred', (e) => 'm' + pr.marks[e], 2);
          if (predG) { fresh.g.style.display = predG.g.style.display; predG.g.replaceWith(fresh.g); graphs[graphs.indexOf(predG)] = fresh; }
          else { overlay.append(fresh.g); graphs.push(fresh); }
          predG = fresh;
          z.apply();
        }
        history.replaceState(null, '', '#' + new URLSearchParams(Object.assign(params(), { rung: String(r.rung) })));
      };
      const ladder = d.rungs && d.rungs.length && window.NSG_LADDER_TILE
        ? window.NSG_LADDER_TILE(d, { el, fmt, layer: () => layer, rung: p.rung, show: showRung }) : null;

      // Side panel: layers, overlays, legend, figures.
      const side = el('div', { class: 'side' });
      const layers = el('fieldset', {}, el('legend', { text: 'Layer' }));
      for (const l of s.layers) {
        const r = el('input', { type: 'radio', name: 'layer', value: l, id: 'layer-' + l });
        if (l === layer) r.checked = true;
        r.addEventListener('change', () => {
          layer = l;
          img.setAttribute('href', 'img/' + shownKey + '.' + l + '.png');
          if (ladder) ladder.setLayer(l);
          legendBox.replaceChildren(layerLegend(l));
          history.replaceState(null, '', '#' + new URLSearchParams(Object.assign(params(), { layer: l })));
        });
        layers.append(el('label', {}, r, ' ' + l + ' '));
      }
      const legendBox = el('div', { id: 'layer-legend' }, layerLegend(layer));
      layers.append(legendBox);
      const toggles = el('fieldset', {}, el('legend', { text: 'Overlays' }));
      const toggle = (label, id, on, fn) => {
        const c = el('input', { type: 'checkbox', id });
        c.checked = on;
        c.addEventListener('change', () => fn(c.checked));
        toggles.append(el('label', {}, c, ' ' + label), el('br'));
      };
      toggle('ground truth', 'show-gt', true, (on) => { gtG.g.style.display = on ? '' : 'none'; });
      if (predG || (ladder && d.pred !== undefined)) toggle('prediction', 'show-pred', true, (on) => { if (predG) predG.g.style.display = on ? '' : 'none'; });
      if (baseG) toggle("baseline's prediction", 'show-base', params().base === '1', (on) => {
        baseG.g.style.display = on ? '' : 'none';
        history.replaceState(null, '', '#' + new URLSearchParams(Object.assign(params(), { base: on ? '1' : '0' })));
      });
      if (d.pred !== undefined) toggle('mark errors', 'show-marks', true, (on) => svg.classList.toggle('plain', !on));
      if (attrG) {
        toggle('lane changes (' + d.attributes.lane_changes.length + ')', 'show-lane-changes', false, (on) => { attrG.changes.g.style.display = on ? '' : 'none'; });
        toggle('junctions (' + d.attributes.junctions.length + ')', 'show-junctions', false, (on) => { attrG.junctions.g.style.display = on ? '' : 'none'; });
      }
      toggles.append(overlayLegend(d));
      toggles.append(el('div', {}, el('button', { text: '+', onclick: () => z.zoom(0.8) }), ' ', el('button', { text: '−', onclick: () => z.zoom(1.25) }), ' ',
        el('button', { text: 'reset', onclick: () => z.reset() }), el('span', { class: 'muted', text: ' wheel: zoom, drag: pan' })));
      side.append(layers, ...(ladder ? [ladder.side] : []), toggles, figures(d));
      main.append(el('div', { class: 'tile-view' }, el('div', { class: 'tile-main' }, svg, ladder ? ladder.strip : null), side));
      if (ladder) ladder.initial();
      requestAnimationFrame(z.apply);
      S.marks.tileShown = key;
    }).catch((e) => { main.textContent = ''; main.append(el('p', { class: 'error', text: String(e) })); S.errors.push(String(e)); });
  }

  function layerLegend(layer) {
    const items = S.summary.legends[layer] || [];
    if (!items.length) return el('div', { class: 'muted', text: layer === 'rgb' ? 'camera colours; black = no data' : '' });
    return el('div', { class: 'legend' }, ...items.map((it) => el('span', {}, el('span', { class: 'swatch', style: 'background:' + it.color }), it.label)));
  }

  // graph.json's lane changes as dashed lines between their two nodes, its split and merge
  // nodes as rings (docs/dataset-format.md "Graph attributes"); null for a tile without them.
  function drawAttributes(d) {
    if (!d.attributes || !d.gt) return null;
    const nodes = d.gt.nodes;
    const changes = sv('g', { id: 'lane-change-layer', class: 'lane-changes' });
    for (const [i, j] of d.attributes.lane_changes)
      changes.append(sv('path', { d: 'M' + nodes[i] + 'L' + nodes[j], class: 'lane-change' }));
    const junctions = sv('g', { id: 'junction-layer', class: 'junctions' });
    for (const [n, kind] of d.attributes.junctions)
      junctions.append(sv('circle', { cx: nodes[n][0], cy: nodes[n][1], r: 3, class: 'junction ' + kind }));
    const zoomWidth = (g, w) => (upp) => g.setAttribute('stroke-width', w * upp);
    return { changes: { g: changes, zoom: zoomWidth(changes, 1.5) }, junctions: { g: junctions, zoom: zoomWidth(junctions, 2) } };
  }

  function overlayLegend(d) {
    const line = (name) => {
      const o = overlay(name);
      return el('span', {}, el('span', { class: 'line-swatch cased' + (o.dashed ? ' dashed' : ''), style: 'border-color:' + o.color }), o.label);
    };
    const items = [line('gt')];
    if (d.attributes) items.push(line('lane_change'), line('junction'));
    if (d.pred !== undefined) {
      items.push(line('missed'), line('pred'), line('wrong_direction'), line('unmatched'));
      if (d.pred === null) items.push(el('span', { class: 'error', text: 'no prediction for this tile (scored as empty)' }));
    }
    if (d.base !== undefined) {
      items.push(line('baseline'));
      if (d.base === null) items.push(el('span', { class: 'muted', text: 'no baseline prediction for this tile' }));
    }
    return el('div', { class: 'legend' }, ...items);
  }

  function figures(d) {
    const t = el('table', { id: 'tile-figures', class: 'facts' });
    const add = (k, v, ...extra) => t.append(el('tr', {}, el('td', { text: k }), el('td', { text: fmt(v) }), ...extra.map((x) => el('td', { text: fmt(x) }))));
    if (d.metrics) {
      t.append(el('tr', {}, el('th', { class: 'key', text: 'metric' }), el('th', { text: 'value' }),
        d.baseline ? el('th', { text: 'baseline' }) : null, d.baseline ? el('th', { text: 'Δ' }) : null));
      for (const [k, v] of Object.entries(d.metrics)) {
        if (d.baseline) add(k, v, d.baseline[k], d.figures['delta.' + k]);
        else add(k, v);
      }
      for (const [k, v] of Object.entries(d.marks)) add('edges: ' + k, v);
    }
    for (const [k, v] of Object.entries(d.figures)) if (!d.metrics || !(k in d.metrics) && !/^(baseline|delta)\./.test(k)) add(k, v);
    return el('fieldset', {}, el('legend', { text: 'Tile ' + d.key + ' (' + d.split + ', ' + d.location + ')' }), t);
  }

  // ---------- routing ----------
  function render() {
    const p = params(), main = document.getElementById('main');
    const view = p.view || 'summary';
    setActive(view === 'tile' ? 'tiles' : view);
    main.textContent = '';
    try {
      if (view === 'summary') summaryPage(main);
      else if (view === 'tile' && p.key) tilePage(main, p.key);
      else {
        main.append(el('p', { class: 'muted', text: 'loading the tiles…' }));
        needTiles().then(() => {
          if ((params().view || 'summary') !== view) return;
          main.textContent = '';
          if (view === 'tiles') tilesPage(main); else overviewPage(main);
        }).catch((e) => S.errors.push(String(e)));
      }
    } catch (e) {
      S.errors.push(String(e && e.stack || e));
      main.append(el('p', { class: 'error', text: String(e) }));
    }
  }

  function start() {
    const s = S.summary;
    // The overlays' colours, declared once in C++ (preview.h), as the stylesheet's variables.
    const root = document.documentElement.style;
    for (const o of s.legends.overlay || []) root.setProperty('--ov-' + o.name, o.color);
    root.setProperty('--ov-casing', s.legends.casing || '#000000');
    document.getElementById('title').textContent = 'nsgraph report — ' + s.dataset + (s.split ? ' / ' + s.split : '') +
      (s.mode === 'submission' ? ' — ' + s.score.submission.split('/').pop() : ' (dataset)');
    status(s.n_tiles + ' tiles · ' + s.tool);
    window.addEventListener('hashchange', render);
    render();
    S.marks.firstRender = performance.now() - S.t0;
    // Milliseconds since navigation, readable from a DOM dump without the self-test.
    document.documentElement.dataset.firstRenderMs = Math.round(performance.now());
    needTiles().then(() => { document.documentElement.dataset.tilesLoadedMs = Math.round(performance.now()); });
    // The self-test (selftest.js) gets the page's state and the steps it drives.
    if (params().selftest) NSG.selftest(params().selftest, { S, needTiles, go, sortState, currentOrder });
  }
})();
