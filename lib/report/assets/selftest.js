// The report page's self-test (report.js calls it for #selftest=...): drives the page as a
// reader would and writes what it saw as JSON into <pre id="selftest"> for headless checks
// (the Browser tests, tests/unit/report/test_browser.cpp). Kept apart from the page's own code.
'use strict';
(function () {
  // ---------- self-test, states into the DOM for headless checks: #selftest=sort:<column>[:desc] sorts
  // the table, opens a tile and the overview; #selftest=table:<column> only sorts (timing) ----------
  const wait = (ms) => new Promise((r) => setTimeout(r, ms));
  async function until(pred, ms) {
    for (let t = 0; t < ms; t += 25) { if (pred()) return true; await wait(25); }
    return false;
  }
  async function selftest(spec, page) {
    const { S, needTiles, go, sortState, currentOrder } = page;
    const out = { errors: S.errors, steps: [] };
    try {
      const [what, col, dir] = spec.split(':');
      await until(() => document.getElementById('summary-table'), 2000);
      out.summary_rows = document.querySelectorAll('#summary-table tr').length - 1;
      out.rung_points = document.querySelectorAll('#rung-curves .rung-point').length;
      out.rung_rows = Math.max(0, document.querySelectorAll('#rung-table tr').length - 1);
      await needTiles();
      out.tiles_loaded_ms = performance.now() - S.t0;
      if (what === 'sort' || what === 'table') {
        const t = performance.now();
        go({ view: 'tiles', sort: col, dir: dir || 'asc', page: 0, selftest: spec });
        await until(() => document.getElementById('tile-table'), 5000);
        out.table_ms = performance.now() - t;
        out.rows = Array.from(document.querySelectorAll('#tile-table tr.row')).map((r) => r.dataset.key);
        out.sorted_by = sortState();
        out.table_columns = Array.from(document.querySelectorAll('#tile-table th[data-col]')).map((th) => th.dataset.col);
        out.chooser_boxes = document.querySelectorAll('#column-chooser input[type=checkbox]').length;
      }
      if (what === 'sort') {
        // Open a tile holding both graphs, its prediction's directions right where there is
        // such a tile (else the first row), and look at its overlays.
        const T = S.tiles, order = currentOrder();
        const both = (i) => (T.values.gt_edges[i] || 0) > 0 && (T.values.pred_edges ? (T.values.pred_edges[i] || 0) > 0 : true);
        const right = (i) => !T.values.wrong_direction_edges || T.values.wrong_direction_edges[i] === 0;
        let pick = order.find((i) => both(i) && right(i));
        if (pick === undefined) pick = order.find(both);
        if (pick === undefined) pick = order[0];
        go({ view: 'tile', key: T.keys[pick], base: '1' });
        await until(() => S.marks.tileShown === T.keys[pick], 3000);
        const img = document.getElementById('layer-image');
        const strokeOf = (sel) => { const p = document.querySelector(sel); return p ? getComputedStyle(p).stroke : null; };
        out.tile = {
          key: T.keys[pick],
          gt_paths: document.querySelectorAll('#gt-layer path.line').length,
          pred_paths: document.querySelectorAll('#pred-layer path.line').length,
          base_paths: document.querySelectorAll('#base-layer path.line').length,
          casing_paths: document.querySelectorAll('#overlay path.casing').length,
          lane_change_paths: document.querySelectorAll('#lane-change-layer path.lane-change').length,
          junction_rings: document.querySelectorAll('#junction-layer circle.junction').length,
          attribute_toggles: document.querySelectorAll('#show-lane-changes, #show-junctions').length,
          strokes: { gt: strokeOf('#gt-layer path.line:not(.missed)'), pred: strokeOf('#pred-layer path.line.m0'),
            baseline: strokeOf('#base-layer path.line'), casing: strokeOf('#overlay path.casing'),
            lane_change: strokeOf('#lane-change-layer path'), junction: strokeOf('#junction-layer circle') },
          image: img ? img.getAttribute('href') : null,
          layers: document.querySelectorAll('input[name=layer]').length,
          figures_rows: document.querySelectorAll('#tile-figures tr').length,
          rung_thumbs: Array.from(document.querySelectorAll('#rung-strip img')).map((i) => i.getAttribute('src')),
        };
        // A ladder tile: choose its first rung and look at what the viewer shows then.
        const first = document.querySelector('input[name=rung]');
        if (first) {
          first.click();
          out.tile.rung_chosen = { rung: first.value, image: img.getAttribute('href'),
            pred_paths: document.querySelectorAll('#pred-layer path.line').length,
            missed_paths: document.querySelectorAll('#gt-layer path.line.missed').length,
            selected: document.querySelectorAll('#rung-strip figure.selected').length };
        }
        go({ view: 'overview', color: 'split' });
        await until(() => document.querySelector('svg.map rect.tile'), 2000);
        out.overview_tiles = document.querySelectorAll('svg.map rect.tile').length;
        out.overview_regions = document.querySelectorAll('svg.map rect.region').length;
        out.overview_buffers = document.querySelectorAll('svg.map rect.buffer').length;
        await wait(100);  // let images finish or fail
      }
      const paint = performance.getEntriesByType('paint').find((e) => e.name === 'first-contentful-paint');
      out.first_contentful_paint_ms = paint ? paint.startTime : null;
      out.first_render_ms = S.marks.firstRender;
    } catch (e) {
      S.errors.push('selftest: ' + (e && e.stack || e));
    }
    const pre = document.getElementById('selftest');
    pre.textContent = JSON.stringify(out);
    pre.dataset.done = '1';
  }
  window.NSG.selftest = selftest;
})();
