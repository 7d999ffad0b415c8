// pkslam view: the strip above the timeline's scrubber, for viewer.js. Plots the whole run
// against time (tick labels in seconds since the first frame): tracked points (grey), keyframes
// (red ticks), PKS's D_c (blue) against Th_adaptive (orange) on one scale, and the online
// calibration's time-offset estimate (purple steps, a purple tick per applied adjustment); a
// black line marks the current frame. The left margin gives each series' top value in its
// colour; a legend above names the series present. Defines window.PkslamStrip.
(function () {
  'use strict';

  const GUTTER = 64;      // left margin of the plot, px (the scrubber starts there too)
  const THUMB = 8;        // the range input's thumb radius: its track starts this far in
  const AXIS = 13;        // bottom margin for the time ticks, px
  const COLOURS = { tracked: '#999999', kf: '#d62728', D_c: '#1f77b4', Th: '#ff7f0e',
                    offset: '#9467bd', current: '#000000' };

  // The series the rows hold, only those present: [{key, name, colour, unit, values, kind, lo,
  // top}], each scaled from lo (0, or its lowest value when negative) to top.
  // `offsetAt(t)` is the time-offset estimate in use at t (undefined before the first).
  function seriesOf(rows, offsetAt) {
    const out = [];
    const finite = (a) => a !== undefined && a !== null && isFinite(a);
    const add = (key, name, colour, unit, value, kind) => {
      const values = rows.map(value);
      if (!values.some(finite)) return null;
      const s = { key, name, colour, unit, values, kind,
                  lo: Math.min(0, ...values.filter(finite)),
                  top: Math.max(0, ...values.filter(finite)) };
      out.push(s);
      return s;
    };
    add('tracked', 'tracked points', COLOURS.tracked, 'points', (r) => r.tracked, 'line');
    if (rows.some((r) => r.kf)) {
      out.push({ key: 'kf', name: 'keyframes', colour: COLOURS.kf, kind: 'ticks', values: [] });
    }
    const d = add('D_c', 'D_c (points that changed view region)', COLOURS.D_c, 'points',
                  (r) => (r.q ? r.q.D_c : undefined), 'line');
    const th = add('Th_adaptive', 'Th_adaptive (threshold on D_c)', COLOURS.Th, 'points',
                   (r) => (r.q ? r.q.Th_adaptive : undefined), 'line');
    if (d && th) {  // one scale: criterion 1 holds where D_c is above Th_adaptive
      d.top = th.top = Math.max(d.top, th.top);
      d.lo = th.lo = Math.min(d.lo, th.lo);
    }
    add('offset', 'time-offset estimate (ticks: adjustments)', COLOURS.offset, 'ms', offsetAt,
        'steps');
    return out;
  }

  // Draws the strip; returns what it drew ({ticks: ['0 s', ...], yLabels: [...]}).
  function draw(canvas, rows, series, current) {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    canvas.width = w;
    canvas.height = h;
    const g = canvas.getContext('2d');
    g.clearRect(0, 0, w, h);
    const drawn = { ticks: [], yLabels: [] };
    if (rows.length < 2) return drawn;
    const t0 = rows[0].t;
    const span = Math.max(1e-9, rows[rows.length - 1].t - t0);
    const left = GUTTER + THUMB, right = w - THUMB, top = 2, bottom = h - AXIS;
    const x = (t) => left + ((t - t0) / span) * (right - left);
    const y = (a, s) => bottom - ((a - s.lo) / (s.top - s.lo)) * (bottom - top - 8);
    const range = (s) => `${s.lo < 0 ? `${Number(s.lo.toPrecision(3))} to ` : ''}` +
                         `${Number(s.top.toPrecision(3))} ${s.unit}`;
    g.font = '10px sans-serif';

    // Time axis: a round step giving a label every 90 px or more.
    g.strokeStyle = '#888888';
    g.beginPath();
    g.moveTo(left, bottom + 0.5);
    g.lineTo(right, bottom + 0.5);
    g.stroke();
    const least = Math.max(1e-3, (span * 90) / Math.max(1, right - left));
    const decade = Math.pow(10, Math.floor(Math.log10(least)));
    const step = [1, 2, 5, 10].map((m) => m * decade).find((v) => v >= least);
    g.fillStyle = '#333333';
    g.textAlign = 'center';
    for (let k = 0; k * step <= span + 1e-9; ++k) {
      const label = `${Number((k * step).toFixed(3))} s`;
      const at = x(t0 + k * step);
      g.fillRect(at, bottom, 1, 3);
      g.fillText(label, Math.min(at, w - g.measureText(label).width / 2 - 1), h - 1);
      drawn.ticks.push(label);
    }
    g.textAlign = 'left';
    g.fillText('time', 2, h - 1);

    // Series: lines and steps scaled to their top value (given in the left margin).
    let labelY = 10;
    series.forEach((s) => {
      if (s.kind === 'ticks') {
        g.fillStyle = s.colour;
        rows.forEach((r) => { if (r.kf) g.fillRect(x(r.t), top, 1, 6); });
        return;
      }
      if (!(s.top > s.lo)) return;
      g.strokeStyle = s.colour;
      g.beginPath();
      let pen = false;
      s.values.forEach((a, i) => {
        if (a === undefined || a === null || !isFinite(a)) { pen = false; return; }
        if (pen) g.lineTo(x(rows[i].t), y(a, s)); else g.moveTo(x(rows[i].t), y(a, s));
        pen = true;
      });
      g.stroke();
      if (s.kind === 'steps') {  // a tick where the estimate changed (an applied adjustment)
        g.fillStyle = s.colour;
        s.values.forEach((a, i) => {
          if (a !== undefined && (i === 0 || a !== s.values[i - 1])) {
            g.fillRect(x(rows[i].t), bottom - 6, 1, 6);
          }
        });
      }
      if (s.key !== 'Th_adaptive' || !series.some((o) => o.key === 'D_c')) {
        g.fillStyle = s.colour;
        g.fillText(`${Number(s.top.toPrecision(3))} ${s.unit}`, 2, labelY);
        drawn.yLabels.push(`${s.key}: ${s.lo < 0 ? '' : '0 to '}${range(s)}`);
        labelY += 11;
      }
    });
    g.fillStyle = '#333333';
    if (series.every((s) => !(s.lo < 0))) g.fillText('0', 2, bottom);
    g.fillStyle = COLOURS.current;
    g.fillRect(x(rows[Math.min(current, rows.length - 1)].t), 0, 1, bottom);
    return drawn;
  }

  // The legend above the strip: one entry per series present, its scale in words.
  function legendHtml(series) {  // (the element's title repeats it, for a narrow window)
    const esc = PkslamLegend.esc;
    const entries = series.map((s) => {
      const mark = s.kind === 'ticks' ? `<span class="sw tick" style="background:${s.colour}"></span>`
                                      : `<span class="sw line" style="background:${s.colour}"></span>`;
      const lo = s.lo < 0 ? Number(s.lo.toPrecision(3)) : 0;
      const scale = s.kind === 'ticks' ? '' : ` (${lo} to ${Number(s.top.toPrecision(3))} ${s.unit})`;
      return `<span class="entry" data-series="${esc(s.key)}">${mark}${esc(s.name)}${scale}</span>`;
    });
    entries.push(`<span class="entry">${'<span class="sw tick" style="background:#000"></span>'}` +
                 'current frame</span>');
    const shared = series.some((s) => s.key === 'D_c') && series.some((s) => s.key === 'Th_adaptive');
    return entries.join('') + '<span class="note">lines scaled to the top values at left' +
           (shared ? ', D_c and Th_adaptive to the same' : '') + '</span>';
  }

  window.PkslamStrip = { GUTTER, THUMB, seriesOf, draw, legendHtml };
})();
