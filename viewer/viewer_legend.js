// pkslam view: the legend panel for viewer.js. Names every colour of the 3-D view (the ATE ramp
// with its numbers, the other trajectories, ground truth, keyframe rules with what each rule
// means, points, axes, grid, scale bar) and puts a checkbox beside each layer. Defines
// window.PkslamLegend and draws nothing by itself.
(function () {
  'use strict';

  // What each keyframe reason name of keyframe_trace.csv means (keyframe/*.cc; the numbers are
  // the selectors' defaults, docs/keyframe_selectors.md). A reason joins the rules that fired
  // with '+' ("c1b+c2") and tracking's notes with ';' ("no;starving").
  const RULE_GLOSS = {
    'imu-uninit-time': 'IMU not initialised yet: a keyframe every 0.25 s (every selector)',
    starving: 'tracking held so few points that it inserted the keyframe anyway',
    busy: 'local mapping was busy when the rule fired',
    no: 'no rule fired',
    c1a: 'ORB-SLAM3: the most frames allowed since the last keyframe (fps) have passed',
    c1b: 'ORB-SLAM3: the fewest frames have passed and local mapping is idle',
    c1c: 'ORB-SLAM3: weak tracking without IMU, stereo/RGB-D (under 1/4 of the reference ' +
         'keyframe\'s points, or too few close points)',
    c2: 'ORB-SLAM3: fewer points tracked than 3/4 of the reference keyframe\'s (monocular: ' +
        '9/10), or too few close points, with more than 15 tracked',
    c3: 'ORB-SLAM3: 0.5 s since the last keyframe (inertial)',
    c4: 'ORB-SLAM3: weak mono-inertial tracking (16 to 74 points, or recently lost)',
    close: 'too few close stereo points tracked (under 100 tracked, over 70 untracked; PKS ' +
           'also waits for idle local mapping)',
    camera: 'PKS camera criterion: enough points changed their viewing-angle region ' +
            '(D_c > Th_adaptive) and the changed points spread over the image (ECOG > |COG|)',
    imu: 'PKS IMU criterion: the mean acceleration changed by more than 1 m/s² (pks: ' +
         'gravity-free, since the keyframe; pks-released: since the previous frame)',
    forced: 'pks-released: the forced keyframe, every 6th frame after the last one',
    time: 'PKS interval: 0.5 s (inertial) or 1 s (visual only) since the last keyframe',
    'weak-mono-inertial': 'PKS: weak mono-inertial tracking (16 to 74 points, or recently lost)',
    weak: 'PKS, visual only: under 1/4 of the reference keyframe\'s points tracked',
    interval: 'interval selector: every 10 frames (or the set seconds)',
    ptam: 'PTAM rule: at least 20 frames and moved over 0.1 × the median scene depth',
    matches: 'match-count selector: fewer than 400 points matched to the last keyframe',
    parallax: 'VINS-Mono rule: mean parallax to the last keyframe of 10 px or more (focal 460)',
    'few-tracked': 'VINS-Mono rule: under 20 features tracked, or none shared with the ' +
                   'last keyframe',
  };
  const NO_REASON = 'no decision traced (the initial map\'s keyframe, or a run without --trace)';

  // The rule names a reason joins: "c1b+c2" -> ['c1b', 'c2'], "no;starving" -> ['no',
  // 'starving'], '' -> [''].
  const ruleParts = (reason) => (reason === '' ? [''] : reason.split(/[+;]/));

  // What one rule name means ('' : no decision traced; unknown names say so).
  const partGloss = (part) => (part === '' ? NO_REASON
    : RULE_GLOSS[part] || '(no description: a rule this page does not know)');

  // "c1b+c2" -> "c1b: ...; c2: ...": every part glossed.
  function ruleGloss(reason) {
    return ruleParts(reason).map((part) => `${part || 'none'}: ${partGloss(part)}`).join('; ');
  }

  // The ATE ramp (viewer.js ateColour: hue 0.66 -> 0 at 100% saturation, 45% lightness) as a
  // CSS gradient.
  function ateRampCss() {
    const stops = [0, 0.25, 0.5, 0.75, 1].map((x) =>
      `hsl(${((1 - x) * 0.66 * 360).toFixed(1)}, 100%, 45%) ${(x * 100).toFixed(0)}%`);
    return `linear-gradient(to right, ${stops.join(', ')})`;
  }

  const esc = (s) => String(s).replace(/[&<>"]/g, (c) =>
    ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]);
  const hex = (c) => '#' + new THREE.Color(c).getHexString();
  const swatch = (colour, shape) =>
    `<span class="sw ${shape || ''}" style="background:${colour}"></span>`;
  const toggle = (layer, on) =>
    `<input type="checkbox" data-layer="${esc(layer)}"${on ? ' checked' : ''}>`;
  const ateText = (ate, alignment) =>
    (ate >= 0 ? `ATE ${ate.toFixed(4)} m rmse (${esc(alignment)})` : 'no ground truth');

  // The panel's HTML. `v` holds what viewer.js drew: D (the data), layers (name -> object or
  // element), tracks [{label, layer, kfLayer, colour, ate, alignment, source}], ateTop,
  // reasons, reasonColour, counts, axesLength, gridCell, gridPlane, colours.
  function panelHtml(v) {
    const D = v.D;
    const L = v.layers;
    let html = `<h1>${esc(D.title)}</h1>`;
    // The run's own warnings (degraded input, suspect estimate) come before any number.
    (D.warnings || []).forEach((w) => { html += `<div class="warning">⚠ ${esc(w)}</div>`; });
    html += `<div>${v.poses} poses, ${D.keyframes.length} keyframes, ` +
            `${D.map_points.length / 3} map points` +
            (D.cloud.length ? `, ${D.cloud.length / 3} cloud points` : '') + '</div>';

    html += '<div class="sec">Trajectories</div>';
    v.tracks.forEach((t, i) => {
      // The run's line: the ATE ramp, or one blue without ground truth (viewer.js ateColour).
      const mark = i > 0 ? swatch(t.colour, 'line')
        : t.ate >= 0 ? `<span class="sw ramp" style="background:${ateRampCss()}"></span>`
          : swatch('#1f77b4', 'line');
      html += `<div class="track-row" data-track="${i}"><label>${toggle(t.layer, true)} ` +
              `${mark}<b>${esc(t.label)}</b></label>: ${ateText(t.ate, t.alignment)}` +
              (t.source === 'trajectory' ? ', trajectory file' : '') +
              (t.kfLayer ? ` <label class="sub">${toggle(t.kfLayer, L[t.kfLayer].visible)}` +
                           ` its ${t.keyframes.length} keyframes</label>` : '') + '</div>';
      if (i === 0 && v.ateTop > 0) {
        html += `<div class="sub">colour = each pose's ATE: <span class="ramp-bar" ` +
                `style="background:${ateRampCss()}"></span><br><span class="ramp-ticks">` +
                `<span>0</span><span>${(v.ateTop / 2).toFixed(3)}</span>` +
                `<span>≥ ${v.ateTop.toFixed(3)} m</span></span><br>` +
                '(red: the 95th percentile or more)</div>';
      }
    });
    if (L['ground truth']) {
      html += `<div><label>${toggle('ground truth', true)} ` +
              `${swatch(hex(v.colours.groundTruth), 'line')}ground truth</label> (grey: the path ` +
              'the run is compared with)</div>';
    }

    if (L.keyframes) {
      html += `<div class="sec">Keyframes${D.selector ? ` (selector ${esc(D.selector)})` : ''}` +
              '</div>';
      html += `<div><label>${toggle('keyframes', true)} ${D.keyframes.length} frustums, ` +
              'coloured by the rule that created them:</label></div><div id="legend">';
      v.reasons.forEach((r) => {
        html += `<span class="rule" title="${esc(ruleGloss(r))}">${swatch(hex(v.reasonColour[r]))}` +
                `<b>${esc(r === '' ? 'none' : r)}</b>: ${v.counts[r]}</span> `;
      });
      // Each rule name once, in words (a reason joins the rules that fired).
      const parts = [...new Set(v.reasons.flatMap(ruleParts))];
      html += '</div><details open><summary>what the rules mean</summary>' +
              parts.map((p) => `<div class="gloss"><b>${esc(p === '' ? 'none' : p)}</b>: ` +
                                `${esc(partGloss(p))}</div>`).join('') +
              (v.reasons.some((r) => /[+;]/.test(r))
                ? '<div class="gloss">a + joins rules that fired together; after a ; comes ' +
                  'what tracking noted</div>' : '') +
              '</details>';
    }

    if (L['map points'] || L['dense cloud']) html += '<div class="sec">Points</div>';
    if (L['map points']) {
      html += `<div><label>${toggle('map points', true)} ${swatch(hex(v.colours.mapPoints), 'dot')}` +
              `map points</label> (${D.map_points.length / 3})</div>`;
    }
    if (L['dense cloud']) {
      const own = D.cloud_colours.length === D.cloud.length;
      html += `<div><label>${toggle('dense cloud', L['dense cloud'].visible)} ` +
              `${swatch(own ? 'linear-gradient(#b08060,#6080a0)' : hex(v.colours.cloud), 'dot')}` +
              `dense cloud</label> (${D.cloud.length / 3} points, ` +
              `${own ? 'in their own colours' : 'grey'})</div>`;
    }

    html += '<div class="sec">Reference</div>';
    html += `<div><label>${toggle('axes', true)} axes</label>: <span style="color:#ff0000">x</span>` +
            ` <span style="color:#00b000">y</span> <span style="color:#0000ff">z</span>, ` +
            `${PkslamScene.metresText(v.axesLength)} long, at the world origin</div>`;
    html += `<div><label>${toggle('grid', true)} grid</label>: ` +
            `${PkslamScene.metresText(v.gridCell)} cells, ${v.gridPlane}</div>`;
    html += `<div><label>${toggle('scale bar', true)} scale bar</label> (lower right): a length ` +
            'at the distance of the orbit centre</div>';
    html += `<div>${swatch(hex(v.colours.marker), 'dot')}the timeline's current frame</div>`;
    html += '<div class="hint">drag: orbit · right-drag: pan · wheel: zoom</div>';
    return html;
  }

  window.PkslamLegend = { RULE_GLOSS, ruleParts, ruleGloss, ateRampCss, panelHtml, esc };
})();
