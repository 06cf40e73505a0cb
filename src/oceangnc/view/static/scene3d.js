// What the 3D views of oceangnc share (the replay page, oceangnc view; the console's 3D panel):
// the frame conversion, the vehicle meshes and the tension colours. An ES module importing 'three'
// (both resolved by the page's import map).
import * as THREE from 'three';

// ---- frames -------------------------------------------------------------------------------------
// The run is in NED (x north, y east, z down) with FRD bodies (x forward, y starboard, z down) and
// ZYX Euler angles: R_ned_frd = Rz(psi) Ry(theta) Rx(phi). three.js is right-handed with y up:
//     three (x, y, z) = (east, -down, -north) = C ned,  C = [[0,1,0],[0,0,-1],[-1,0,0]] (det +1).
// A vehicle's mesh is built in its FRD body coordinates; its matrix is [C R | C p]. This function
// (and bodyMatrix below, which applies the same C) is the only place the frames meet.
export function nedToThree(n, e, d, out = new THREE.Vector3()) {
  return out.set(e, -d, -n);
}
export function bodyMatrix(n, e, d, phi, theta, psi, m) {
  const cf = Math.cos(phi), sf = Math.sin(phi), ct = Math.cos(theta), st = Math.sin(theta);
  const cs = Math.cos(psi), ss = Math.sin(psi);
  // R_ned_frd rows
  const r00 = cs * ct, r01 = cs * st * sf - ss * cf, r02 = cs * st * cf + ss * sf;
  const r10 = ss * ct, r11 = ss * st * sf + cs * cf, r12 = ss * st * cf - cs * sf;
  const r20 = -st, r21 = ct * sf, r22 = ct * cf;
  // C R and C p: rows (east, -down, -north)
  m.set(r10, r11, r12, e,
        -r20, -r21, -r22, -d,
        -r00, -r01, -r02, -n,
        0, 0, 0, 1);
  return m;
}

// ---- colours ------------------------------------------------------------------------------------
const STOPS = [[0, [0.15, 0.35, 1.0]], [0.35, [0.1, 0.85, 0.55]], [0.7, [1.0, 0.85, 0.1]], [1, [1.0, 0.15, 0.1]]];
export function tensionColor(f, out) {  // blue (0) - green - yellow - red (1), as the MCAP scene
  f = Math.min(Math.max(f, 0), 1);
  for (let i = 1; i < STOPS.length; i++) {
    if (f <= STOPS[i][0]) {
      const [f0, c0] = STOPS[i - 1], [f1, c1] = STOPS[i];
      const a = (f - f0) / (f1 - f0);
      return out.setRGB(c0[0] + a * (c1[0] - c0[0]), c0[1] + a * (c1[1] - c0[1]), c0[2] + a * (c1[2] - c0[2]));
    }
  }
  return out.setRGB(1, 0.15, 0.1);
}
export const BACKGROUND = 0x0b1724;
export const BODY_COLORS = { usv: 0xdadbe6, uuv: 0xffbf1a, ship: 0xb3402f };

// multisampling unless WebGL is rendered in software (SwiftShader, llvmpipe: headless browsers,
// machines without a GPU), where it costs a third of the frame rate; ?aa=1 / ?aa=0 overrides
export function softwareGL() {
  try {
    const gl = document.createElement('canvas').getContext('webgl');
    const ext = gl && gl.getExtension('WEBGL_debug_renderer_info');
    const name = ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : '';
    gl?.getExtension('WEBGL_lose_context')?.loseContext();
    return /swiftshader|llvmpipe|software/i.test(name);
  } catch (e) { return false; }
}
export const AA = /[?&]aa=1\b/.test(location.search) || (!/[?&]aa=0\b/.test(location.search) && !softwareGL());

// vehicles: meshes in FRD body coordinates (x forward, y starboard, z down)
// the renderer (drawn into ``container``), the scene with its background and lights, and the camera,
// as both the replay page and the console's 3D panel set them up
export function createScene(container) {
  const renderer = new THREE.WebGLRenderer({ antialias: AA, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  container.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(BACKGROUND);
  const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 20000);
  scene.add(new THREE.HemisphereLight(0xcfe6ff, 0x203040, 1.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(0.4, 1, 0.3);
  scene.add(sun);
  return { renderer, scene, camera };
}

export function torpedo(L, D, color) {
  const g = new THREE.Group();
  const mat = new THREE.MeshStandardMaterial({ color, roughness: 0.5, metalness: 0.1 });
  const body = new THREE.CylinderGeometry(D / 2, D / 2, 0.8 * L, 24);
  body.rotateZ(-Math.PI / 2);  // axis y -> x
  body.translate(-0.1 * L, 0, 0);
  const nose = new THREE.ConeGeometry(D / 2, 0.2 * L, 24);
  nose.rotateZ(-Math.PI / 2);
  nose.translate(0.4 * L, 0, 0);
  g.add(new THREE.Mesh(body, mat), new THREE.Mesh(nose, mat));
  const fin = new THREE.MeshStandardMaterial({ color: 0x333333 });
  const vfin = new THREE.Mesh(new THREE.BoxGeometry(0.12 * L, 0.02 * L, 2.2 * D), fin);
  const hfin = new THREE.Mesh(new THREE.BoxGeometry(0.12 * L, 2.2 * D, 0.02 * L), fin);
  vfin.position.x = hfin.position.x = -0.44 * L;
  const top = new THREE.Mesh(new THREE.BoxGeometry(0.1 * L, 0.03 * L, 0.03 * L), new THREE.MeshBasicMaterial({ color: 0xff3030 }));
  top.position.set(-0.44 * L, 0, -1.1 * D);  // red tip of the upper fin: shows roll
  g.add(vfin, hfin, top);
  return g;
}
export function hull(L, B, color) {
  const h = 0.35 * B;
  const s = new THREE.Shape();
  s.moveTo(-L / 2, -B / 2); s.lineTo(0.25 * L, -B / 2); s.lineTo(L / 2, 0); s.lineTo(0.25 * L, B / 2);
  s.lineTo(-L / 2, B / 2); s.lineTo(-L / 2, -B / 2);
  const g = new THREE.ExtrudeGeometry(s, { depth: h, bevelEnabled: false });
  g.translate(0, 0, -0.7 * h);  // 70 % of the hull above the water line (z down)
  const grp = new THREE.Group();
  grp.add(new THREE.Mesh(g, new THREE.MeshStandardMaterial({ color, roughness: 0.6 })));
  const edges = new THREE.LineSegments(new THREE.EdgesGeometry(g), new THREE.LineBasicMaterial({ color: 0x334455 }));
  grp.add(edges);
  return grp;
}


// ---- waves ---------------------------------------------------------------------------------------
// The sea surface of a run with waves, W = {a, omega, k, theta, eps} (arrays of the components, from
// the run's oceangnc.environment.waves.WaveField): the linear (Airy) elevation, up positive, m,
//     eta(n, e, t) = sum_j a_j cos(k_j (n cos theta_j + e sin theta_j) - omega_j t + eps_j)
// as waves.py (its module docstring and wave_kinematics) evaluates it: a second implementation of
// that sum, in double precision, which tests/test_view.py compares with waves.py (1e-6 Hs).
export function waveElevation(W, n, e, t) {
  let eta = 0;
  for (let j = 0; j < W.a.length; j++) {
    eta += W.a[j] * Math.cos(W.k[j] * (n * Math.cos(W.theta[j]) + e * Math.sin(W.theta[j])) - W.omega[j] * t + W.eps[j]);
  }
  return eta;
}

// A square patch of that surface, ``size`` m on a side with ``cells`` x ``cells`` cells, centred on a
// point (snapped to the grid step, so the drawn waves stay fixed in the world while the patch moves).
// Its heights are the same sum on the grid, by the angle-addition form
//     cos(A_i + B_l) = cos A_i cos B_l - sin A_i sin B_l,  A_i = kn n_i - omega t + eps,  B_l = ke e_l
// (kn = k cos theta, ke = k sin theta): 2 (cells + 1) cosines and sines per component instead of
// (cells + 1)^2. ``eta`` holds them in double precision, the mesh in single.
export class WavePatch {
  constructor(W, size, cells, material) {
    this.W = W;
    this.m = W.a.length;
    this.kn = Float64Array.from(W.k, (k, j) => k * Math.cos(W.theta[j]));
    this.ke = Float64Array.from(W.k, (k, j) => k * Math.sin(W.theta[j]));
    this.cells = cells;
    this.step = size / cells;
    const g1 = cells + 1;
    this.g1 = g1;
    this.eta = new Float64Array(g1 * g1);
    this.ca = new Float64Array(g1); this.sa = new Float64Array(g1);
    this.cb = new Float64Array(g1); this.sb = new Float64Array(g1);
    const pos = new Float32Array(g1 * g1 * 3);
    const idx = [];
    for (let i = 0; i < cells; i++) for (let l = 0; l < cells; l++) {
      const a = i * g1 + l, b = a + 1, c = a + g1, d = c + 1;
      idx.push(a, b, c, b, d, c);  // counter-clockwise seen from above: the front faces up
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    geo.setAttribute('color', new THREE.BufferAttribute(new Float32Array(g1 * g1 * 3), 3));
    geo.setIndex(idx);
    // colour by elevation (troughs dark, crests light) over +-amp, the largest elevation the
    // components can reach together (sum of a) scaled down to the usual crest (Hs / 2 ~ 2 sigma)
    this.amp = Math.max(1e-6, 2 * Math.sqrt(0.5 * W.a.reduce((s, a) => s + a * a, 0)));
    this.mesh = new THREE.Mesh(geo, material);
    this.mesh.frustumCulled = false;
    this.n0 = NaN; this.e0 = NaN; this.t = NaN;
  }
  // heights at time t of the patch centred near (cn, ce); nothing to do when neither moved
  update(cn, ce, t) {
    const h = this.step, half = this.cells / 2;
    const n0 = (Math.round(cn / h) - half) * h, e0 = (Math.round(ce / h) - half) * h;
    if (n0 === this.n0 && e0 === this.e0 && t === this.t) return false;
    this.n0 = n0; this.e0 = e0; this.t = t;
    const { W, g1, eta, ca, sa, cb, sb } = this;
    eta.fill(0);
    for (let j = 0; j < this.m; j++) {
      const a = W.a[j], ph = -W.omega[j] * t + W.eps[j], kn = this.kn[j], ke = this.ke[j];
      for (let i = 0; i < g1; i++) {
        const A = kn * (n0 + i * h) + ph;
        ca[i] = a * Math.cos(A); sa[i] = a * Math.sin(A);
        const B = ke * (e0 + i * h);
        cb[i] = Math.cos(B); sb[i] = Math.sin(B);
      }
      for (let i = 0; i < g1; i++) {
        const c = ca[i], s = sa[i], row = i * g1;
        for (let l = 0; l < g1; l++) eta[row + l] += c * cb[l] - s * sb[l];
      }
    }
    const pos = this.mesh.geometry.attributes.position.array, col = this.mesh.geometry.attributes.color.array;
    // shading computed here, not by the GPU (an unlit material: software WebGL draws it 5 times faster than
    // a lit one): the colour by elevation times a Lambert factor of the slope (central differences) against
    // the scene's sun, three direction (0.4, 1, 0.3); the surface normal is (-eta_e, 1, eta_n) in three
    const Lx = 0.4 / 1.118, Ly = 1 / 1.118, Lz = 0.3 / 1.118, inv = 1 / (2 * h), last = g1 - 1;
    for (let i = 0; i < g1; i++) for (let l = 0; l < g1; l++) {
      const v = i * g1 + l;  // three (x, y, z) = (east, up, -north)
      pos[3 * v] = e0 + l * h; pos[3 * v + 1] = eta[v]; pos[3 * v + 2] = -(n0 + i * h);
      const en = (eta[(i < last ? i + 1 : i) * g1 + l] - eta[(i > 0 ? i - 1 : i) * g1 + l]) * inv;
      const ee = (eta[i * g1 + (l < last ? l + 1 : l)] - eta[i * g1 + (l > 0 ? l - 1 : l)]) * inv;
      const lam = Math.max(0, (-ee * Lx + Ly + en * Lz) / Math.sqrt(ee * ee + 1 + en * en));
      const f = Math.min(1, Math.max(0, 0.5 + 0.5 * eta[v] / this.amp)), s = 0.35 + 0.75 * lam;
      col[3 * v] = (0.03 + 0.3 * f) * s; col[3 * v + 1] = (0.2 + 0.4 * f) * s; col[3 * v + 2] = (0.42 + 0.4 * f) * s;
    }
    this.mesh.geometry.attributes.position.needsUpdate = true;
    this.mesh.geometry.attributes.color.needsUpdate = true;
    return true;
  }
}
