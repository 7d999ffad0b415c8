// pkslam run --live-view: the viewer's 3-D scene (viewer_scene.js helpers: axes, grid, lines,
// frustums, scale bar) fed while the run goes. Every POLL_MS it asks the run's server for
// /data.json?since=N (the camera poses after the N it has, the keyframes, the map points, the
// current frame's tracking state and tracked keypoints) and redraws; /frame.jpg?seq=K is the
// current left image, drawn under its tracked keypoints. #status reports "drawn" after the first
// answer, "finished" once the run has stopped tracking, "error" on a script error;
// window.pkslamLive holds what was drawn, for tests.
(function () {
  'use strict';
  const POLL_MS = 500;
  const status = document.getElementById('status');
  function fail(message) {
    status.dataset.state = 'error';
    status.dataset.errors = String(message);
  }
  window.addEventListener('error', (e) => fail(e.message));

  const S = PkslamScene;
  const container = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(container.clientWidth, container.clientHeight);
  renderer.setClearColor(0xffffff);
  container.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(50, container.clientWidth / container.clientHeight,
                                             0.01, 10000);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  const scaleBar = document.getElementById('scalebar');
  const info = document.getElementById('live-info');
  const frameCanvas = document.getElementById('frame');

  const live = { polls: 0, poses: [], keyframes: 0, points: 0, keypoints: 0, frame: -1,
                 state: '', finished: false, imageSeq: -1, framed: false };
  window.pkslamLive = live;

  // Objects replaced on each update: name -> three.js object.
  const objects = {};
  function replace(name, object) {
    if (objects[name]) {
      scene.remove(objects[name]);
      objects[name].geometry.dispose();
    }
    objects[name] = object;
    if (object) scene.add(object);
  }

  function draw() {
    S.updateScaleBar(scaleBar, camera, controls.target, container.clientHeight);
    renderer.render(scene, camera);
  }
  controls.addEventListener('change', draw);
  window.addEventListener('resize', () => {
    camera.aspect = container.clientWidth / container.clientHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(container.clientWidth, container.clientHeight);
    draw();
  });

  // The first time there is something to look at: camera up (z for gravity-aligned inertial
  // maps, -y for a visual map in the first camera's frame), view fitted to the path so far,
  // axes and a grid sized to it.
  function frameView(d) {
    const up = d.gravity_aligned ? [0, 0, 1] : [0, -1, 0];
    camera.up.set(up[0], up[1], up[2]);
    const box = new THREE.Box3();
    live.poses.forEach((p) => box.expandByPoint(p));
    const size = Math.max(1, box.getSize(new THREE.Vector3()).length());
    const centre = box.getCenter(new THREE.Vector3());
    controls.target.copy(centre);
    const back = new THREE.Vector3(up[0], up[1], up[2]).multiplyScalar(0.8 * size)
      .add(new THREE.Vector3(up[1] - up[2], up[2] - up[0], up[0] - up[1]).multiplyScalar(size));
    camera.position.copy(centre).add(back);
    controls.update();
    const span = box.clone().expandByScalar(2 * size);
    scene.add(S.makeAxes(S.roundStep(Math.max(0.2, size / 4))));
    const upIndex = d.gravity_aligned ? 2 : 1;
    const grid = S.makeGrid(span, upIndex, d.gravity_aligned ? 1 : -1,
                            S.roundStep(Math.max(0.1, size / 10)));
    if (grid) scene.add(grid);
    live.framed = true;
  }

  function update(d) {
    for (let i = 0; i + 2 < d.poses.length; i += 3) {
      live.poses.push(new THREE.Vector3(d.poses[i], d.poses[i + 1], d.poses[i + 2]));
    }
    if (live.poses.length > 1) {
      replace('trajectory', S.trajectoryLine(live.poses.map((p) => ({ p })),
                                             new THREE.Color(0x1f77b4), null));
    }
    const keyframes = [];
    for (let i = 0; i + 6 < d.keyframes.length; i += 7) {
      const k = d.keyframes;
      keyframes.push({ p: [k[i], k[i + 1], k[i + 2]], q: [k[i + 3], k[i + 4], k[i + 5], k[i + 6]] });
    }
    const depth = Math.max(0.05, 0.02 * (objects.trajectory
      ? new THREE.Box3().setFromObject(objects.trajectory).getSize(new THREE.Vector3()).length()
      : 1));
    replace('keyframes', keyframes.length ? S.frustums(keyframes, depth, () => '#d62728') : null);
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(d.points), 3));
    replace('points', new THREE.Points(g, new THREE.PointsMaterial({ color: 0x2828c8, size: 2,
                                                                     sizeAttenuation: false })));
    live.keyframes = keyframes.length;
    live.points = d.points.length / 3;
    live.keypoints = d.keypoints.length / 2;
    live.frame = d.frame;
    live.state = d.state;
    live.finished = d.finished;
    if (!live.framed && live.poses.length > 5) frameView(d);
    info.textContent = `frame ${d.frame} (t ${d.t_s.toFixed(2)} s) · ${d.state} · ` +
      `${live.poses.length} poses · ${live.keyframes} keyframes · ${live.points} map points` +
      (d.finished ? ' · run finished' : '');
    if (d.image_seq !== live.imageSeq) drawFrame(d);
    draw();
  }

  // The current left image with its tracked keypoints (green: pose inliers).
  function drawFrame(d) {
    live.imageSeq = d.image_seq;
    const image = new Image();
    image.onload = () => {
      const scale = frameCanvas.clientHeight / image.height;
      frameCanvas.width = Math.round(image.width * scale);
      frameCanvas.height = frameCanvas.clientHeight;
      const ctx = frameCanvas.getContext('2d');
      ctx.drawImage(image, 0, 0, frameCanvas.width, frameCanvas.height);
      ctx.fillStyle = '#00c000';
      for (let i = 0; i + 1 < d.keypoints.length; i += 2) {
        ctx.fillRect(d.keypoints[i] * scale - 1.5, d.keypoints[i + 1] * scale - 1.5, 3, 3);
      }
    };
    image.src = `frame.jpg?seq=${d.image_seq}`;
  }

  function poll() {
    fetch(`data.json?since=${live.poses.length}`)
      .then((r) => { if (!r.ok) throw new Error(`data.json: HTTP ${r.status}`); return r.json(); })
      .then((d) => {
        update(d);
        live.polls += 1;
        status.dataset.poses = String(live.poses.length);
        status.dataset.polls = String(live.polls);
        if (status.dataset.state !== 'error') status.dataset.state = d.finished ? 'finished' : 'drawn';
        setTimeout(poll, POLL_MS);
      })
      .catch((e) => {
        // The run has ended and its server with it: keep what is drawn.
        info.textContent += ' · connection closed';
        status.dataset.closed = String(e);
      });
  }
  draw();
  poll();
})();
