// pkslam view: scene helpers for viewer.js (three.js r111). Builds the world axes, the ground
// grid, lines for trajectories, keyframe frustums, and keeps the scale bar up to date. Defines
// window.PkslamScene and draws nothing by itself.
(function () {
  'use strict';

  // The largest 1, 2 or 5 x 10^k not above x (x > 0): grid cells, axes, scale bar, time ticks.
  function roundStep(x) {
    const p = Math.pow(10, Math.floor(Math.log10(x)));
    for (const m of [5, 2, 1]) { if (m * p <= x) return m * p; }
    return p;
  }

  // A length in metres as a person would write it: "0.2 m", "5 m", "0.05 m".
  function metresText(m) { return `${Number(m.toPrecision(3))} m`; }

  // Axis colours: x red, y green, z blue (pure colours: none of the ATE ramp's, the keyframe
  // rules' or the map points' colours, so the screenshot test can still tell those apart).
  const AXIS_COLOURS = [0xff0000, 0x00b000, 0x0000ff];

  function textSprite(text, colour, height) {
    const canvas = document.createElement('canvas');
    canvas.width = 64;
    canvas.height = 64;
    const g = canvas.getContext('2d');
    g.font = 'bold 48px sans-serif';
    g.textAlign = 'center';
    g.textBaseline = 'middle';
    g.fillStyle = '#' + new THREE.Color(colour).getHexString();
    g.fillText(text, 32, 34);
    const material = new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(canvas),
                                                depthTest: false, transparent: true });
    const sprite = new THREE.Sprite(material);
    sprite.scale.set(height, height, 1);
    return sprite;
  }

  // World axes at the origin, `length` metres long, each labelled at its end.
  function makeAxes(length) {
    const group = new THREE.Group();
    const pos = [];
    const col = [];
    ['x', 'y', 'z'].forEach((name, i) => {
      const end = [0, 0, 0];
      end[i] = length;
      const c = new THREE.Color(AXIS_COLOURS[i]);
      pos.push(0, 0, 0, ...end);
      col.push(c.r, c.g, c.b, c.r, c.g, c.b);
      const label = textSprite(name, AXIS_COLOURS[i], 0.25 * length);
      label.position.set(end[0] * 1.15, end[1] * 1.15, end[2] * 1.15);
      group.add(label);
    });
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pos), 3));
    g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(col), 3));
    group.add(new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true })));
    return group;
  }

  // A ground grid under the scene's box: horizontal (perpendicular to `up`, the index of the
  // world's up axis, with `upSign` its direction) at the box's lowest point, cells of `cell`
  // metres, covering the box with a cell to spare.
  function makeGrid(box, up, upSign, cell) {
    const [a, b] = [0, 1, 2].filter((i) => i !== up);
    const lo = box.min.toArray();
    const hi = box.max.toArray();
    const level = upSign > 0 ? lo[up] : hi[up];
    const a0 = Math.floor(lo[a] / cell) * cell - cell, a1 = Math.ceil(hi[a] / cell) * cell + cell;
    const b0 = Math.floor(lo[b] / cell) * cell - cell, b1 = Math.ceil(hi[b] / cell) * cell + cell;
    const pos = [];
    const point = (u, v) => { const p = [0, 0, 0]; p[a] = u; p[b] = v; p[up] = level; return p; };
    for (let u = a0; u <= a1 + cell / 2; u += cell) pos.push(...point(u, b0), ...point(u, b1));
    for (let v = b0; v <= b1 + cell / 2; v += cell) pos.push(...point(a0, v), ...point(a1, v));
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pos), 3));
    return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0xdddddd }));
  }

  // Flat pose array (t, x, y, z, qx, qy, qz, qw, ate per pose; view_data.h) to objects.
  function readPoses(flat) {
    const poses = [];
    for (let i = 0; i + 8 < flat.length; i += 9) {
      poses.push({ t: flat[i], p: new THREE.Vector3(flat[i + 1], flat[i + 2], flat[i + 3]),
                   ate: flat[i + 8] });
    }
    return poses;
  }

  // A polyline through the poses: one colour, or colourOf(pose) per vertex.
  function trajectoryLine(poses, colour, colourOf) {
    const g = new THREE.BufferGeometry();
    const pos = new Float32Array(poses.length * 3);
    poses.forEach((p, i) => pos.set([p.p.x, p.p.y, p.p.z], 3 * i));
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    if (!colourOf) return new THREE.Line(g, new THREE.LineBasicMaterial({ color: colour }));
    const col = new Float32Array(poses.length * 3);
    poses.forEach((p, i) => { const c = colourOf(p); col.set([c.r, c.g, c.b], 3 * i); });
    g.setAttribute('color', new THREE.BufferAttribute(col, 3));
    return new THREE.Line(g, new THREE.LineBasicMaterial({ vertexColors: true }));
  }

  // Keyframe frustums `s` metres deep, each coloured colourOf(keyframe).
  function frustums(keyframes, s, colourOf) {
    const corners = [[-1, -0.75, 1.2], [1, -0.75, 1.2], [1, 0.75, 1.2], [-1, 0.75, 1.2]]
      .map((c) => new THREE.Vector3(c[0] * s, c[1] * s, c[2] * s));
    const pos = [];
    const col = [];
    keyframes.forEach((k) => {
      const q = new THREE.Quaternion(k.q[0], k.q[1], k.q[2], k.q[3]);
      const o = new THREE.Vector3(...k.p);
      const w = corners.map((c) => c.clone().applyQuaternion(q).add(o));
      const segs = [[o, w[0]], [o, w[1]], [o, w[2]], [o, w[3]],
                    [w[0], w[1]], [w[1], w[2]], [w[2], w[3]], [w[3], w[0]]];
      const c = new THREE.Color(colourOf(k));
      segs.forEach(([a, b]) => {
        pos.push(a.x, a.y, a.z, b.x, b.y, b.z);
        col.push(c.r, c.g, c.b, c.r, c.g, c.b);
      });
    });
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pos), 3));
    g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(col), 3));
    return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true }));
  }

  // The scale bar: a round length whose bar is 60 to 150 pixels long at the distance of the
  // orbit centre (controls.target), recomputed on every camera change. Returns its length (m).
  function updateScaleBar(element, camera, target, heightPx) {
    const d = camera.position.distanceTo(target);
    const metresPerPx = (2 * d * Math.tan((camera.fov * Math.PI) / 360)) / Math.max(1, heightPx);
    const length = roundStep(150 * metresPerPx);
    element.querySelector('#scalebar-bar').style.width = `${(length / metresPerPx).toFixed(0)}px`;
    element.querySelector('#scalebar-text').textContent = metresText(length);
    return length;
  }

  window.PkslamScene = { roundStep, metresText, AXIS_COLOURS, makeAxes, makeGrid, readPoses,
                         trajectoryLine, frustums, updateScaleBar };
})();
