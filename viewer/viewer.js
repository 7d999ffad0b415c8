// pkslam view: draws PKSLAM_DATA (viewer/view_data.h) with three.js and the helpers of
// viewer_scene.js, viewer_legend.js and viewer_strip.js (loaded before it). Layers: the
// estimated trajectory coloured by its ATE (blue = small, red = the 95th percentile or more),
// further runs and trajectory files in their own colours, the ground truth (grey), keyframe
// frustums coloured by the rule that created them, map points, dense cloud, world axes, a
// ground grid and a scale bar; a timeline scrubber moves a marker along the trajectory and
// shows the frame's tracking state, keyframe decision and selector quantities. #status reports
// "drawn" (with the time to the first frame) or "error"; window.pkslamView describes what was
// drawn, for tests.
(function () {
  'use strict';
  const status = document.getElementById('status');
  const errors = [];
  function fail(message) {
    errors.push(String(message));
    status.dataset.state = 'error';
    status.dataset.errors = errors.join(' | ');
  }
  window.addEventListener('error', (e) => fail(e.message));
  const consoleError = console.error.bind(console);
  console.error = function (...args) { fail(args.join(' ')); consoleError(...args); };

  const D = PKSLAM_DATA;
  const S = PkslamScene;
  const RULE_COLOURS = ['#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b', '#e377c2',
                        '#17becf', '#bcbd22'];
  // Further runs and trajectory files: a categorical palette apart from the rule colours and
  // the ATE ramp (none has a top channel of 222 to 236 with another near 0).
  const TRACK_COLOURS = ['#1b9e77', '#d95f02', '#7570b3', '#e7298a', '#66a61e', '#a6761d',
                         '#1f1f1f', '#b8860b'];
  const COLOURS = { groundTruth: 0x888888, mapPoints: 0x2828c8, marker: 0xff00ff,
                    noReason: 0x555555, cloud: 0x9a9a9a };

  const container = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(container.clientWidth, container.clientHeight);
  renderer.setClearColor(0xffffff);
  container.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(50, container.clientWidth / container.clientHeight,
                                             0.01, 10000);
  const zUp = D.alignment !== 'none';
  camera.up.set(0, zUp ? 0 : -1, zUp ? 1 : 0);

  const poses = S.readPoses(D.estimate);
  const ates = poses.map((p) => p.ate).filter((a) => a >= 0).sort((a, b) => a - b);
  const ateTop = ates.length ? Math.max(1e-9, ates[Math.floor(0.95 * (ates.length - 1))]) : 0;
  function ateColour(a) {  // blue -> cyan -> green -> yellow -> red (viewer_legend.js ateRampCss)
    if (a < 0 || !ateTop) return new THREE.Color(0x1f77b4);
    const x = Math.min(1, a / ateTop);
    const c = new THREE.Color();
    c.setHSL((1 - x) * 0.66, 1.0, 0.45);
    return c;
  }

  // Layers: name -> three.js object (or {visible, element} for an overlay), one checkbox each.
  const layers = {};
  function addLayer(name, object, visible = true) {
    object.visible = visible;
    scene.add(object);
    layers[name] = object;
  }

  // Trajectories: the run's coloured by ATE, then further runs and files in their colours.
  const tracks = [];
  if (poses.length > 1) {
    addLayer('estimate', S.trajectoryLine(poses, null, (p) => ateColour(p.ate)));
    tracks.push({ label: D.title, layer: 'estimate', ate: D.ate_rmse_m, alignment: D.alignment,
                  source: 'run', colour: null, poses });
  }
  (D.tracks || []).forEach((t, i) => {
    const colour = TRACK_COLOURS[i % TRACK_COLOURS.length];
    const p = S.readPoses(t.estimate);
    const layer = `trajectory: ${t.label}`;
    addLayer(layer, S.trajectoryLine(p, new THREE.Color(colour), null));
    tracks.push({ label: t.label, layer, ate: t.ate_rmse_m, alignment: t.alignment,
                  source: t.source, colour, poses: p, keyframes: t.keyframes });
  });
  if (D.ground_truth.length >= 6) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(D.ground_truth), 3));
    addLayer('ground truth',
             new THREE.Line(g, new THREE.LineBasicMaterial({ color: COLOURS.groundTruth })));
  }

  // Scene size (for frustums, grid, axes and the initial view).
  const box = new THREE.Box3();
  tracks.forEach((t) => t.poses.forEach((p) => box.expandByPoint(p.p)));
  for (let i = 0; i + 2 < D.ground_truth.length; i += 3) {
    box.expandByPoint(new THREE.Vector3(D.ground_truth[i], D.ground_truth[i + 1],
                                        D.ground_truth[i + 2]));
  }
  D.keyframes.forEach((k) => box.expandByPoint(new THREE.Vector3(...k.p)));
  if (box.isEmpty()) box.expandByPoint(new THREE.Vector3(0, 0, 0));
  const size = Math.max(box.getSize(new THREE.Vector3()).length(), 0.1);

  // Keyframe frustums: the run's coloured by rule, further runs' in their colour (hidden at
  // first).
  const reasons = [...new Set(D.keyframes.map((k) => k.reason))].sort();
  const reasonColour = {};
  reasons.forEach((r, i) => {
    reasonColour[r] = r === '' ? COLOURS.noReason
                               : new THREE.Color(RULE_COLOURS[i % RULE_COLOURS.length]).getHex();
  });
  const counts = {};
  D.keyframes.forEach((k) => { counts[k.reason] = (counts[k.reason] || 0) + 1; });
  if (D.keyframes.length) {
    addLayer('keyframes', S.frustums(D.keyframes, 0.025 * size, (k) => reasonColour[k.reason]));
  }
  tracks.forEach((t) => {
    if (!t.keyframes || !t.keyframes.length) return;
    t.kfLayer = `keyframes: ${t.label}`;
    addLayer(t.kfLayer, S.frustums(t.keyframes, 0.025 * size, () => t.colour), false);
  });

  function pointsLayer(name, flat, colours, colour, pixels, visible) {
    if (flat.length < 3) return;
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(flat), 3));
    const m = new THREE.PointsMaterial({ size: pixels, sizeAttenuation: false });
    if (colours && colours.length === flat.length) {
      g.setAttribute('color', new THREE.BufferAttribute(
        new Float32Array(colours.map((v) => v / 255)), 3));
      m.vertexColors = true;
    } else {
      m.color = new THREE.Color(colour);
    }
    addLayer(name, new THREE.Points(g, m), visible);
  }
  pointsLayer('map points', D.map_points, null, COLOURS.mapPoints, 2, true);
  pointsLayer('dense cloud', D.cloud, D.cloud_colours, COLOURS.cloud, 1, D.cloud.length > 0);

  // Reference: world axes at the origin, a ground grid under the paths (horizontal: the x-y
  // plane with ground truth, z up; the first camera's x-z plane without, y down), a scale bar.
  const upAxis = zUp ? 2 : 1;
  const extent = box.getSize(new THREE.Vector3()).toArray().filter((_, i) => i !== upAxis);
  const gridCell = S.roundStep(Math.max(0.1, ...extent) / 8);
  addLayer('grid', S.makeGrid(box, upAxis, zUp ? 1 : -1, gridCell));
  const gridPlane = zUp ? 'horizontal (x-y plane) at the lowest point of the paths'
                        : 'in the first camera\'s x-z plane below the paths (no ground truth: ' +
                          'map frame, y down)';
  const axesLength = S.roundStep(size / 6);
  addLayer('axes', S.makeAxes(axesLength));
  const scaleBarElement = document.getElementById('scalebar');
  layers['scale bar'] = { visible: true, element: scaleBarElement };
  let scaleBarMetres = 0;

  const marker = new THREE.Mesh(new THREE.SphereGeometry(0.012 * size, 12, 8),
                                new THREE.MeshBasicMaterial({ color: COLOURS.marker }));
  scene.add(marker);
  marker.visible = poses.length > 0;
  if (poses.length) marker.position.copy(poses[0].p);

  // Initial view: the whole scene from above and aside.
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  const centre = box.getCenter(new THREE.Vector3());
  controls.target.copy(centre);
  const offset = zUp ? new THREE.Vector3(0.35, -0.7, 0.9) : new THREE.Vector3(0.35, -0.9, -0.7);
  camera.position.copy(centre).add(offset.multiplyScalar(size * 0.9));
  camera.near = size * 1e-3;
  camera.far = size * 100;
  camera.updateProjectionMatrix();
  controls.update();

  // Panel: summary, legends for every colour, a checkbox per layer (viewer_legend.js).
  const panel = document.getElementById('panel');
  panel.innerHTML = PkslamLegend.panelHtml({
    D, layers, tracks, ateTop, reasons, reasonColour, counts, axesLength, gridCell, gridPlane,
    colours: COLOURS, poses: poses.length,
  });
  panel.querySelectorAll('input[data-layer]').forEach((box) => {
    box.addEventListener('change', () => {
      const layer = layers[box.dataset.layer];
      layer.visible = box.checked;
      if (layer.element) layer.element.style.display = box.checked ? '' : 'none';
      draw();
    });
  });
  const esc = PkslamLegend.esc;

  // Timeline.
  const rows = D.timeline.length ? D.timeline
                                 : poses.map((p, i) => ({ t: p.t, frame: i, state: 'OK' }));
  const scrub = document.getElementById('scrub');
  const info = document.getElementById('frameinfo');
  scrub.max = Math.max(0, rows.length - 1);
  function poseAt(t) {  // nearest estimated pose in time (binary search)
    let lo = 0, hi = poses.length - 1;
    if (hi < 0) return null;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (poses[mid].t < t) lo = mid + 1; else hi = mid;
    }
    if (lo > 0 && Math.abs(poses[lo - 1].t - t) < Math.abs(poses[lo].t - t)) lo -= 1;
    return Math.abs(poses[lo].t - t) < 0.05 ? poses[lo] : null;
  }
  // The online calibration estimate in use at time t (the last adjustment applied before it).
  const steps = (D.calibration || []).slice().sort((a, b) => a.t - b.t);
  function calibrationAt(t) {
    let found = null;
    for (const s of steps) { if (s.t <= t) found = s; }
    return found;
  }
  function showRow(i) {
    const r = rows[i];
    if (!r) return;
    const p = poseAt(r.t);
    marker.visible = !!p;
    if (p) marker.position.copy(p.p);
    let text = `t ${(r.t - rows[0].t).toFixed(2)} s · frame ${r.frame} · ${esc(r.state)}`;
    if (r.tracked !== undefined) text += ` · ${r.tracked} tracked points`;
    if (r.kf) text += ' · <b>keyframe</b>';
    if (r.reason) text += ` · decision: ${esc(r.reason)}`;
    if (p && p.ate >= 0) text += ` · ATE ${p.ate.toFixed(3)} m`;
    const c = calibrationAt(r.t);
    if (c) {
      const e = c.e;
      const parts = [];
      if (e.time_offset !== undefined) parts.push(`time offset ${e.time_offset.toFixed(2)} ms`);
      const rot = ['imu.rx', 'imu.ry', 'imu.rz'].map((k) => e[k] || 0);
      if (e['imu.rx'] !== undefined) {
        parts.push(`camera-IMU rotation ${Math.hypot(...rot).toFixed(3)} deg off the file`);
      }
      const gyro = ['gyro.sx', 'gyro.sy', 'gyro.sz'].filter((k) => e[k] !== undefined);
      if (gyro.length) {
        parts.push(`gyro scale ${gyro.map((k) => `${k.slice(-1)} ${e[k].toFixed(2)}`).join(' ')} %`);
      }
      const accel = ['accel.sx', 'accel.sy', 'accel.sz'].filter((k) => e[k] !== undefined);
      if (accel.length) {
        parts.push(`accelerometer scale ${
            accel.map((k) => `${k.slice(-1)} ${e[k].toFixed(2)}`).join(' ')} %`);
      }
      for (const k of ['cam0.fx', 'cam0.cx', 'cam1.cx']) {
        if (e[k] !== undefined && D.calibration_file[k] !== undefined) {
          parts.push(`${k} ${(e[k] - D.calibration_file[k]) >= 0 ? '+' : ''}${(e[k] - D.calibration_file[k]).toFixed(2)} px`);
        }
      }
      text += ` · calibration (since t ${(c.t - rows[0].t).toFixed(1)} s): ${parts.join(', ')}`;
    }
    if (r.q) {
      const order = ['M_c', 'D_c', 'Th_adaptive', 'A_c', 'E_c', 'criterion1', 'criterion2',
                     'M_r', 'D_r'];
      const keys = Object.keys(r.q).sort((a, b) => {
        const ia = order.indexOf(a), ib = order.indexOf(b);
        return (ia < 0 ? 99 : ia) - (ib < 0 ? 99 : ib) || a.localeCompare(b);
      });
      text += ' · ' + keys.map((k) => `${esc(k)} ${Number(r.q[k]).toPrecision(3)}`).join(', ');
    }
    info.innerHTML = text;
  }
  // The strip above the scrubber (viewer_strip.js): the whole run against time, with a legend.
  const strip = document.getElementById('strip');
  const series = PkslamStrip.seriesOf(rows, (r) => {
    const c = calibrationAt(r.t);
    return c ? c.e.time_offset : undefined;
  });
  const stripLegend = document.getElementById('striplegend');
  stripLegend.innerHTML = PkslamStrip.legendHtml(series);
  stripLegend.title = stripLegend.textContent;
  let stripDrawn = { ticks: [], yLabels: [] };
  function drawStrip(current) { stripDrawn = PkslamStrip.draw(strip, rows, series, current); }
  scrub.addEventListener('input', () => {
    showRow(Number(scrub.value));
    drawStrip(Number(scrub.value));
    draw();
  });
  window.addEventListener('resize', () => drawStrip(Number(scrub.value)));
  drawStrip(0);
  showRow(0);

  function draw() {
    scaleBarMetres = S.updateScaleBar(scaleBarElement, camera, controls.target,
                                      container.clientHeight);
    renderer.render(scene, camera);
  }
  controls.addEventListener('change', draw);
  window.addEventListener('resize', () => {
    camera.aspect = container.clientWidth / container.clientHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(container.clientWidth, container.clientHeight);
    draw();
  });
  draw();

  // For tests and the console: what the page drew.
  window.pkslamView = {
    tracks: tracks.map((t) => ({ label: t.label, source: t.source, ate_rmse_m: t.ate,
                                 colour: t.colour, object: layers[t.layer],
                                 keyframes: t.kfLayer ? layers[t.kfLayer] : null })),
    layers,
    axes: layers.axes,
    axesLength,
    grid: layers.grid,
    gridCell,
    scaleBar: { element: scaleBarElement, metres: () => scaleBarMetres },
    strip: () => ({ ticks: stripDrawn.ticks, yLabels: stripDrawn.yLabels,
                    legend: series.map((s) => s.name) }),
    camera,
    controls,
    draw,
  };
  requestAnimationFrame(() => {
    if (status.dataset.state !== 'error') status.dataset.state = 'drawn';
    status.dataset.firstFrameMs = performance.now().toFixed(0);
  });
})();
