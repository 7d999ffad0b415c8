// pkslam view: draws PKSLAM_DATA (viewer/view_data.h) with three.js. Layers: the estimated
// trajectory coloured by its ATE (blue = small, red = the 95th percentile or more), the ground
// truth (grey), keyframe frustums coloured by the rule that created them, map points, dense
// cloud; a timeline scrubber moves a marker along the trajectory and shows the frame's
// tracking state, keyframe decision and selector quantities. #status reports "drawn" (with
// the time to the first frame) or "error" for tests.
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
  const RULE_COLOURS = ['#d62728', '#2ca02c', '#ff7f0e', '#9467bd', '#8c564b', '#e377c2',
                        '#17becf', '#bcbd22'];
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

  // Estimate: flat array t, x, y, z, qx, qy, qz, qw, ate per pose.
  const E = D.estimate;
  const poses = [];
  for (let i = 0; i + 8 < E.length; i += 9) {
    poses.push({ t: E[i], p: new THREE.Vector3(E[i + 1], E[i + 2], E[i + 3]), ate: E[i + 8] });
  }
  const ates = poses.map((p) => p.ate).filter((a) => a >= 0).sort((a, b) => a - b);
  const ateTop = ates.length ? Math.max(1e-9, ates[Math.floor(0.95 * (ates.length - 1))]) : 0;
  function ateColour(a) {  // blue -> cyan -> green -> yellow -> red
    if (a < 0 || !ateTop) return new THREE.Color(0x1f77b4);
    const x = Math.min(1, a / ateTop);
    const c = new THREE.Color();
    c.setHSL((1 - x) * 0.66, 1.0, 0.45);
    return c;
  }

  const layers = {};
  function addLayer(name, object, visible = true) {
    object.visible = visible;
    scene.add(object);
    layers[name] = object;
  }

  if (poses.length > 1) {
    const g = new THREE.BufferGeometry();
    const pos = new Float32Array(poses.length * 3);
    const col = new Float32Array(poses.length * 3);
    poses.forEach((p, i) => {
      pos.set([p.p.x, p.p.y, p.p.z], 3 * i);
      const c = ateColour(p.ate);
      col.set([c.r, c.g, c.b], 3 * i);
    });
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.BufferAttribute(col, 3));
    addLayer('estimate', new THREE.Line(g, new THREE.LineBasicMaterial({ vertexColors: true })));
  }
  if (D.ground_truth.length >= 6) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(D.ground_truth), 3));
    addLayer('ground truth',
             new THREE.Line(g, new THREE.LineBasicMaterial({ color: COLOURS.groundTruth })));
  }

  // Scene size (for frustums and the initial view).
  const box = new THREE.Box3();
  poses.forEach((p) => box.expandByPoint(p.p));
  for (let i = 0; i + 2 < D.ground_truth.length; i += 3) {
    box.expandByPoint(new THREE.Vector3(D.ground_truth[i], D.ground_truth[i + 1],
                                        D.ground_truth[i + 2]));
  }
  D.keyframes.forEach((k) => box.expandByPoint(new THREE.Vector3(...k.p)));
  if (box.isEmpty()) box.expandByPoint(new THREE.Vector3(0, 0, 0));
  const size = Math.max(box.getSize(new THREE.Vector3()).length(), 0.1);

  // Keyframe frustums, coloured by rule.
  const reasons = [...new Set(D.keyframes.map((k) => k.reason))].sort();
  const reasonColour = {};
  reasons.forEach((r, i) => {
    reasonColour[r] = r === '' ? COLOURS.noReason
                               : new THREE.Color(RULE_COLOURS[i % RULE_COLOURS.length]).getHex();
  });
  if (D.keyframes.length) {
    const s = 0.025 * size;
    const corners = [[-1, -0.75, 1.2], [1, -0.75, 1.2], [1, 0.75, 1.2], [-1, 0.75, 1.2]]
      .map((c) => new THREE.Vector3(c[0] * s, c[1] * s, c[2] * s));
    const pos = [];
    const col = [];
    D.keyframes.forEach((k) => {
      const q = new THREE.Quaternion(k.q[0], k.q[1], k.q[2], k.q[3]);
      const o = new THREE.Vector3(...k.p);
      const w = corners.map((c) => c.clone().applyQuaternion(q).add(o));
      const segs = [[o, w[0]], [o, w[1]], [o, w[2]], [o, w[3]],
                    [w[0], w[1]], [w[1], w[2]], [w[2], w[3]], [w[3], w[0]]];
      const c = new THREE.Color(reasonColour[k.reason]);
      segs.forEach(([a, b]) => {
        pos.push(a.x, a.y, a.z, b.x, b.y, b.z);
        col.push(c.r, c.g, c.b, c.r, c.g, c.b);
      });
    });
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pos), 3));
    g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(col), 3));
    addLayer('keyframes',
             new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true })));
  }

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

  // Panel: summary, legend, layer toggles.
  const panel = document.getElementById('panel');
  const esc = (s) => String(s).replace(/[&<>]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;' })[c]);
  let html = `<h1>${esc(D.title)}</h1>`;
  // The run's own warnings (degraded input, suspect estimate) come before any number.
  (D.warnings || []).forEach((w) => { html += `<div class="warning">⚠ ${esc(w)}</div>`; });
  html += `${poses.length} poses, ${D.keyframes.length} keyframes, ` +
          `${D.map_points.length / 3} map points`;
  if (D.cloud.length) html += `, ${D.cloud.length / 3} cloud points`;
  html += '<br>';
  if (D.ate_rmse_m >= 0) {
    html += `ATE ${D.ate_rmse_m.toFixed(4)} m rmse (${D.alignment}); colour: ` +
            `blue 0 → red ≥ ${ateTop.toFixed(3)} m<br>`;
  } else {
    html += 'no ground truth (map frame)<br>';
  }
  const counts = {};
  D.keyframes.forEach((k) => { counts[k.reason] = (counts[k.reason] || 0) + 1; });
  html += '<div id="legend">' + reasons.map((r) =>
    `<div><span style="background:#${new THREE.Color(reasonColour[r]).getHexString()}"></span>` +
    `${esc(r === '' ? 'no decision traced (initial map, or a run without --trace)' : r)}: ` +
    `${counts[r]}</div>`).join('') +
    '</div>';
  html += Object.keys(layers).map((n) =>
    `<label><input type="checkbox" data-layer="${esc(n)}" ${layers[n].visible ? 'checked' : ''}>` +
    ` ${esc(n)}</label>`).join('<br>');
  panel.innerHTML = html;
  panel.querySelectorAll('input[data-layer]').forEach((box) => {
    box.addEventListener('change', () => { layers[box.dataset.layer].visible = box.checked; draw(); });
  });

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
  // The timeline strip: tracked points (grey), keyframes (red ticks), and when the trace has
  // them PKS's D_c (blue) against its adaptive threshold Th_adaptive (orange), each scaled to
  // its own maximum; with online calibration its time-offset estimate (purple steps, scaled to
  // its largest value, labelled) and a purple tick at each adjustment; a black line marks the
  // current frame.
  const strip = document.getElementById('strip');
  function drawStrip(current) {
    const w = strip.clientWidth, h = strip.clientHeight;
    strip.width = w;
    strip.height = h;
    const g = strip.getContext('2d');
    g.clearRect(0, 0, w, h);
    if (rows.length < 2) return;
    const x = (i) => (i / (rows.length - 1)) * (w - 1);
    function series(value, colour) {
      const v = rows.map(value);
      const top = Math.max(...v.filter((a) => a !== undefined && isFinite(a)), 0);
      if (!(top > 0)) return;
      g.strokeStyle = colour;
      g.beginPath();
      let pen = false;
      v.forEach((a, i) => {
        if (a === undefined || !isFinite(a)) { pen = false; return; }
        const y = h - 2 - (a / top) * (h - 4);
        if (pen) g.lineTo(x(i), y); else g.moveTo(x(i), y);
        pen = true;
      });
      g.stroke();
    }
    series((r) => r.tracked, '#999999');
    series((r) => (r.q ? r.q.D_c : undefined), '#1f77b4');
    series((r) => (r.q ? r.q.Th_adaptive : undefined), '#ff7f0e');
    if (steps.length) {
      series((r) => { const c = calibrationAt(r.t); return c ? c.e.time_offset : undefined; },
             '#9467bd');
      g.fillStyle = '#9467bd';
      let last = -1;
      rows.forEach((r, i) => {
        const c = calibrationAt(r.t);
        if (c && c !== last) { g.fillRect(x(i), h - 6, 1, 6); last = c; }
      });
      const top = Math.max(...steps.map((s) => s.e.time_offset || 0));
      if (top > 0) {
        g.font = '10px sans-serif';
        g.fillText(`time offset estimate (top ${top.toFixed(2)} ms)`, 4, 11);
      }
    }
    g.fillStyle = '#d62728';
    rows.forEach((r, i) => { if (r.kf) g.fillRect(x(i), 0, 1, 6); });
    g.fillStyle = '#000000';
    g.fillRect(x(current), 0, 1, h);
  }
  scrub.addEventListener('input', () => {
    showRow(Number(scrub.value));
    drawStrip(Number(scrub.value));
    draw();
  });
  window.addEventListener('resize', () => drawStrip(Number(scrub.value)));
  drawStrip(0);
  showRow(0);

  function draw() { renderer.render(scene, camera); }
  controls.addEventListener('change', draw);
  window.addEventListener('resize', () => {
    camera.aspect = container.clientWidth / container.clientHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(container.clientWidth, container.clientHeight);
    draw();
  });
  draw();
  requestAnimationFrame(() => {
    if (status.dataset.state !== 'error') status.dataset.state = 'drawn';
    status.dataset.firstFrameMs = performance.now().toFixed(0);
  });
})();
