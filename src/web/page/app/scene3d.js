// The 3D view: the Node3Ds and hulls of /api/scene drawn with three.js. Every object sits at the scene
// root with its world matrix from the server (column-major, Matrix4.fromArray), so the `frames` of a
// `changes` event move it directly, without a hierarchy to keep in step with the database's. Meshes come
// from the database's Geometry (/api/mesh), never from files. vsd is z-up, as URDF and the robots are.

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { get } from './api.js';
import { isA, on, select, state } from './bus.js';

const container = document.getElementById('scene');
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f5f7);
const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 1000);
camera.up.set(0, 0, 1);
camera.position.set(2.5, -2.5, 2);

scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(3, -2, 5);
scene.add(sun);
const grid = new THREE.GridHelper(4, 20, 0xb0b4bc, 0xd8dbe0);
grid.rotation.x = Math.PI / 2; // three's grid lies in xz; vsd's floor is xy
scene.add(grid);

// WebGL may be missing (a headless browser without a GPU path): the scene graph is kept anyway, so the
// view's state (and window.vsdTest.positions()) stays right; only the drawing is skipped.
let renderer = null;
let controls = null;
try {
  renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  container.append(renderer.domElement);
  controls = new OrbitControls(camera, renderer.domElement);
  controls.addEventListener('change', () => requestRender());
} catch (e) {
  const note = document.createElement('p');
  note.className = 'hint';
  note.textContent = `WebGL is not available (${e.message}); the 3D view is not drawn.`;
  container.append(note);
}

// Two switches over the view: collision hulls (drawn as wireframes; off by default when there are
// visual hulls, which they mostly double) and the axes of the Node3D frames.
const toolbar = document.createElement('div');
toolbar.className = 'scene-toolbar';
toolbar.innerHTML = '<label><input type="checkbox" data-show="collision"> collision hulls</label> ' +
  '<label><input type="checkbox" data-show="axes" checked> frames</label>';
container.append(toolbar);
const show = { collision: null, axes: true }; // collision: null = not chosen by the user yet
for (const box of toolbar.querySelectorAll('input')) {
  box.addEventListener('change', () => {
    show[box.dataset.show] = box.checked;
    applyVisibility();
  });
}

const objects = new Map();   // id -> Object3D (nodes: axes; hulls: meshes)
const hullNode = new Map();  // hull id -> its node's id (what a pick selects)
const meshCache = new Map(); // Geometry id -> Promise<BufferGeometry>
const root = new THREE.Group();
scene.add(root);
let fitted = false;

let renderQueued = false;
function requestRender() {
  if (renderQueued || !renderer) return;
  renderQueued = true;
  requestAnimationFrame(() => {
    renderQueued = false;
    renderer.render(scene, camera);
  });
}

function resize() {
  const w = container.clientWidth;
  const h = container.clientHeight;
  if (!renderer || w === 0 || h === 0) return;
  renderer.setSize(w, h);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  requestRender();
}
new ResizeObserver(resize).observe(container);

function place(object, world) {
  object.matrixAutoUpdate = false;
  object.matrix.fromArray(world);
  object.matrixWorldNeedsUpdate = true;
}

async function meshGeometry(id) {
  if (!meshCache.has(id)) {
    meshCache.set(id, get('/api/mesh', { id }).then((m) => {
      let g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(m.positions, 3));
      if (m.indices?.length) g.setIndex(m.indices);
      // Flat normals: the database holds no normals here, and averaging them over shared vertices
      // smears the edges of CAD parts.
      g = g.toNonIndexed();
      g.computeVertexNormals();
      return g;
    }));
  }
  return meshCache.get(id);
}

// three's cylinder and capsule stand along y; vsd's (URDF's) along z.
const yToZ = new THREE.Matrix4().makeRotationX(Math.PI / 2);

async function shapeGeometry(shape) {
  switch (shape?.kind) {
    case 'Box': return new THREE.BoxGeometry(...shape.size);
    case 'Sphere': return new THREE.SphereGeometry(shape.radius, 24, 16);
    case 'Cylinder': return new THREE.CylinderGeometry(shape.radius, shape.radius, shape.length, 24).applyMatrix4(yToZ);
    case 'Capsule': return new THREE.CapsuleGeometry(shape.radius, shape.length, 6, 16).applyMatrix4(yToZ);
    case 'Plane': {
      // Unbounded in the model; drawn as a 4 m square through the origin, facing `normal`.
      const g = new THREE.PlaneGeometry(4, 4);
      const n = new THREE.Vector3(...(shape.normal || [0, 0, 1])).normalize();
      return g.applyQuaternion(new THREE.Quaternion().setFromUnitVectors(new THREE.Vector3(0, 0, 1), n));
    }
    case 'Mesh': {
      const g = (await meshGeometry(shape.geometry)).clone();
      const s = shape.scale || [1, 1, 1];
      return g.scale(s[0], s[1], s[2]);
    }
    default: return null;
  }
}

function material(hull) {
  const [r, g, b, a] = hull.color || [0.8, 0.8, 0.8, 1];
  const collision = hull.role === 'Collision';
  return new THREE.MeshStandardMaterial({
    color: new THREE.Color(r, g, b),
    transparent: collision || a < 1,
    opacity: collision ? 0.35 : a,
    wireframe: collision,
    side: hull.shape?.kind === 'Plane' ? THREE.DoubleSide : THREE.FrontSide,
  });
}

function clear() {
  for (const object of objects.values()) {
    object.geometry?.dispose?.();
    object.material?.dispose?.();
  }
  root.clear();
  objects.clear();
  hullNode.clear();
}

export async function reload() {
  const answer = await get('/api/scene');
  meshCache.clear();
  clear();
  for (const node of answer.nodes || []) {
    const axes = new THREE.AxesHelper(0.08);
    axes.userData = { id: node.id, kind: 'node' };
    place(axes, node.world);
    objects.set(node.id, axes);
    root.add(axes);
  }
  await Promise.all((answer.hulls || []).map(async (hull) => {
    let geometry = null;
    try {
      geometry = await shapeGeometry(hull.shape);
    } catch (e) {
      console.error(`vsd: hull #${hull.id}: its geometry could not be fetched`, e);
    }
    // A hull without drawable geometry still gets an object: its position is part of the view's state.
    const mesh = geometry ? new THREE.Mesh(geometry, material(hull)) : new THREE.Object3D();
    mesh.userData = { id: hull.id, node: hull.node, kind: 'hull', role: hull.role };
    place(mesh, hull.world);
    // A hull that is also a node of the answer (hulls are Node3Ds) replaces the node's axes.
    const old = objects.get(hull.id);
    if (old) root.remove(old);
    objects.set(hull.id, mesh);
    hullNode.set(hull.id, hull.node);
    root.add(mesh);
  }));
  applyVisibility();
  highlight();
  if (!fitted) fit();
  requestRender();
}

function applyVisibility() {
  const hulls = [...objects.values()].filter((o) => o.userData.kind === 'hull');
  if (show.collision === null) {
    // Until the user chooses: collision hulls only where there is nothing else to see.
    const visual = hulls.some((o) => o.userData.role !== 'Collision');
    toolbar.querySelector('[data-show="collision"]').checked = !visual;
  }
  const collision = toolbar.querySelector('[data-show="collision"]').checked;
  for (const o of objects.values()) {
    if (o.userData.kind === 'node') o.visible = show.axes;
    else if (o.userData.role === 'Collision') o.visible = collision;
  }
  requestRender();
}

// Point the camera at everything drawn (planes left out: they would make the box 4 m wide).
function fit() {
  const box = new THREE.Box3();
  root.updateMatrixWorld(true);
  for (const object of objects.values()) {
    if (object.isMesh && object.geometry.type !== 'PlaneGeometry') box.expandByObject(object);
    else box.expandByPoint(new THREE.Vector3().setFromMatrixPosition(object.matrixWorld));
  }
  if (box.isEmpty()) return;
  fitted = true;
  const center = box.getCenter(new THREE.Vector3());
  const size = Math.max(box.getSize(new THREE.Vector3()).length(), 0.5);
  camera.position.copy(center).add(new THREE.Vector3(1, -1, 0.8).normalize().multiplyScalar(size * 2.2));
  camera.near = size / 100;
  camera.far = size * 100;
  camera.updateProjectionMatrix();
  if (controls) {
    controls.target.copy(center);
    controls.update();
  }
}

// The selected node's hulls (or the selected hull) glow.
function highlight() {
  for (const object of objects.values()) {
    if (!object.isMesh) continue;
    const on = state.selected !== null &&
      (object.userData.id === state.selected || object.userData.node === state.selected);
    object.material.emissive?.setHex(on ? 0x203050 : 0x000000);
  }
  requestRender();
}

// Picking: a click (not a drag of the orbit controls) on a hull selects the hull's node.
if (renderer) {
  const raycaster = new THREE.Raycaster();
  let down = null;
  renderer.domElement.addEventListener('pointerdown', (e) => (down = [e.clientX, e.clientY]));
  renderer.domElement.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
    const rect = renderer.domElement.getBoundingClientRect();
    const pointer = new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1,
                                      -((e.clientY - rect.top) / rect.height) * 2 + 1);
    raycaster.setFromCamera(pointer, camera);
    const hit = raycaster.intersectObjects([...objects.values()].filter((o) => o.isMesh && o.visible))[0];
    if (hit) pick(hit.object.userData.id);
  });
}

export function pick(hullId) {
  select(hullNode.get(hullId) ?? hullId);
}

// Shape and material edits need the hull rebuilt; a refetch of the scene is simplest and rare.
const RESHAPE = new Set(['geometry', 'material', 'color', 'size', 'radius', 'length', 'normal', 'scale',
                         'vertices', 'facets', 'role', 'kind']);
let reloadTimer = null;
function reloadSoon() {
  clearTimeout(reloadTimer);
  reloadTimer = setTimeout(() => reload().catch((e) => console.error('vsd: scene', e)), 100);
}

on('changes', (batch) => {
  let moved = false;
  for (const f of batch.frames || []) {
    const object = objects.get(f.id);
    if (!object) continue;
    place(object, f.world);
    moved = true;
  }
  if (moved) requestRender();
  const created = (batch.created || []).some((c) =>
    ['scene::Node3D', 'scene::Geometry', 'scene::Material'].some((base) => isA(c.class, base)));
  const deleted = (batch.deleted || []).some((id) => objects.has(id));
  const reshaped = (batch.set || []).some((s) => RESHAPE.has(s.property));
  if (created || deleted || reshaped || (batch.moved || []).some((m) => objects.has(m.id))) reloadSoon();
});
on('select', highlight);
on('tab', (name) => name === 'scene' && resize());

// For the browser tests (window.vsdTest): every object's world position, as three.js holds it.
export function positions() {
  const out = {};
  for (const [id, object] of objects) {
    const p = new THREE.Vector3().setFromMatrixPosition(object.matrix);
    out[id] = [p.x, p.y, p.z];
  }
  return out;
}

// Where an object's origin is drawn, in page pixels (null when the view is not drawn): the tests click
// there to pick it.
export function screenPosition(id) {
  const object = objects.get(id);
  if (!object || !renderer) return null;
  const p = new THREE.Vector3().setFromMatrixPosition(object.matrix).project(camera);
  const rect = renderer.domElement.getBoundingClientRect();
  if (rect.width === 0) return null;
  return [rect.left + ((p.x + 1) / 2) * rect.width, rect.top + ((1 - p.y) / 2) * rect.height];
}

export function objectIds() {
  return [...objects.keys()];
}
