// 3D replay of an oceangnc run (oceangnc view RUN; docs/view.md). Data: the JSON in #replay-data
// (oceangnc.view.replay.replay_data). The page state is on window.replay (for users and tests).
import * as THREE from 'three';
import { AA, BACKGROUND, BODY_COLORS, WavePatch, bodyMatrix, createScene, hull, nedToThree, tensionColor, torpedo,
  waveElevation } from 'oceangnc/scene3d';

const DATA = JSON.parse(document.getElementById('replay-data').textContent);

function decode(b64, f64) {
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return f64 ? new Float64Array(bytes.buffer) : new Float32Array(bytes.buffer);
}
const T = decode(DATA.t, true);
const N = T.length;
const SERIES = {};
for (const [k, v] of Object.entries(DATA.series)) SERIES[k] = decode(v, false);
const col = (name) => (name && SERIES[name]) || null;

// ---- time ---------------------------------------------------------------------------------------
const T0 = T[0], T1 = T[N - 1];
function rowAt(t) {  // [k, a]: t between rows k and k+1, a in [0, 1)
  if (!(t > T0)) return [0, 0];
  if (t >= T1) return [N - 1, 0];
  let lo = 0, hi = N - 1;
  while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (T[mid] <= t) lo = mid; else hi = mid; }
  const dt = T[hi] - T[lo];
  return [lo, dt > 0 ? (t - T[lo]) / dt : 0];
}
function lerp(arr, k, a, dflt = 0) {
  if (!arr) return dflt;
  const v0 = arr[k];
  if (a === 0 || k + 1 >= arr.length) return v0;
  const v1 = arr[k + 1];
  if (!Number.isFinite(v1)) return v0;
  return v0 + a * (v1 - v0);
}
function lerpAngle(arr, k, a) {
  if (!arr) return 0;
  const v0 = arr[k];
  if (a === 0 || k + 1 >= arr.length) return v0;
  let dv = arr[k + 1] - v0;
  dv = Math.atan2(Math.sin(dv), Math.cos(dv));
  return v0 + a * dv;
}

// ---- scene --------------------------------------------------------------------------------------
const view = document.getElementById('view');
const { renderer, scene, camera } = createScene(view);

const EXT = DATA.extent;
const spanN = EXT.n1 - EXT.n0, spanE = EXT.e1 - EXT.e0;
const midN = (EXT.n0 + EXT.n1) / 2, midE = (EXT.e0 + EXT.e1) / 2;
const objects = {};  // name -> Object3D (for setVisible)

// sea surface: a translucent plane at depth 0, with a grid for scale
{
  const g = new THREE.PlaneGeometry(spanE, spanN);
  g.rotateX(-Math.PI / 2);  // normal up (three y)
  const m = new THREE.MeshBasicMaterial({ color: 0x1a6fb3, transparent: true, opacity: 0.22, depthWrite: false,
    side: THREE.DoubleSide });
  const sea = new THREE.Mesh(g, m);
  nedToThree(midN, midE, 0, sea.position);
  sea.renderOrder = 2;
  scene.add(sea);
  objects.sea = sea;

  const step = Math.pow(10, Math.floor(Math.log10(Math.max(spanN, spanE) / 4)));
  const size = Math.ceil(Math.max(spanN, spanE) / step) * step;
  const grid = new THREE.GridHelper(size, Math.round(size / step), 0x3d6d96, 0x24476a);
  grid.material.transparent = true;
  grid.material.opacity = 0.35;
  nedToThree(midN, midE, 0, grid.position);
  scene.add(grid);
  objects.grid = grid;
  if (DATA.waves && !/[?&]waves=0\b/.test(location.search)) {
    // the calm plane stays as the far sea, fainter; the waves are drawn about the camera's target; the grid
    // (at the mean surface, which the waves cross) hidden (replay.setVisible('grid', true) shows it)
    m.opacity = 0.1;
    grid.visible = false;
    objects.sea_far = sea;
  }
}

// waves: a patch of the run's wave field (WavePatch, scene3d.js) that follows the camera's target,
// 4 peak wavelengths (deep water, g Tp^2 / 2 pi) on a side, 60 to 400 m, 48 x 48 cells (?wavecells=N,
// 8 to 160: 12 vertices a peak wavelength by default; finer costs frames in software WebGL, bench_view.py)
let waves = null;
const WAVES = DATA.waves && !/[?&]waves=0\b/.test(location.search);  // ?waves=0: the calm plane only
if (WAVES) {
  const W = DATA.waves;
  const lp = 9.80665 * W.tp * W.tp / (2 * Math.PI);
  const size = Math.min(400, Math.max(60, 4 * (lp || 50)));
  // unlit (WavePatch shades it), both faces in one pass: software WebGL draws a lit or two-pass surface at
  // half the frame rate
  const mat = new THREE.MeshBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.6, depthWrite: false,
    side: THREE.DoubleSide, forceSinglePass: true });
  const cells = Math.min(160, Math.max(8, parseInt((location.search.match(/[?&]wavecells=(\d+)/) || [])[1] || "48", 10)));
  waves = new WavePatch(W, size, cells, mat);
  waves.mesh.renderOrder = 3;
  scene.add(waves.mesh);
  objects.sea = waves.mesh;
  objects.waves = waves.mesh;
}

// seabed: the plane D + tan(slope) (n cos chi + e sin chi)
if (DATA.seabed) {
  const b = DATA.seabed, s = Math.tan(b.slope_deg * Math.PI / 180), chi = b.slope_direction_deg * Math.PI / 180;
  const depth = (n, e) => b.depth + s * (n * Math.cos(chi) + e * Math.sin(chi));
  const corners = [[EXT.n0, EXT.e0], [EXT.n0, EXT.e1], [EXT.n1, EXT.e1], [EXT.n1, EXT.e0]];
  const pos = [];
  for (const i of [0, 2, 1, 0, 3, 2]) {
    const [n, e] = corners[i];
    const v = nedToThree(n, e, depth(n, e));
    pos.push(v.x, v.y, v.z);
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  g.computeVertexNormals();
  const bed = new THREE.Mesh(g, new THREE.MeshLambertMaterial({ color: 0x7a6244, side: THREE.DoubleSide }));
  scene.add(bed);
  const wire = new THREE.LineSegments(new THREE.WireframeGeometry(g), new THREE.LineBasicMaterial({ color: 0x9c8360 }));
  scene.add(wire);
  objects.seabed = bed;
}

// route and waypoints (at the surface)
if (DATA.route.length) {
  const pts = DATA.route.map(([n, e]) => nedToThree(n, e, 0));
  const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts),
    new THREE.LineDashedMaterial({ color: 0x33e066, dashSize: 1, gapSize: 0.5 }));
  line.computeLineDistances();
  scene.add(line);
  const r = DATA.acceptance || 1;
  for (const p of pts) {
    const ring = new THREE.Mesh(new THREE.RingGeometry(r * 0.9, r, 48),
      new THREE.MeshBasicMaterial({ color: 0x33e066, side: THREE.DoubleSide, transparent: true, opacity: 0.8 }));
    ring.rotation.x = -Math.PI / 2;
    ring.position.copy(p);
    scene.add(ring);
  }
  objects.route = line;
}

const bodies = DATA.bodies.map((b) => {
  const c = b.columns;
  const arr = { x: col(c.x), y: col(c.y), z: col(c.z), phi: col(c.phi), theta: col(c.theta), psi: col(c.psi) };
  const color = BODY_COLORS[b.name] ?? 0xdadbe6;
  const obj = b.kind === 'torpedo' ? torpedo(b.length, b.width, color) : hull(b.length, b.width, color);
  obj.matrixAutoUpdate = false;
  scene.add(obj);
  objects[b.name] = obj;
  // trail: every logged position, drawn up to the current row
  const tp = new Float32Array(N * 3);
  const v = new THREE.Vector3();
  let last = null;
  for (let i = 0; i < N; i++) {
    const n = arr.x[i], e = arr.y[i], d = arr.z ? arr.z[i] : 0;
    if (Number.isFinite(n) && Number.isFinite(e) && Number.isFinite(d)) last = nedToThree(n, e, d, v).toArray();
    if (last) tp.set(last, 3 * i);
  }
  const tg = new THREE.BufferGeometry();
  tg.setAttribute('position', new THREE.BufferAttribute(tp, 3));
  const trail = new THREE.Line(tg, new THREE.LineBasicMaterial({ color, transparent: true, opacity: 0.6 }));
  trail.frustumCulled = false;
  scene.add(trail);
  objects[b.name + '_trail'] = trail;
  return { ...b, arr, obj, trail, ned: [0, 0, 0], world: [0, 0, 0], m: new THREE.Matrix4() };
});
const byName = Object.fromEntries(bodies.map((b) => [b.name, b]));

// cable: a polyline (and points) through every node, coloured by tension
const NODES = DATA.cable.nodes;
let cable = null;
if (NODES) {
  const cx = [], cy = [], cz = [];
  for (let k = 0; k < NODES; k++) { cx.push(col(`cable.x${k}`)); cy.push(col(`cable.y${k}`)); cz.push(col(`cable.z${k}`)); }
  const tens = DATA.cable.tension.map(col);
  let tmax = 0;
  for (const a of tens) for (let i = 0; i < a.length; i++) if (a[i] > tmax) tmax = a[i];
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(NODES * 3), 3));
  g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(NODES * 3), 3));
  const line = new THREE.Line(g, new THREE.LineBasicMaterial({ vertexColors: true }));
  const pts = new THREE.Points(g, new THREE.PointsMaterial({ vertexColors: true, size: 4, sizeAttenuation: false }));
  line.frustumCulled = pts.frustumCulled = false;
  scene.add(line, pts);
  objects.cable = line;
  objects.cable_nodes = pts;
  cable = { cx, cy, cz, tens, tmax, g, ned: [0, 0, 0], world: [0, 0, 0] };
  const lg = document.getElementById('legend');
  lg.style.display = 'block';
  lg.innerHTML = tens.length
    ? `cable tension 0<span class="bar"></span>${tmax.toFixed(0)} N` +
      (DATA.cable.tensionMode === 'ends' ? ' (end tensions, linear between)' : '')
    : 'cable nodes by segment (no tension logged)<span class="bar"></span>';
}

if (DATA.waves) {
  const lg = document.getElementById('legend'), W = DATA.waves;
  lg.style.display = 'block';
  const line = document.createElement('div');
  line.textContent = `waves: ${W.kind} Hs ${W.hs} m, Tp ${W.tp} s, toward ${W.direction_deg} deg, ${W.a.length} components`;
  lg.appendChild(line);
}

// ---- update -------------------------------------------------------------------------------------
const tmpV = new THREE.Vector3(), tmpC = new THREE.Color();
const state = { t: T0, k: 0, a: 0, playing: false, speed: 1, follow: 'tow', frames: 0, trails: true, waveMs: 0, waveUpdates: 0 };

function update(t) {
  t = Math.min(Math.max(t, T0), T1);
  const [k, a] = rowAt(t);
  state.t = t; state.k = k; state.a = a;
  for (const b of bodies) {
    const n = lerp(b.arr.x, k, a), e = lerp(b.arr.y, k, a), d = lerp(b.arr.z, k, a);
    const phi = lerpAngle(b.arr.phi, k, a), th = lerpAngle(b.arr.theta, k, a), psi = lerpAngle(b.arr.psi, k, a);
    const ok = [n, e, d, phi, th, psi].every(Number.isFinite);
    b.obj.visible = ok && b.shown !== false;
    if (ok) {
      bodyMatrix(n, e, d, phi, th, psi, b.obj.matrix);
      b.obj.matrixWorldNeedsUpdate = true;
      b.ned = [n, e, d];
      b.world = nedToThree(n, e, d, tmpV).toArray();
    }
    b.trail.geometry.setDrawRange(0, k + 1);
  }
  if (cable) {
    const pos = cable.g.attributes.position.array, colr = cable.g.attributes.color.array;
    let lastOk = null;
    for (let j = 0; j < NODES; j++) {
      let n = lerp(cable.cx[j], k, a, NaN), e = lerp(cable.cy[j], k, a, NaN), d = lerp(cable.cz[j], k, a, NaN);
      if (!(Number.isFinite(n) && Number.isFinite(e) && Number.isFinite(d))) {
        if (!lastOk) continue;  // a node not in use (winch): drawn on the last one in use
        [n, e, d] = lastOk;
      } else lastOk = [n, e, d];
      nedToThree(n, e, d, tmpV);
      pos[3 * j] = tmpV.x; pos[3 * j + 1] = tmpV.y; pos[3 * j + 2] = tmpV.z;
      let f = j / Math.max(NODES - 1, 1);
      if (cable.tens.length === NODES && cable.tmax > 0) f = lerp(cable.tens[j], k, a) / cable.tmax;
      else if (cable.tens.length === 2 && cable.tmax > 0) {
        const top = lerp(cable.tens[0], k, a), bot = lerp(cable.tens[1], k, a);
        f = (top + (bot - top) * j / Math.max(NODES - 1, 1)) / cable.tmax;
      }
      tensionColor(f, tmpC);
      colr[3 * j] = tmpC.r; colr[3 * j + 1] = tmpC.g; colr[3 * j + 2] = tmpC.b;
    }
    if (lastOk) {
      cable.ned = lastOk;
      cable.world = nedToThree(lastOk[0], lastOk[1], lastOk[2], tmpV).toArray();
    }
    cable.g.attributes.position.needsUpdate = true;
    cable.g.attributes.color.needsUpdate = true;
  }
}

// ---- camera: orbit about a target that follows the tow -----------------------------------------
const orbit = { az: -2.3, el: 0.45, dist: 1, target: new THREE.Vector3() };
{
  // far enough for the longest vehicle and the largest USV-UUV separation of the run
  const L = Math.max(1, ...bodies.map((b) => b.length));
  let sep = 0;
  for (let i = 0; i < bodies.length; i++) for (let j = i + 1; j < bodies.length; j++) {
    const a = bodies[i].arr, b = bodies[j].arr;
    for (let k = 0; k < N; k += Math.max(1, Math.floor(N / 500))) {
      const s = Math.hypot(a.x[k] - b.x[k], a.y[k] - b.y[k], (a.z ? a.z[k] : 0) - (b.z ? b.z[k] : 0));
      if (s > sep) sep = s;
    }
  }
  orbit.dist = Math.max(8, 4 * L, 1.6 * sep);
}
function followTarget(out) {
  const chosen = state.follow === 'tow' ? bodies : bodies.filter((b) => b.name === state.follow);
  if (!chosen.length || state.follow === 'free') return false;
  out.set(0, 0, 0);
  for (const b of chosen) out.add(tmpV.fromArray(b.world));
  out.multiplyScalar(1 / chosen.length);
  return true;
}
function placeCamera() {
  followTarget(orbit.target);
  const c = Math.cos(orbit.el);
  camera.position.set(orbit.target.x + orbit.dist * c * Math.sin(orbit.az), orbit.target.y + orbit.dist * Math.sin(orbit.el),
    orbit.target.z + orbit.dist * c * Math.cos(orbit.az));
  camera.lookAt(orbit.target);
  camera.updateMatrixWorld();
}
{
  let drag = null;
  const el = renderer.domElement;
  el.addEventListener('pointerdown', (ev) => { drag = [ev.clientX, ev.clientY, ev.button]; el.setPointerCapture(ev.pointerId); });
  el.addEventListener('pointerup', () => { drag = null; });
  el.addEventListener('pointermove', (ev) => {
    if (!drag) return;
    const dx = ev.clientX - drag[0], dy = ev.clientY - drag[1];
    drag[0] = ev.clientX; drag[1] = ev.clientY;
    if (drag[2] === 0 && !ev.shiftKey) {
      orbit.az -= dx * 0.005;
      orbit.el = Math.min(1.5, Math.max(-1.5, orbit.el + dy * 0.005));
    } else {  // pan (right button or shift): leaves follow mode
      state.follow = 'free'; document.getElementById('follow').value = 'free';
      const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
      const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
      const s = orbit.dist * 0.0015;
      orbit.target.addScaledVector(right, -dx * s).addScaledVector(up, dy * s);
    }
    requestRender();
  });
  el.addEventListener('contextmenu', (ev) => ev.preventDefault());
  el.addEventListener('wheel', (ev) => {
    ev.preventDefault();
    orbit.dist = Math.min(1e4, Math.max(0.5, orbit.dist * Math.exp(ev.deltaY * 0.001)));
    requestRender();
  }, { passive: false });
}

// ---- panels -------------------------------------------------------------------------------------
const panelBox = document.getElementById('panels');
const PANEL_COLORS = ['#ffbf1a', '#4fb3ff', '#ff6b6b'];
const panels = DATA.panels.map((p) => {
  const canvas = document.createElement('canvas');
  panelBox.appendChild(canvas);
  const series = p.series.map(([c, label]) => ({ arr: col(c), label }));
  let lo = Infinity, hi = -Infinity;
  for (const s of series) for (const v of s.arr) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
  if (!(hi > lo)) { lo = (Number.isFinite(lo) ? lo : 0) - 1; hi = lo + 2; }
  const pad = 0.05 * (hi - lo);
  const panel = { ...p, canvas, series, lo: lo - pad, hi: hi + pad, bg: null };
  const seekAt = (ev) => {
    const r = canvas.getBoundingClientRect();
    api.seek(T0 + (T1 - T0) * (ev.clientX - r.left - 40) / (r.width - 48));
  };
  canvas.addEventListener('pointerdown', (ev) => { seekAt(ev); canvas.setPointerCapture(ev.pointerId); panel.drag = true; });
  canvas.addEventListener('pointermove', (ev) => { if (panel.drag) seekAt(ev); });
  canvas.addEventListener('pointerup', () => { panel.drag = false; });
  return panel;
});
function panelGeom(p) {
  const w = p.canvas.width, h = p.canvas.height, r = window.devicePixelRatio || 1;
  return { w, h, r, x0: 40 * r, x1: w - 8 * r, y0: 18 * r, y1: h - 16 * r };
}
function drawPanelBackground(p) {  // the series once; the cursor is drawn over a copy each frame
  const r = window.devicePixelRatio || 1;
  const cw = Math.max(1, Math.round(p.canvas.clientWidth * r)), ch = Math.max(1, Math.round(p.canvas.clientHeight * r));
  p.canvas.width = cw; p.canvas.height = ch;
  const g = panelGeom(p);
  const off = document.createElement('canvas');
  off.width = cw; off.height = ch;
  const c = off.getContext('2d');
  const X = (t) => g.x0 + (g.x1 - g.x0) * (t - T0) / Math.max(T1 - T0, 1e-9);
  const Y = (v) => p.invert ? g.y0 + (g.y1 - g.y0) * (v - p.lo) / (p.hi - p.lo) : g.y1 - (g.y1 - g.y0) * (v - p.lo) / (p.hi - p.lo);
  c.fillStyle = '#0b1724'; c.fillRect(0, 0, cw, ch);
  c.strokeStyle = '#2a3f58'; c.strokeRect(g.x0, g.y0, g.x1 - g.x0, g.y1 - g.y0);
  c.fillStyle = '#d8e2ee'; c.font = `${11 * r}px system-ui, sans-serif`;
  c.fillText(`${p.title} (${p.unit})${p.invert ? ', down' : ''}`, g.x0, 12 * r);
  c.fillStyle = '#8aa0b8';
  c.fillText(p.hi.toPrecision(3), 2 * r, p.invert ? g.y1 : g.y0 + 9 * r);
  c.fillText(p.lo.toPrecision(3), 2 * r, p.invert ? g.y0 + 9 * r : g.y1);
  c.fillText(`${T0.toFixed(0)} s`, g.x0, ch - 3 * r);
  c.fillText(`${T1.toFixed(0)} s`, g.x1 - 30 * r, ch - 3 * r);
  p.series.forEach((s, i) => {
    c.strokeStyle = PANEL_COLORS[i % PANEL_COLORS.length]; c.lineWidth = 1.2 * r; c.beginPath();
    const step = Math.max(1, Math.floor(N / (2 * cw)));
    let pen = false;
    for (let j = 0; j < N; j += step) {
      const v = s.arr[j];
      if (!Number.isFinite(v)) { pen = false; continue; }
      if (pen) c.lineTo(X(T[j]), Y(v)); else c.moveTo(X(T[j]), Y(v));
      pen = true;
    }
    c.stroke();
  });
  p.bg = off; p.X = X; p.Y = Y;
}
function drawPanels() {
  for (const p of panels) {
    if (!p.bg || p.canvas.width !== Math.round(p.canvas.clientWidth * (window.devicePixelRatio || 1))) drawPanelBackground(p);
    const c = p.canvas.getContext('2d'), g = panelGeom(p);
    c.drawImage(p.bg, 0, 0);
    const x = p.X(state.t);
    c.strokeStyle = '#ffffff'; c.lineWidth = 1; c.beginPath(); c.moveTo(x, g.y0); c.lineTo(x, g.y1); c.stroke();
    const vals = p.series.map((s, i) => {
      const v = lerp(s.arr, state.k, state.a);
      c.fillStyle = PANEL_COLORS[i % PANEL_COLORS.length];
      if (Number.isFinite(v)) { c.beginPath(); c.arc(x, p.Y(v), 3 * g.r, 0, 2 * Math.PI); c.fill(); }
      return `${s.label} ${Number.isFinite(v) ? v.toPrecision(4) : '-'}`;
    });
    c.fillStyle = '#d8e2ee'; c.textAlign = 'right';
    c.fillText(vals.join('  '), g.x1, 12 * g.r);
    c.textAlign = 'left';
  }
}

// ---- controls -----------------------------------------------------------------------------------
const $ = (id) => document.getElementById(id);
$('title').textContent = `${DATA.scenario || ''} ${DATA.run}`;
const fmt = (t) => `t = ${t.toFixed(2)} / ${T1.toFixed(2)} s`;
const shown = {};
function show(id, prop, v) { if (shown[id] !== v) { $(id)[prop] = v; shown[id] = v; } }
function syncControls() {  // the DOM touched only where it changes
  show('play', 'innerHTML', state.playing ? '&#10074;&#10074;' : '&#9654;');
  show('scrub', 'value', String(Math.round(1000 * (state.t - T0) / Math.max(T1 - T0, 1e-9))));
  show('time', 'textContent', fmt(state.t));
}
$('play').addEventListener('click', () => (state.playing ? api.pause() : api.play()));
$('speed').addEventListener('change', (ev) => api.setSpeed(parseFloat(ev.target.value)));
$('scrub').addEventListener('input', (ev) => api.seek(T0 + (T1 - T0) * ev.target.value / 1000));
$('follow').addEventListener('change', (ev) => { state.follow = ev.target.value; requestRender(); });
$('trails').addEventListener('change', (ev) => {
  state.trails = ev.target.checked;
  for (const b of bodies) b.trail.visible = state.trails;
  requestRender();
});
window.addEventListener('keydown', (ev) => {
  if (ev.target.tagName === 'SELECT' || ev.target.tagName === 'INPUT' && ev.target.type !== 'range') return;
  if (ev.code === 'Space') { ev.preventDefault(); state.playing ? api.pause() : api.play(); }
  if (ev.code === 'ArrowRight' || ev.code === 'ArrowLeft') {
    ev.preventDefault();
    const k = Math.min(N - 1, Math.max(0, state.k + (ev.code === 'ArrowRight' ? 1 : (state.a > 0 ? 0 : -1))));
    api.seek(T[k]);
  }
});
for (const sel of ['follow']) $(sel).querySelectorAll('option').forEach((o) => {
  if (o.value !== 'tow' && o.value !== 'free' && !byName[o.value]) o.remove();
});

// ---- render loop --------------------------------------------------------------------------------
let dirty = true, lastPanels = -1e9;
function requestRender() { dirty = true; }
function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  if (renderer.domElement.width !== Math.round(w * renderer.getPixelRatio()) ||
      renderer.domElement.height !== Math.round(h * renderer.getPixelRatio())) {
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    for (const p of panels) p.bg = null;
  }
}
function render() {
  resize();
  placeCamera();
  if (waves) {  // target three (x, z) = (east, -north)
    const w0 = performance.now();
    if (waves.update(-orbit.target.z, orbit.target.x, state.t)) { state.waveMs += performance.now() - w0; state.waveUpdates++; }
  }
  scene.updateMatrixWorld();
  renderer.render(scene, camera);
  const now = performance.now();  // the panels at most 20 times a second (their canvases cost frames)
  if (!state.playing || now - lastPanels > 50) { drawPanels(); lastPanels = now; }
  syncControls();
  state.frames++;
  dirty = false;
}
let lastWall = null;
function loop(now) {
  if (state.playing) {
    if (lastWall !== null) {
      update(state.t + (now - lastWall) / 1000 * state.speed);
      if (state.t >= T1) state.playing = false;
    }
    lastWall = now;
    dirty = true;
  } else lastWall = null;
  if (dirty) render();
  requestAnimationFrame(loop);
}
window.addEventListener('resize', requestRender);

// ---- the page's state, for users and tests ------------------------------------------------------
const api = {
  ready: false,
  get t() { return state.t; },
  get playing() { return state.playing; },
  get speed() { return state.speed; },
  get frames() { return state.frames; },
  t0: T0, t1: T1, rows: N,
  get uuv() { const b = byName.uuv; return b ? { ned: b.ned.slice(), world: b.world.slice() } : null; },
  get cableEnd() { return cable ? { ned: cable.ned.slice(), world: cable.world.slice() } : null; },
  get bodies() { return Object.fromEntries(bodies.map((b) => [b.name, { ned: b.ned.slice(), world: b.world.slice() }])); },
  seek(t) { update(t); render(); return state.t; },
  play() { if (state.t >= T1) update(T0); state.playing = true; lastWall = null; syncControls(); },
  pause() { state.playing = false; render(); },
  setSpeed(s) { state.speed = s; $('speed').value = String(s); },
  setFollow(f) { state.follow = f; $('follow').value = f; render(); },
  // the orbiting camera: azimuth and elevation (rad) and distance (m) about the followed target
  get orbit() { return { az: orbit.az, el: orbit.el, dist: orbit.dist }; },
  setOrbit({ az = orbit.az, el = orbit.el, dist = orbit.dist } = {}) {
    orbit.az = az; orbit.el = Math.min(1.5, Math.max(-1.5, el)); orbit.dist = Math.min(1e4, Math.max(0.5, dist));
    render(); return api.orbit;
  },
  setVisible(name, on) {
    const o = objects[name];
    if (!o) return false;
    if (byName[name]) byName[name].shown = on;
    o.visible = on; render(); return true;
  },
  nedToThree: (n, e, d) => nedToThree(n, e, d).toArray(),
  // CSS pixels from the canvas's top-left corner of a three.js world point, as drawn by this camera
  project(x, y, z) {
    const v = new THREE.Vector3(x, y, z).project(camera);
    const r = renderer.domElement.getBoundingClientRect();
    return [(v.x + 1) / 2 * r.width, (1 - v.y) / 2 * r.height, v.z];
  },
  // the drawn object's own world position (its matrixWorld), projected
  projectObject(name) {
    if (name === 'cableEnd') {
      if (!cable) return null;
      const a = cable.g.attributes.position, j = NODES - 1;
      return api.project(a.getX(j), a.getY(j), a.getZ(j));
    }
    const o = objects[name];
    if (!o) return null;
    const p = new THREE.Vector3().setFromMatrixPosition(o.matrixWorld);
    return api.project(p.x, p.y, p.z);
  },
  cameraMatrices() {
    const r = renderer.domElement.getBoundingClientRect();
    return { projection: camera.projectionMatrix.elements.slice(), view: camera.matrixWorldInverse.elements.slice(),
      left: r.left, top: r.top, width: r.width, height: r.height };
  },
  // the sea surface (runs with waves): the page's elevation (m, up) at north n, east e (m), time t (s),
  // and the drawn patch: its grid (north n0 + i step, east e0 + l step), heights in double precision
  // (eta) and as drawn (the mesh's single-precision y)
  waves: waves ? { count: DATA.waves.a.length, hs: DATA.waves.hs, tp: DATA.waves.tp, size: waves.step * waves.cells,
    cells: waves.cells } : null,
  // mean wall time of one update of the wave patch (ms; its share of a frame, for the benchmark)
  get waveMs() { return state.waveUpdates ? state.waveMs / state.waveUpdates : 0; },
  seaElevation(n, e, t) { return DATA.waves ? waveElevation(DATA.waves, n, e, t) : 0; },
  seaPatch() {
    if (!waves) return null;
    const y = waves.mesh.geometry.attributes.position.array;
    return { t: waves.t, n0: waves.n0, e0: waves.e0, step: waves.step, cells: waves.cells, eta: Array.from(waves.eta),
      drawn: Array.from({ length: waves.eta.length }, (_, v) => y[3 * v + 1]) };
  },
  get layers() { return Object.keys(objects).filter((k) => objects[k].visible); },
  background: '#' + new THREE.Color(BACKGROUND).getHexString(),
  antialias: AA,
  camera, renderer, scene,
};
window.replay = api;
update(T0);
render();
requestAnimationFrame(loop);
api.loadMs = performance.now();  // from the navigation's start to the first frame drawn
api.ready = true;
if (!/[?&]paused\b/.test(location.search)) api.play();
