// nsgraph report page: the observation ladder's section of the summary (a submission that
// predicts rung tiles, score's `rungs`): per metric, the mean over tiles at each rung with
// ± one standard error, as a curve and as a table. report.js calls NSG_LADDER(summary, h)
// with its element helpers h = {el, sv, fmt}.
'use strict';
window.NSG_LADDER = function (s, h) {
  const { el, sv, fmt } = h;
  const rungs = s.rungs || [];
  const nodes = [el('h2', { text: 'Per rung (observation ladder: tiles seen by the first k scenes)' })];
  // One curve per main metric: x = the rungs in order, y = mean ± SE.
  function curve(metric) {
    const W = 260, H = 150, L = 36, R = 10, T = 10, B = 26;
    const pts = rungs.map((r, i) => ({ i, r: r.rung, m: r.metrics[metric] || {} }))
      .filter((p) => p.m.mean !== null && p.m.mean !== undefined);
    const svg = sv('svg', { width: W, height: H, class: 'rung-svg', 'data-metric': metric });
    const box = el('div', { class: 'hist rung-curve' }, el('div', { text: metric + ' by rung (mean ± SE)' }), svg);
    if (!pts.length) return box;
    let lo = Math.min(...pts.map((p) => p.m.mean - (p.m.se || 0)));
    let hi = Math.max(...pts.map((p) => p.m.mean + (p.m.se || 0)));
    if (hi - lo < 1e-9) { lo -= 0.5; hi += 0.5; }
    const x = (i) => L + (rungs.length > 1 ? i * (W - L - R) / (rungs.length - 1) : (W - L - R) / 2);
    const y = (v) => T + (hi - v) / (hi - lo) * (H - T - B);
    svg.append(sv('polyline', { class: 'rung-line', fill: 'none', points: pts.map((p) => x(p.i) + ',' + y(p.m.mean)).join(' ') }));
    for (const p of pts) {
      const se = p.m.se || 0;
      svg.append(sv('line', { class: 'rung-err', x1: x(p.i), x2: x(p.i), y1: y(p.m.mean - se), y2: y(p.m.mean + se) }),
        sv('circle', { class: 'rung-point', cx: x(p.i), cy: y(p.m.mean), r: 3, 'data-rung': p.r },
          sv('title', { text: 'rung ' + p.r + ': ' + fmt(p.m.mean) + ' ± ' + fmt(p.m.se) + ' (' + p.m.n + ' tiles)' })));
    }
    rungs.forEach((r, i) => svg.append(sv('text', { x: x(i), y: H - 8, 'text-anchor': 'middle', text: r.rung })));
    svg.append(sv('text', { x: 2, y: T + 8, text: fmt(hi) }), sv('text', { x: 2, y: H - B, text: fmt(lo) }));
    return box;
  }
  const curves = el('div', { class: 'hists', id: 'rung-curves' });
  for (const m of s.main) curves.append(curve(m));
  nodes.push(curves);
  // The table: every metric, mean ± SE per rung, and the paired difference to "all".
  const head = ['metric'];
  for (const r of rungs) head.push('rung ' + r.rung, r.rung === 'all' ? '' : 'Δ vs all');
  const t = el('table', { id: 'rung-table' }, el('tr', {}, ...head.filter((x) => x !== '').map((x, i) => el('th', { class: i ? '' : 'key', text: x }))));
  const pm = (st) => (st && st.mean !== null && st.mean !== undefined ? fmt(st.mean) + ' ± ' + fmt(st.se) : '—');
  for (const metric of Object.keys(rungs.length ? rungs[0].metrics : {})) {
    const cells = [el('td', { class: 'key', text: metric })];
    for (const r of rungs) {
      cells.push(el('td', { text: pm(r.metrics[metric]) }));
      if (r.rung !== 'all') cells.push(el('td', { text: pm(r.vs_all && r.vs_all[metric]) }));
    }
    t.append(el('tr', { class: s.main.includes(metric) ? 'headline' : '' }, ...cells));
  }
  nodes.push(el('div', { class: 'table-wrap' }, t));
  const facts = rungs.map((r) => 'rung ' + r.rung + ': ' + r.tiles + ' tiles, ' + r.missing + ' missing').join('; ');
  nodes.push(el('p', { class: 'muted', text: facts + '. Paired differences are over the tiles defined at both rungs; a missing prediction is scored as empty.' }));
  return nodes;
};

// The tile view's rungs (a ladder dataset: the tile's data file has `rungs`, one entry per
// built rung; the tile itself is rung "all"): the selected layer of every rung side by side
// under the viewer, and a chooser beside it. Choosing a rung calls h.show(entry), which puts
// that rung's layer and, with a submission, its prediction in the viewer. report.js calls
// NSG_LADDER_TILE(tileData, h) with h = {el, fmt, layer: () => the layer shown, rung: the
// URL's rung or undefined, show}; returns {strip, side, setLayer(layer), initial}.
window.NSG_LADDER_TILE = function (d, h) {
  const { el, fmt } = h;
  const all = { rung: 'all', key: d.key, scenes: d.scenes, coverage_lidar: d.figures.coverage_lidar,
    pred: d.pred, missed: d.gt && d.gt.missed, metrics: d.metrics };
  const rungs = d.rungs.concat([all]);
  const pct = (v) => (v === null || v === undefined ? '—' : Math.round(100 * v) + ' %');
  const strip = el('div', { id: 'rung-strip', class: 'rung-strip' });
  const side = el('fieldset', { id: 'rung-chooser' }, el('legend', { text: 'Rung (observation ladder)' }));
  const shown = [];
  const select = (r) => {
    for (const s of shown) {
      s.radio.checked = s.r === r;
      s.fig.classList.toggle('selected', s.r === r);
    }
    h.show(r);
  };
  for (const r of rungs) {
    const apls = r.metrics && r.metrics.apls !== undefined ? ' · APLS ' + fmt(r.metrics.apls) : '';
    const img = el('img', { class: 'rung-thumb', 'data-rung': r.rung, alt: r.key, src: 'img/' + r.key + '.' + h.layer() + '.png' });
    const fig = el('figure', { class: 'rung-fig', title: (r.scenes || []).join(', '), onclick: () => select(r) }, img,
      el('figcaption', { text: 'rung ' + r.rung + ' · ' + (r.scenes || []).length + ' scene(s) · LiDAR ' + pct(r.coverage_lidar) + apls }));
    const radio = el('input', { type: 'radio', name: 'rung', value: r.rung, id: 'rung-' + r.rung });
    radio.addEventListener('change', () => select(r));
    side.append(el('label', {}, radio, ' ' + r.rung + ' '));
    strip.append(fig);
    shown.push({ r, img, fig, radio });
  }
  side.append(el('div', { class: 'muted', text: 'tiles rebuilt from the first k scenes that saw them; same ground truth' }));
  const initial = rungs.find((r) => String(r.rung) === h.rung) || all;
  return {
    strip, side,
    initial: () => select(initial),
    setLayer: (layer) => { for (const s of shown) s.img.setAttribute('src', 'img/' + s.r.key + '.' + layer + '.png'); },
  };
};
