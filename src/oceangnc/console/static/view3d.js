// The console's 3D panel (issue 31; docs/view.md): the running simulation as the replay page draws
// a run - hulls, the UUV with its attitude, the cable nodes coloured by tension, trails, the route,
// the sea surface. It reads the state the console page already receives (window.__console, set by
// console.js) and draws each new state once; it sends nothing. Frames and meshes: oceangnc/scene3d.
import * as THREE from 'three';
import { BODY_COLORS, WavePatch, bodyMatrix, createScene, hull, nedToThree, tensionColor, torpedo } from 'oceangnc/scene3d';

const box = document.getElementById('view3d');
const { renderer, scene, camera } = createScene(box);

// the sea surface and a 10 m grid, centred under the vehicles (moved with them)
const sea = new THREE.Mesh(new THREE.PlaneGeometry(400, 400).rotateX(-Math.PI / 2),
  new THREE.MeshBasicMaterial({ color: 0x1a6fb3, transparent: true, opacity: 0.22, depthWrite: false, side: THREE.DoubleSide }));
sea.renderOrder = 2;
const grid = new THREE.GridHelper(400, 40, 0x3d6d96, 0x24476a);
grid.material.transparent = true;
grid.material.opacity = 0.35;
scene.add(sea, grid);

const TRAIL = 3000;  // points per trail (the last ones)
let built = null;  // what was built for the current run: {run, bodies, cable, route}
const tmpV = new THREE.Vector3(), tmpC = new THREE.Color();
const orbit = { az: -2.3, el: 0.45, dist: 12, target: new THREE.Vector3() };

function shapeOf(b) {
  return b.shape === 'sub' || b.name === 'uuv' ? 'torpedo' : 'hull';
}

function build(hello) {
  if (built) for (const o of built.objects) scene.remove(o);
  const v = hello.view || {};
  const objects = [];
  const bodies = (v.bodies || []).map((b) => {
    const color = BODY_COLORS[b.name] ?? 0xdadbe6;
    const obj = shapeOf(b) === 'torpedo' ? torpedo(b.length, b.beam, color) : hull(b.length, b.beam, color);
    obj.matrixAutoUpdate = false;
    obj.visible = false;
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(TRAIL * 3), 3));
    g.setDrawRange(0, 0);
    const trail = new THREE.Line(g, new THREE.LineBasicMaterial({ color, transparent: true, opacity: 0.6 }));
    trail.frustumCulled = false;
    objects.push(obj, trail);
    return { name: b.name, length: b.length, obj, trail, n: 0, ned: null, world: null };
  });
  let cable = null;
  if (v.cable && v.cable.x && v.cable.x.length >= 2) {
    const n = v.cable.x.length;
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(n * 3), 3));
    g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(n * 3), 3));
    const line = new THREE.Line(g, new THREE.LineBasicMaterial({ vertexColors: true }));
    const pts = new THREE.Points(g, new THREE.PointsMaterial({ vertexColors: true, size: 4, sizeAttenuation: false }));
    line.frustumCulled = pts.frustumCulled = false;
    objects.push(line, pts);
    cable = { keys: v.cable, n, g, tmax: 0, ned: null, world: null };
  }
  if (v.route && v.route.length) {
    const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(v.route.map(([n, e]) => nedToThree(n, e, 0))),
      new THREE.LineDashedMaterial({ color: 0x33e066, dashSize: 1, gapSize: 0.5 }));
    line.computeLineDistances();
    objects.push(line);
  }
  // a scenario at sea: the wave surface (as the replay page's, WavePatch) about the vehicles, 200 m, 48 x 48
  // cells, at the time of the state drawn; the flat sea fainter and the grid hidden
  let waves = null;
  if (v.waves && v.waves.a && v.waves.a.length) {
    const mat = new THREE.MeshBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.6, depthWrite: false,
      side: THREE.DoubleSide, forceSinglePass: true });
    waves = new WavePatch(v.waves, 200, 48, mat);
    waves.mesh.renderOrder = 3;
    objects.push(waves.mesh);
  }
  sea.material.opacity = waves ? 0.1 : 0.22;
  grid.visible = !waves;
  for (const o of objects) scene.add(o);
  const L = Math.max(1, ...bodies.map((b) => b.length));
  orbit.dist = Math.max(8, 4 * L);
  built = { run: hello.run, bodies, cable, objects, waves };
}

const num = (sig, k, d = 0) => (typeof sig[k] === 'number' ? sig[k] : d);

function update(state) {
  const sig = state.signals || {};
  for (const b of built.bodies) {
    const n = sig[`${b.name}.x`], e = sig[`${b.name}.y`];
    if (typeof n !== 'number' || typeof e !== 'number') { b.obj.visible = false; continue; }
    const d = num(sig, `${b.name}.z`);
    bodyMatrix(n, e, d, num(sig, `${b.name}.phi`), num(sig, `${b.name}.theta`), num(sig, `${b.name}.psi`), b.obj.matrix);
    b.obj.matrixWorldNeedsUpdate = true;
    b.obj.visible = true;
    b.ned = [n, e, d];
    b.world = nedToThree(n, e, d, tmpV).toArray();
    const pos = b.trail.geometry.attributes.position;
    if (b.n >= TRAIL) { pos.array.copyWithin(0, (TRAIL / 2) * 3); b.n = TRAIL / 2; }
    pos.array.set(b.world, 3 * b.n);
    b.n += 1;
    pos.needsUpdate = true;
    b.trail.geometry.setDrawRange(0, b.n);
  }
  const c = built.cable;
  if (c) {
    const pos = c.g.attributes.position.array, col = c.g.attributes.color.array;
    const top = sig['cable.top_tension'], bot = sig['cable.bottom_tension'];
    const tens = typeof top === 'number' && typeof bot === 'number';
    if (tens) c.tmax = Math.max(c.tmax, top, bot);
    let last = null;
    for (let j = 0; j < c.n; j++) {
      let n = sig[c.keys.x[j]], e = sig[c.keys.y[j]], d = sig[c.keys.z[j]];
      if (typeof n !== 'number' || typeof e !== 'number' || typeof d !== 'number') {
        if (!last) continue;  // a node not in use (winch): drawn on the last one in use
        [n, e, d] = last;
      } else last = [n, e, d];
      nedToThree(n, e, d, tmpV);
      pos[3 * j] = tmpV.x; pos[3 * j + 1] = tmpV.y; pos[3 * j + 2] = tmpV.z;
      const s = j / Math.max(c.n - 1, 1);
      tensionColor(tens && c.tmax > 0 ? (top + (bot - top) * s) / c.tmax : s, tmpC);
      col[3 * j] = tmpC.r; col[3 * j + 1] = tmpC.g; col[3 * j + 2] = tmpC.b;
    }
    if (last) { c.ned = last; c.world = nedToThree(last[0], last[1], last[2], tmpV).toArray(); }
    c.g.attributes.position.needsUpdate = true;
    c.g.attributes.color.needsUpdate = true;
  }
}

function placeCamera() {
  const shown = built ? built.bodies.filter((b) => b.world) : [];
  if (shown.length) {
    orbit.target.set(0, 0, 0);
    for (const b of shown) orbit.target.add(tmpV.fromArray(b.world));
    orbit.target.multiplyScalar(1 / shown.length);
  }
  const t = orbit.target;
  sea.position.set(Math.round(t.x / 10) * 10, 0, Math.round(t.z / 10) * 10);
  grid.position.copy(sea.position);
  if (built?.waves && typeof api.t === 'number') built.waves.update(-t.z, t.x, api.t);  // target three (x, z) = (east, -north)
  const c = Math.cos(orbit.el);
  camera.position.set(t.x + orbit.dist * c * Math.sin(orbit.az), t.y + orbit.dist * Math.sin(orbit.el),
    t.z + orbit.dist * c * Math.cos(orbit.az));
  camera.lookAt(t);
  camera.updateMatrixWorld();
}

function render() {
  const w = box.clientWidth, h = box.clientHeight;
  if (w > 0 && h > 0 && (renderer.domElement.width !== Math.round(w * renderer.getPixelRatio()) ||
      renderer.domElement.height !== Math.round(h * renderer.getPixelRatio()))) {
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  placeCamera();
  scene.updateMatrixWorld();
  renderer.render(scene, camera);
  api.frames += 1;
}

{  // orbit with the mouse (drag), zoom with the wheel
  let drag = null;
  const el = renderer.domElement;
  el.addEventListener('pointerdown', (ev) => { drag = [ev.clientX, ev.clientY]; el.setPointerCapture(ev.pointerId); });
  el.addEventListener('pointerup', () => { drag = null; });
  el.addEventListener('pointermove', (ev) => {
    if (!drag) return;
    orbit.az -= (ev.clientX - drag[0]) * 0.005;
    orbit.el = Math.min(1.5, Math.max(-1.5, orbit.el + (ev.clientY - drag[1]) * 0.005));
    drag = [ev.clientX, ev.clientY];
    dirty = true;
  });
  el.addEventListener('wheel', (ev) => {
    ev.preventDefault();
    orbit.dist = Math.min(1e4, Math.max(0.5, orbit.dist * Math.exp(ev.deltaY * 0.001)));
    dirty = true;
  }, { passive: false });
}

let lastState = null, dirty = true;
function loop() {
  const S = window.__console;
  if (S && S.hello && (!built || built.run !== S.hello.run)) { build(S.hello); dirty = true; }
  if (S && built && S.state && S.state !== lastState && S.state.run === built.run) {
    lastState = S.state;
    update(lastState);
    api.updates += 1;
    api.t = lastState.t;
    api.state = lastState;
    dirty = true;
  }
  if (dirty) { render(); dirty = false; }
  requestAnimationFrame(loop);
}

// the panel's state, for scripts and the tests (as window.replay on the replay page)
const api = {
  updates: 0, frames: 0, t: null, state: null,
  get uuv() { const b = built?.bodies.find((x) => x.name === 'uuv'); return b?.ned ? { ned: b.ned, world: b.world } : null; },
  get cableEnd() { const c = built?.cable; return c?.ned ? { ned: c.ned, world: c.world } : null; },
  get bodies() { return Object.fromEntries((built?.bodies || []).filter((b) => b.ned).map((b) => [b.name, { ned: b.ned, world: b.world }])); },
  project(x, y, z) {
    const v = new THREE.Vector3(x, y, z).project(camera);
    const r = renderer.domElement.getBoundingClientRect();
    return [(v.x + 1) / 2 * r.width, (1 - v.y) / 2 * r.height, v.z];
  },
  projectObject(name) {
    if (name === 'cableEnd') {
      const c = built?.cable;
      if (!c) return null;
      const a = c.g.attributes.position;
      return api.project(a.getX(c.n - 1), a.getY(c.n - 1), a.getZ(c.n - 1));
    }
    const b = built?.bodies.find((x) => x.name === name);
    if (!b) return null;
    const p = new THREE.Vector3().setFromMatrixPosition(b.obj.matrixWorld);
    return api.project(p.x, p.y, p.z);
  },
  cameraMatrices() {
    const r = renderer.domElement.getBoundingClientRect();
    return { projection: camera.projectionMatrix.elements.slice(), view: camera.matrixWorldInverse.elements.slice(),
      left: r.left, top: r.top, width: r.width, height: r.height };
  },
  nedToThree: (n, e, d) => nedToThree(n, e, d).toArray(),
  // the drawn wave surface (a scenario at sea), as the replay page's replay.seaPatch()
  seaPatch() {
    const w = built?.waves;
    if (!w) return null;
    return { t: w.t, n0: w.n0, e0: w.e0, step: w.step, cells: w.cells, eta: Array.from(w.eta) };
  },
};
window.view3d = api;
requestAnimationFrame(loop);
