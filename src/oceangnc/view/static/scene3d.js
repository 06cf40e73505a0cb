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

