// The 3D viewer of a scene's page in the linkage report: reads the run from the JSON of
// <script id="viewer-data"> (see src/render/viewer/data.rs) and draws it with three.js
// (THREE, pasted into the page before this script). Orbit, zoom and pan; a slider and
// play/pause through the frames; colours by member stress or stress ratio with their scale;
// obstacles where they are at each frame; contact forces as arrows and broken members in red
// (toggles). 2D scenes are drawn flat (pan and zoom, no orbit). Without WebGL it says so and
// leaves the PNG frames below as the pictures. `window.linkageViewer` lets a test drive it.
(function () {
  'use strict';
  const root = document.getElementById('viewer');
  const note = document.getElementById('viewer-note');
  const data = JSON.parse(document.getElementById('viewer-data').textContent);
  const say = (text) => { note.textContent = text; };

  const probe = document.createElement('canvas');
  if (typeof THREE === 'undefined' || !(probe.getContext('webgl2') || probe.getContext('webgl'))) {
    say('This browser cannot draw WebGL, so there is no 3D view here: the frames below show the run.');
    root.classList.add('no-webgl');
    window.linkageViewer = { ready: true, webgl: false };
    return;
  }

  const buffer = (b64) => {
    const s = atob(b64);
    const a = new Uint8Array(s.length);
    for (let i = 0; i < s.length; i++) a[i] = s.charCodeAt(i);
    return a.buffer;
  };
  const f32 = (b64) => new Float32Array(buffer(b64));
  const u32 = (b64) => new Uint32Array(buffer(b64));
  // A list of per-frame arrays where null repeats the previous frame's.
  const perFrame = (list, decode) => {
    let last = null;
    return list.map((x) => (x === null ? last : (last = decode(x))));
  };

  // The pictures' colour scales: diverging for stress, grey to red for the ratio (black at
  // and beyond the strength, as overloaded members are drawn).
  const DIVERGING = [[0, [40, 60, 175]], [0.25, [110, 150, 235]], [0.5, [185, 185, 190]],
    [0.75, [235, 130, 100]], [1, [170, 10, 35]]];
  const RATIO = [[0, [185, 185, 190]], [0.5, [235, 170, 60]], [1, [170, 10, 35]]];
  const ramp = (stops, t) => {
    t = Math.min(1, Math.max(0, t));
    for (let i = 1; i < stops.length; i++) {
      const [t1, c1] = stops[i];
      if (t <= t1) {
        const [t0, c0] = stops[i - 1];
        const u = (t - t0) / (t1 - t0);
        return c0.map((c, k) => (c + (c1[k] - c) * u) / 255);
      }
    }
    return stops[stops.length - 1][1].map((c) => c / 255);
  };
  const stressLimit = data.stressLimit > 0 ? data.stressLimit : 1;
  const ratioLimit = data.ratioLimit || 1;
  const PLAIN_LINE = [0.38, 0.41, 0.46];
  const PLAIN_SURFACE = [0.70, 0.75, 0.82];
  let mode = 'stress';
  const colourOf = (value, ratio, surface) => {
    if (mode === 'ratio' && ratio !== undefined) {
      return ratio >= 1 ? [0, 0, 0] : ramp(RATIO, ratio);
    }
    if (mode === 'plain' || (mode === 'ratio' && ratio === undefined)) {
      return surface ? PLAIN_SURFACE : PLAIN_LINE;
    }
    return ramp(DIVERGING, value / stressLimit * 0.5 + 0.5);
  };

  const n = data.frames.length;
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xffffff);
  const box = { lo: [Infinity, Infinity, Infinity], hi: [-Infinity, -Infinity, -Infinity] };
  const grow = (p) => {
    for (let i = 0; i + 2 < p.length; i += 3) {
      for (let k = 0; k < 3; k++) {
        box.lo[k] = Math.min(box.lo[k], p[i + k]);
        box.hi[k] = Math.max(box.hi[k], p[i + k]);
      }
    }
  };

  const bodies = data.bodies.map((b) => {
    const index = u32(b.index);
    const positions = perFrame(b.positions, f32);
    positions.forEach(grow);
    const body = {
      surface: b.surface,
      index,
      positions,
      stress: perFrame(b.stress, f32),
      ratio: b.ratio ? perFrame(b.ratio, f32) : null,
      broken: perFrame(b.broken, u32),
      contacts: b.contacts.map(f32),
    };
    const geometry = new THREE.BufferGeometry();
    const places = b.surface ? positions[0].length / 3 : index.length;
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(places * 3), 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(places * 3), 3));
    if (b.surface) {
      geometry.setIndex(new THREE.BufferAttribute(index, 1));
      body.object = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial(
        { vertexColors: true, side: THREE.DoubleSide }));
    } else {
      body.object = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true }));
    }
    body.cracks = new THREE.LineSegments(new THREE.BufferGeometry(),
      new THREE.LineBasicMaterial({ color: 0xd00000, depthTest: false }));
    body.cracks.renderOrder = 2;
    body.arrows = new THREE.LineSegments(new THREE.BufferGeometry(),
      new THREE.LineBasicMaterial({ color: 0xeb7800, depthTest: false }));
    body.arrows.renderOrder = 3;
    scene.add(body.object, body.cracks, body.arrows);
    return body;
  });
  if (!isFinite(box.lo[0])) {
    box.lo = [-1, -1, -1];
    box.hi = [1, 1, 1];
  }
  const centre = box.lo.map((l, k) => (l + box.hi[k]) / 2);
  const size = Math.max(1e-9, Math.hypot(...box.hi.map((h, k) => h - box.lo[k])));
  const radius = size / 2;
  const arrowScale = data.maxContact > 0 ? 0.15 * size / data.maxContact : 0;

  const obstacles = data.obstacles.map((o) => {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(f32(o.vertices), 3));
    geometry.setIndex(new THREE.BufferAttribute(u32(o.index), 1));
    geometry.computeVertexNormals();
    const mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({
      color: 0xbeb4a0, transparent: true, opacity: 0.4, side: THREE.DoubleSide, depthWrite: false,
    }));
    scene.add(mesh);
    return { mesh, offsets: o.offsets };
  });

  const width = Math.max(320, Math.min(root.clientWidth || 960, 1280));
  const height = Math.round(width * 0.5625);
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    say('WebGL could not start here (' + e.message + '): the frames below show the run.');
    window.linkageViewer = { ready: true, webgl: false };
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(width, height);
  document.getElementById('viewer-canvas').appendChild(renderer.domElement);

  // The scene's up (+y unless model.json says otherwise): the camera's x and z of a y-up
  // scene are turned with it (the rotation taking +y onto up, Rodrigues' formula).
  const up = (data.up || [0, 1, 0]).slice();
  const upLength = Math.hypot(...up) || 1;
  for (let k = 0; k < 3; k++) up[k] /= upLength;
  const fromY = (v) => {
    const axis = [up[2], 0, -up[0]]; // (0, 1, 0) × up
    const s = Math.hypot(...axis);
    const c = up[1];
    if (s < 1e-12) return c > 0 ? v : [v[0], -v[1], -v[2]];
    const k = axis.map((a) => a / s);
    const kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    const cross = [k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]];
    return [0, 1, 2].map((i) => v[i] * c + cross[i] * s + k[i] * kv * (1 - c));
  };
  let camera;
  if (data.is3d) {
    camera = new THREE.PerspectiveCamera(35, width / height, radius / 100, radius * 100);
    const az = 35 * Math.PI / 180;
    const el = 25 * Math.PI / 180;
    const d = 1.15 * radius / Math.sin(17.5 * Math.PI / 180);
    const ex = fromY([1, 0, 0]);
    const ez = fromY([0, 0, 1]);
    const along = [0, 1, 2].map((i) => d * (Math.sin(az) * Math.cos(el) * ex[i] +
      Math.sin(el) * up[i] + Math.cos(az) * Math.cos(el) * ez[i]));
    camera.up.set(up[0], up[1], up[2]);
    camera.position.set(centre[0] + along[0], centre[1] + along[1], centre[2] + along[2]);
  } else {
    const half = 0.6 * Math.max(box.hi[0] - box.lo[0], (box.hi[1] - box.lo[1]) * width / height, 1e-9);
    const halfH = half * height / width;
    camera = new THREE.OrthographicCamera(-half, half, halfH, -halfH, -100 * size, 100 * size);
    camera.position.set(centre[0], centre[1], centre[2] + 4 * size);
    // A 2D scene seen from +z, turned so that its up (in its plane) points up.
    if (Math.abs(up[2]) < 1e-9) camera.up.set(up[0], up[1], 0);
  }
  scene.add(camera);
  scene.add(new THREE.AmbientLight(0xffffff, 1.6));
  const light = new THREE.DirectionalLight(0xffffff, 2.2);
  light.position.set(0.4, 0.8, 1);
  camera.add(light);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.set(centre[0], centre[1], centre[2]);
  if (!data.is3d) controls.enableRotate = false;
  controls.update();
  const draw = () => renderer.render(scene, camera);
  controls.addEventListener('change', draw);

  const show = { contacts: true, broken: true, obstacles: true };
  let current = 0;

  const setFrame = (k) => {
    k = Math.max(0, Math.min(n - 1, k | 0));
    current = k;
    bodies.forEach((b) => {
      const p = b.positions[k];
      const stress = b.stress[k];
      const ratio = b.ratio ? b.ratio[k] : null;
      const geometry = b.object.geometry;
      const pos = geometry.attributes.position.array;
      const col = geometry.attributes.color.array;
      if (b.surface) {
        pos.set(p);
        for (let v = 0; v < p.length / 3; v++) {
          col.set(colourOf(stress[v], ratio ? ratio[v] : undefined, true), 3 * v);
        }
        geometry.computeVertexNormals();
      } else {
        const broken = new Set();
        const cut = b.broken[k];
        for (let i = 0; i + 1 < cut.length; i += 2) broken.add(cut[i] + ',' + cut[i + 1]);
        for (let m = 0; m < b.index.length / 2; m++) {
          const a = b.index[2 * m];
          const c = b.index[2 * m + 1];
          const gone = broken.has(a + ',' + c);
          for (let k2 = 0; k2 < 3; k2++) {
            pos[6 * m + k2] = p[3 * a + k2];
            pos[6 * m + 3 + k2] = gone ? p[3 * a + k2] : p[3 * c + k2];
          }
          const colour = colourOf(stress[m], ratio ? ratio[m] : undefined, false);
          col.set(colour, 6 * m);
          col.set(colour, 6 * m + 3);
        }
      }
      geometry.attributes.position.needsUpdate = true;
      geometry.attributes.color.needsUpdate = true;
      geometry.computeBoundingSphere();
      // Broken members, in red where their nodes are now.
      const cut = b.broken[k];
      const cracks = new Float32Array(cut.length * 3);
      for (let i = 0; i < cut.length; i++) cracks.set(p.subarray(3 * cut[i], 3 * cut[i] + 3), 3 * i);
      b.cracks.geometry.setAttribute('position', new THREE.BufferAttribute(cracks, 3));
      b.cracks.geometry.computeBoundingSphere();
      b.cracks.visible = show.broken && cut.length > 0;
      // Contact forces: an arrow to each node, from where the force comes.
      const c = b.contacts[k];
      const lines = [];
      for (let i = 0; i + 5 < c.length; i += 6) {
        const tip = [c[i], c[i + 1], c[i + 2]];
        const f = [c[i + 3], c[i + 4], c[i + 5]].map((x) => x * arrowScale);
        const len = Math.hypot(...f);
        if (!(len > 0)) continue;
        const tail = tip.map((x, j) => x - f[j]);
        const u = f.map((x) => x / len);
        // A direction across the arrow: in the view plane in 2D, else any perpendicular.
        let side = [-u[1], u[0], 0];
        if (Math.hypot(...side) < 1e-6) side = [1, 0, 0];
        const s = Math.hypot(...side);
        const head = 0.25 * len;
        lines.push(...tail, ...tip);
        for (const sign of [1, -1]) {
          lines.push(...tip, ...tip.map((x, j) => x - head * u[j] + sign * 0.5 * head * side[j] / s));
        }
      }
      b.arrows.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(lines), 3));
      b.arrows.geometry.computeBoundingSphere();
      b.arrows.visible = show.contacts && lines.length > 0;
    });
    obstacles.forEach((o) => {
      const d = o.offsets[k] || [0, 0, 0];
      o.mesh.position.set(d[0], d[1], d[2]);
      o.mesh.visible = show.obstacles;
    });
    const f = data.frames[k];
    const when = data.timed ? 't = ' + si(f.time, 's') : (data.loadName || 'load factor') + ' ' + f.load_factor.toPrecision(3);
    document.getElementById('viewer-label').textContent =
      'step ' + f.step + ' (' + (k + 1) + ' of ' + n + '), ' + when;
    slider.value = String(k);
    draw();
  };

  const si = (v, unit) => {
    if (!(v !== 0 && isFinite(v))) return '0 ' + unit;
    const prefixes = [[1e12, 'T'], [1e9, 'G'], [1e6, 'M'], [1e3, 'k'], [1, ''], [1e-3, 'm'], [1e-6, 'µ'], [1e-9, 'n']];
    const [f, p] = prefixes.find(([f]) => Math.abs(v) >= f) || [1e-9, 'n'];
    return (v / f).toPrecision(3) + ' ' + p + unit;
  };

  const scale = document.getElementById('viewer-scale');
  const drawScale = () => {
    const stops = mode === 'ratio' ? RATIO : DIVERGING;
    const css = stops.map(([t, c]) => 'rgb(' + c.join(',') + ') ' + (100 * t) + '%').join(', ');
    const labels = mode === 'ratio'
      ? ['0', 'stress ratio |σ| / strength', '1 and above: black']
      : mode === 'plain' ? [] : ['−' + si(stressLimit, 'Pa') + ' (compression)', '0', '+' + si(stressLimit, 'Pa') + ' (tension)'];
    scale.innerHTML = '';
    if (!labels.length) return;
    const bar = document.createElement('div');
    bar.className = 'viewer-bar';
    bar.style.background = 'linear-gradient(to right, ' + css + ')';
    const text = document.createElement('div');
    text.className = 'viewer-ticks';
    labels.forEach((l) => {
      const s = document.createElement('span');
      s.textContent = l;
      text.appendChild(s);
    });
    scale.append(bar, text);
  };

  const slider = document.getElementById('viewer-slider');
  slider.max = String(n - 1);
  slider.addEventListener('input', () => { stop(); setFrame(Number(slider.value)); });
  const play = document.getElementById('viewer-play');
  let timer = null;
  const stop = () => {
    if (timer !== null) clearInterval(timer);
    timer = null;
    play.textContent = 'play';
  };
  play.addEventListener('click', () => {
    if (timer !== null) return stop();
    if (current >= n - 1) setFrame(0);
    play.textContent = 'pause';
    timer = setInterval(() => {
      if (current >= n - 1) return stop();
      setFrame(current + 1);
    }, 100);
  });
  const colour = document.getElementById('viewer-colour');
  if (!data.ratioLimit) colour.querySelector('option[value=ratio]').remove();
  colour.addEventListener('change', () => { mode = colour.value; drawScale(); setFrame(current); });
  for (const name of ['contacts', 'broken', 'obstacles']) {
    const check = document.getElementById('viewer-' + name);
    check.addEventListener('change', () => { show[name] = check.checked; setFrame(current); });
  }
  const notes = ['Drag to turn' + (data.is3d ? '' : ' (a 2D scene: flat)') +
    ', right-drag or shift-drag to pan, wheel to zoom.'];
  if (data.magnification !== 1) notes.push('Displacements drawn ×' + data.magnification + '.');
  if (data.frames.length < data.stored) {
    notes.push('A large run: ' + n + ' of its ' + data.stored +
      ' stored steps are shown (evenly spaced, the first and the last kept), surfaces only.');
  }
  say(notes.join(' '));
  drawScale();
  setFrame(0);

  // For tests: the pixels of the picture that are not background, the box around them
  // ([left, top, right, bottom], canvas pixels from the top left; null when none), and a
  // fingerprint.
  const pixels = () => {
    draw();
    const c = document.createElement('canvas');
    c.width = renderer.domElement.width;
    c.height = renderer.domElement.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(renderer.domElement, 0, 0);
    const img = ctx.getImageData(0, 0, c.width, c.height).data;
    let drawn = 0;
    let hash = 2166136261;
    let box = null;
    for (let i = 0; i < img.length; i += 4) {
      if (img[i] < 247 || img[i + 1] < 247 || img[i + 2] < 247) {
        drawn++;
        const x = (i / 4) % c.width;
        const y = Math.floor(i / 4 / c.width);
        if (!box) box = [x, y, x, y];
        box = [Math.min(box[0], x), Math.min(box[1], y), Math.max(box[2], x), Math.max(box[3], y)];
      }
      hash = Math.imul(hash ^ (img[i] + 3 * img[i + 1] + 7 * img[i + 2]), 16777619) >>> 0;
    }
    return { drawn, hash, box, total: img.length / 4 };
  };
  window.linkageViewer = { ready: true, webgl: true, frames: n, setFrame, pixels, frame: () => current };
})();
