// The CF graph viewer that `cfinspect GRAPH --html OUT.html` writes. The page carries the
// graph file's JSON text and, optionally, a cfreplay CSV and its trajectory in <script>
// elements; everything else (geometry, contact planes, filters) is computed here.
// window.cfViewer is the test hook (tools/cfinspect/viewer/test/viewer_test.mjs).

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { parseReplay, parseTrajectory } from './csv.js';

const TYPES = ['f-f', 'e-f', 'f-e', 'v-f', 'f-v', 'e-e'];
const KIND_NAME = { v: 'vertex', e: 'edge', f: 'face' };
const PC_COLOURS = ['#e6194b', '#1f9e3a', '#2f5de0'];  // one per PC of a CF (at most 3)
const LIST_LIMIT = 2000;  // rows drawn in the CF list; the rest is reached by filters or id

const $ = (id) => document.getElementById(id);
const v3 = (a) => new THREE.Vector3(a[0], a[1], a[2]);
const fmt = (x, d = 3) => Number(x).toFixed(d);

function embedded(id) {
  const el = document.getElementById(id);
  return el && el.textContent.trim() ? JSON.parse(el.textContent) : null;
}

// ---------------------------------------------------------------------------------------
// Graph and geometry
// ---------------------------------------------------------------------------------------

const graph = embedded('cf-graph');
const meta = embedded('cf-meta') || {};
const modelA = graph.models.A, modelB = graph.models.B;

// Outgoing transitions per CF.
const out = graph.cfs.map(() => []);
for (const t of graph.transitions) out[t.from].push(t);

const pcText = (pc) => `${pc.type}:${pc.a}:${pc.b}`;
const pcsText = (cf) => cf.pcs.map(pcText).join('; ');

// Newell's normal of a loop of vertex indices (counter-clockwise seen from outside).
function loopNormal(verts, loop) {
  const n = new THREE.Vector3();
  for (let i = 0; i < loop.length; ++i) {
    const p = verts[loop[i]], q = verts[loop[(i + 1) % loop.length]];
    n.x += (p[1] - q[1]) * (p[2] + q[2]);
    n.y += (p[2] - q[2]) * (p[0] + q[0]);
    n.z += (p[0] - q[0]) * (p[1] + q[1]);
  }
  return n.normalize();
}

// Triangles of face f (with holes) as a flat position array, in the model's frame.
function faceTriangles(model, f) {
  const verts = model.vertices, loops = model.faces[f].loops;
  const n = loopNormal(verts, loops[0]);
  const u = new THREE.Vector3().crossVectors(Math.abs(n.x) < 0.9 ? new THREE.Vector3(1, 0, 0) : new THREE.Vector3(0, 1, 0), n).normalize();
  const w = new THREE.Vector3().crossVectors(n, u);
  const flat = (loop) => loop.map((i) => { const p = v3(verts[i]); return new THREE.Vector2(p.dot(u), p.dot(w)); });
  const tris = THREE.ShapeUtils.triangulateShape(flat(loops[0]), loops.slice(1).map(flat));
  const all = loops.flat();
  const pos = [];
  for (const tri of tris) for (const k of tri) pos.push(...verts[all[k]]);
  return pos;
}

function faceCentroid(model, f) {
  const loop = model.faces[f].loops[0];
  const c = new THREE.Vector3();
  for (const i of loop) c.add(v3(model.vertices[i]));
  return c.divideScalar(loop.length);
}

function modelSize(model) {
  const box = new THREE.Box3();
  for (const p of model.vertices) box.expandByPoint(v3(p));
  return box.getSize(new THREE.Vector3()).length();
}

// A model as a group: faces (flat shaded), edges, vertices.
function modelGroup(model, colour) {
  const group = new THREE.Group();
  const pos = [];
  for (let f = 0; f < model.faces.length; ++f) pos.push(...faceTriangles(model, f));
  const geom = new THREE.BufferGeometry();
  geom.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  geom.computeVertexNormals();  // triangles do not share vertices: flat normals
  const material = new THREE.MeshLambertMaterial({ color: colour, side: THREE.DoubleSide, polygonOffset: true,
    polygonOffsetFactor: 1, polygonOffsetUnits: 1, transparent: true, opacity: 1 });
  group.add(new THREE.Mesh(geom, material));
  const ep = [];
  for (const [i, j] of model.edges) ep.push(...model.vertices[i], ...model.vertices[j]);
  const eg = new THREE.BufferGeometry();
  eg.setAttribute('position', new THREE.Float32BufferAttribute(ep, 3));
  group.add(new THREE.LineSegments(eg, new THREE.LineBasicMaterial({ color: 0x333333 })));
  const vg = new THREE.BufferGeometry();
  vg.setAttribute('position', new THREE.Float32BufferAttribute(model.vertices.flat(), 3));
  group.add(new THREE.Points(vg, new THREE.PointsMaterial({ color: 0x111111, size: 4, sizeAttenuation: false })));
  group.userData.material = material;
  return group;
}

// ---------------------------------------------------------------------------------------
// Scene
// ---------------------------------------------------------------------------------------

const view = $('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });  // readable pixels
renderer.setPixelRatio(window.devicePixelRatio || 1);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xffffff);
scene.add(new THREE.HemisphereLight(0xffffff, 0x666677, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 0.8);
sun.position.set(1, 3, 2);  // from above: the models and gravity are y-up (docs/spec.md, section 2)
scene.add(sun);

const size = Math.max(modelSize(modelA), modelSize(modelB));
const groupB = modelGroup(modelB, 0xb8b8b0);
const groupA = modelGroup(modelA, 0x8fb8de);
groupA.matrixAutoUpdate = false;
scene.add(groupB, groupA);
const overlay = new THREE.Group();  // highlights, planes, frames, arrows: rebuilt per CF
scene.add(overlay);

const camera = new THREE.PerspectiveCamera(40, 1, size / 100, size * 100);
const centreB = new THREE.Box3().setFromObject(groupB).getCenter(new THREE.Vector3());
camera.up.set(0, 1, 0);  // y up, as the models are drawn and gravity points (-y)
camera.position.copy(centreB).add(new THREE.Vector3(1.2, 1.1, 1.6).multiplyScalar(size));
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.copy(centreB);
controls.update();
const headlight = new THREE.DirectionalLight(0xffffff, 1.2);  // so that no face towards the viewer is dark
headlight.position.set(0.3, 0.5, 1);
camera.add(headlight);
scene.add(camera);

// Look at the contacts of the CF shown from the side of A (the planes' normals point into
// A), tilted so that no contact plane is seen edge-on: the contacts are often behind B.
function aim() {
  if (!state.highlighted.length) return;
  const c = new THREE.Vector3(), n = new THREE.Vector3();
  for (const h of state.highlighted) { c.add(v3(h.plane.point)); n.add(v3(h.plane.normal)); }
  c.divideScalar(state.highlighted.length);
  if (n.lengthSq() < 1e-6) n.set(0, 1, 0);
  n.normalize();
  // Of a few directions around the mean normal, the one that sees every contact plane most
  // squarely from A's side (the smallest cosine with a plane's normal is largest).
  let dir = n.clone(), best = -Infinity;
  for (const g of [[1, -1, 1], [1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, -1]]) {
    const d = n.clone().add(new THREE.Vector3(...g).normalize().multiplyScalar(0.8)).normalize();
    // Capped: beyond 0.75 an oblique view (the first in the list) beats a head-on one.
    const score = Math.min(0.75, ...state.highlighted.map((h) => d.dot(v3(h.plane.normal))));
    if (score > best + 1e-9) { best = score; dir = d; }
  }
  controls.target.copy(c);
  camera.position.copy(c).addScaledVector(dir, 1.7 * size);
  controls.update();
}
controls.addEventListener('change', render);  // drags; render() must not call update() (it fires 'change')

function resize() {
  const w = Math.max(view.clientWidth, 50), h = Math.max(view.clientHeight, 50);
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  render();
}
window.addEventListener('resize', resize);

// The axis triad: B's (the world's) axes as the camera sees them, in the lower left corner.
const triad = { scene: new THREE.Scene(), camera: new THREE.OrthographicCamera(-1.6, 1.6, 1.6, -1.6, 0.1, 10), px: 130 };
function textSprite(text, colour) {
  const c = document.createElement('canvas');
  c.width = c.height = 64;
  const g = c.getContext('2d');
  g.font = 'bold 44px sans-serif';
  g.fillStyle = colour;
  g.textAlign = 'center';
  g.textBaseline = 'middle';
  g.fillText(text, 32, 34);
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(c), depthTest: false }));
  sprite.scale.set(0.6, 0.6, 1);
  return sprite;
}
const TRIAD_COLOURS = ['#e02020', '#20a020', '#2040e0'];  // x red, y green, z blue
[[1, 0, 0], [0, 1, 0], [0, 0, 1]].forEach((d, k) => {
  triad.scene.add(new THREE.ArrowHelper(v3(d), new THREE.Vector3(), 1, TRIAD_COLOURS[k], 0.36, 0.2));
  const label = textSprite('xyz'[k], TRIAD_COLOURS[k]);
  label.position.copy(v3(d).multiplyScalar(1.38));
  triad.scene.add(label);
});
function triadView() {
  triad.camera.position.copy(camera.position).sub(controls.target).normalize().multiplyScalar(4);
  triad.camera.up.copy(camera.up);
  triad.camera.lookAt(0, 0, 0);
  triad.camera.updateMatrixWorld(true);
}

renderer.autoClear = false;
function render() {
  renderer.clear();
  renderer.render(scene, camera);
  triadView();
  const size2 = renderer.getSize(new THREE.Vector2()), s = triad.px;
  renderer.setScissorTest(true);
  renderer.setScissor(0, 0, s, s);
  renderer.setViewport(0, 0, s, s);
  renderer.clearDepth();
  renderer.render(triad.scene, triad.camera);
  renderer.setScissorTest(false);
  renderer.setViewport(0, 0, size2.x, size2.y);
}

// Pose {R: rows, t} as a Matrix4 (x_B = R x_A + t).
function poseMatrix(pose) {
  const R = pose.R, t = pose.t;
  return new THREE.Matrix4().set(R[0][0], R[0][1], R[0][2], t[0], R[1][0], R[1][1], R[1][2], t[1],
    R[2][0], R[2][1], R[2][2], t[2], 0, 0, 0, 1);
}

function setPoseA(pose) {
  groupA.matrix.copy(poseMatrix(pose));
  groupA.matrixWorldNeedsUpdate = true;
  groupA.updateMatrixWorld(true);
}

// ---------------------------------------------------------------------------------------
// Contact elements, planes and task frames of a CF at a pose
// ---------------------------------------------------------------------------------------

// Element `index` of kind k ('v'|'e'|'f') of a model, in world coordinates under matrix m.
function element(model, k, index, m) {
  const P = (i) => v3(model.vertices[i]).applyMatrix4(m);
  if (k === 'v') return { kind: 'vertex', point: P(index) };
  if (k === 'e') {
    const [i, j] = model.edges[index];
    return { kind: 'edge', p: P(i), q: P(j), point: P(i).add(P(j)).multiplyScalar(0.5) };
  }
  const normal = loopNormal(model.vertices, model.faces[index].loops[0]).transformDirection(m);
  return { kind: 'face', point: faceCentroid(model, index).applyMatrix4(m), normal };
}

// Closest point between the lines of two edges (midpoint of the shortest segment).
function edgeEdgePoint(ea, eb) {
  const d1 = ea.q.clone().sub(ea.p), d2 = eb.q.clone().sub(eb.p), r = ea.p.clone().sub(eb.p);
  const a = d1.dot(d1), b = d1.dot(d2), c = d2.dot(d2), d = d1.dot(r), e = d2.dot(r);
  const den = a * c - b * b;
  const s = den > 1e-12 ? THREE.MathUtils.clamp((b * e - c * d) / den, 0, 1) : 0.5;
  const u = den > 1e-12 ? THREE.MathUtils.clamp((a * e - b * d) / den, 0, 1) : 0.5;
  return ea.p.clone().addScaledVector(d1, s).add(eb.p.clone().addScaledVector(d2, u)).multiplyScalar(0.5);
}

// Contact plane (normal into A, point) and task frame x axis of one PC.
function contactFrame(pc, ea, eb, mA, planeFromFile) {
  const [ka, kb] = [pc.type[0], pc.type[2]];
  let n, point, x = null;
  if (kb === 'f') { n = eb.normal.clone(); point = ea.point.clone(); if (ka === 'e') x = ea.q.clone().sub(ea.p); }
  else if (ka === 'f') { n = ea.normal.clone().negate(); point = eb.point.clone(); if (kb === 'e') x = eb.q.clone().sub(eb.p); }
  else {  // e-e: the plane of both edges, its normal pointing into A
    x = ea.q.clone().sub(ea.p);
    n = x.clone().cross(eb.q.clone().sub(eb.p)).normalize();
    point = edgeEdgePoint(ea, eb);
    const centreA = new THREE.Vector3().setFromMatrixPosition(mA);
    if (n.dot(centreA.clone().sub(point)) < 0) n.negate();
  }
  if (planeFromFile) {  // cfgen's plane at the witness, when the file has it
    n = v3(planeFromFile).normalize();
    point.addScaledVector(n, planeFromFile[3] - n.dot(point));
  }
  if (!x || x.clone().cross(n).lengthSq() < 1e-12) x = new THREE.Vector3().crossVectors(n, Math.abs(n.x) < 0.9 ? new THREE.Vector3(1, 0, 0) : new THREE.Vector3(0, 1, 0));
  x.addScaledVector(n, -x.dot(n)).normalize();
  return { normal: n, point, x, y: new THREE.Vector3().crossVectors(n, x) };
}

function highlightMesh(model, k, index, colour) {
  const m = new THREE.MeshBasicMaterial({ color: colour, side: THREE.DoubleSide, depthTest: k === 'f',
    polygonOffset: true, polygonOffsetFactor: -2, polygonOffsetUnits: -2 });
  if (k === 'f') {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(faceTriangles(model, index), 3));
    return new THREE.Mesh(g, m);
  }
  if (k === 'v') {
    const s = new THREE.Mesh(new THREE.SphereGeometry(size * 0.015, 16, 12), m);
    s.position.copy(v3(model.vertices[index]));
    s.renderOrder = 2;
    return s;
  }
  const [i, j] = model.edges[index];
  const p = v3(model.vertices[i]), q = v3(model.vertices[j]);
  const tube = new THREE.Mesh(new THREE.CylinderGeometry(size * 0.009, size * 0.009, p.distanceTo(q), 8), m);
  tube.position.copy(p).add(q).multiplyScalar(0.5);
  tube.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), q.clone().sub(p).normalize());
  tube.renderOrder = 2;
  return tube;
}

const overlayA = new THREE.Group();  // A's highlights move with A
overlayA.matrixAutoUpdate = false;

function clearOverlay() {
  for (const g of [overlay, overlayA]) {
    // ArrowHelpers share one geometry among all of them (the replay's arrows too): keep it.
    g.traverse((o) => {
      if (o.geometry && !(o.parent instanceof THREE.ArrowHelper)) o.geometry.dispose();
      if (o.material) o.material.dispose();
    });
    g.clear();
  }
  overlay.add(overlayA);
}

// ---------------------------------------------------------------------------------------
// State and the test hook
// ---------------------------------------------------------------------------------------

const state = {
  ready: false,
  selected: -1,
  highlighted: [],  // [{pc, colour, a: {model, kind, index, drawnAt}, b: {...}, plane}] of the CF shown
  listed: [],       // ids in the CF list after the filters
  listWindow: [0, 0],  // the positions in `listed` drawn as rows
  pose: null,       // A's pose drawn
  replay: null,     // {rows, poses, tick, playing}
};

function describeFreedoms(cf) {
  if (cf.dof === undefined && cf.translation_dof === undefined) return 'freedoms: not in the file';
  const rot = cf.dof - cf.translation_dof;
  return `freedoms: ${cf.dof} dof (${cf.translation_dof} translational, ${rot} more with rotation); ` +
    `pure rotation ${cf.pure_rotation ? 'possible' : 'not possible'}`;
}

// Draw CF `id` with A at `pose` (default its witness). `fromReplay` keeps the list as it is.
function showCf(id, pose, fromReplay = false) {
  clearOverlay();
  state.highlighted = [];
  state.selected = id;
  const cf = id >= 0 ? graph.cfs[id] : null;
  state.pose = pose || (cf ? cf.witness : state.pose);
  if (state.pose) setPoseA(state.pose);
  overlayA.matrix.copy(groupA.matrix);
  overlayA.matrixWorldNeedsUpdate = true;
  if (!fromReplay) for (const el of document.querySelectorAll('#cf-list div.selected')) el.classList.remove('selected');
  if (!cf) {
    $('cf-title').textContent = fromReplay ? 'no contact' : 'no CF selected';
    $('pcs').innerHTML = ''; $('freedoms').textContent = ''; $('neighbours').innerHTML = ''; $('pose').textContent = '';
    render();
    return;
  }
  const mA = groupA.matrix, mB = new THREE.Matrix4();
  $('cf-title').textContent = `CF ${id}: ${cf.pcs.length} PC${cf.pcs.length > 1 ? 's' : ''}`;
  const ul = $('pcs');
  ul.innerHTML = '';
  cf.pcs.forEach((pc, k) => {
    const colour = PC_COLOURS[k % PC_COLOURS.length];
    const [ka, kb] = [pc.type[0], pc.type[2]];
    const meshA = highlightMesh(modelA, ka, pc.a, colour), meshB = highlightMesh(modelB, kb, pc.b, colour);
    overlayA.add(meshA);
    overlay.add(meshB);
    overlay.updateMatrixWorld(true);
    // Where the highlights are drawn (world frame, bounding-box centres), for the test hook.
    const centre = (mesh) => new THREE.Box3().setFromObject(mesh).getCenter(new THREE.Vector3()).toArray();
    const ea = element(modelA, ka, pc.a, mA), eb = element(modelB, kb, pc.b, mB);
    const frame = contactFrame(pc, ea, eb, mA, pose ? null : cf.planes && cf.planes[k]);
    if ($('show-planes').checked) {
      const plane = new THREE.Mesh(new THREE.PlaneGeometry(size * 0.35, size * 0.35),
        new THREE.MeshBasicMaterial({ color: colour, transparent: true, opacity: 0.22, side: THREE.DoubleSide, depthWrite: false }));
      plane.quaternion.setFromRotationMatrix(new THREE.Matrix4().makeBasis(frame.x, frame.y, frame.normal));
      plane.position.copy(frame.point);
      overlay.add(plane);
      const len = size * 0.15;
      for (const [dir, c] of [[frame.x, 0xcc3333], [frame.y, 0x33aa33], [frame.normal, 0x3333cc]])
        overlay.add(new THREE.ArrowHelper(dir, frame.point, len, c, len * 0.25, len * 0.12));
    }
    state.highlighted.push({ pc: pcText(pc), colour,
      a: { model: 'A', kind: KIND_NAME[ka], index: pc.a, drawnAt: centre(meshA) },
      b: { model: 'B', kind: KIND_NAME[kb], index: pc.b, drawnAt: centre(meshB) },
      plane: { normal: frame.normal.toArray(), point: frame.point.toArray() } });
    const li = document.createElement('li');
    li.className = 'pc';
    li.dataset.pc = pcText(pc);
    li.innerHTML = `<span class="swatch" style="background:${colour}"></span>${pcText(pc)}` +
      ` <span class="muted">(A ${KIND_NAME[ka]} ${pc.a}, B ${KIND_NAME[kb]} ${pc.b})</span>`;
    ul.appendChild(li);
  });
  $('freedoms').textContent = describeFreedoms(cf);
  const t = state.pose.t;
  $('pose').textContent = `${pose ? 'A at the replay pose' : 'A at the witness pose'}: t = (${t.map((x) => fmt(x, 2)).join(', ')}) mm`;
  const nb = $('neighbours');
  nb.innerHTML = '';
  for (const kind of ['gain', 'lose', 'change']) {
    const list = out[id].filter((tr) => tr.kind === kind);
    const h = document.createElement('div');
    h.innerHTML = `<b>${kind}</b> <span class="muted">(${list.length})</span>`;
    nb.appendChild(h);
    for (const tr of list) {
      const b = document.createElement('button');
      b.className = 'nb';
      b.dataset.to = tr.to;
      b.dataset.kind = kind;
      b.textContent = `CF ${tr.to}: ${pcsText(graph.cfs[tr.to])}`;
      b.onclick = () => select(tr.to);
      nb.appendChild(b);
    }
  }
  if (!fromReplay) showInList(id);
  render();
}

function select(id) {
  if (state.replay) pause();
  drawGap(null, null);  // the device belongs to a replay's tick
  showCf(id, null);
  aim();
  render();
}

// ---------------------------------------------------------------------------------------
// CF list and filters
// ---------------------------------------------------------------------------------------

const typeBoxes = {};
for (const t of TYPES) {
  const l = document.createElement('label');
  l.innerHTML = `<input type="checkbox" checked data-type="${t}"> ${t}`;
  $('f-types').appendChild(l);
  typeBoxes[t] = l.firstChild;
}

function applyFilters() {
  const num = $('f-num').value ? Number($('f-num').value) : 0;
  const types = new Set(TYPES.filter((t) => typeBoxes[t].checked));
  const model = $('f-model').value, kind = $('f-kind').value, idxText = $('f-index').value;
  const index = idxText === '' ? -1 : Number(idxText);
  state.listed = [];
  for (const cf of graph.cfs) {
    if (num && cf.pcs.length !== num) continue;
    if (!cf.pcs.some((pc) => types.has(pc.type))) continue;
    if (model && index >= 0) {
      const hit = cf.pcs.some((pc) => model === 'A' ? pc.type[0] === kind && pc.a === index : pc.type[2] === kind && pc.b === index);
      if (!hit) continue;
    }
    state.listed.push(cf.id);
  }
  drawList();
}

// The listed CFs drawn as rows: at most LIST_LIMIT of them, a window that holds the selected
// CF (a graph of 100,000 CFs lists the rows around it).
function drawList() {
  const at = state.listed.indexOf(state.selected);
  const from = state.listed.length <= LIST_LIMIT || at < LIST_LIMIT / 2 ? 0
    : Math.min(at - LIST_LIMIT / 2, state.listed.length - LIST_LIMIT);
  const shown = state.listed.slice(from, from + LIST_LIMIT);
  state.listWindow = [from, from + shown.length];
  const html = [];
  for (const id of shown)
    html.push(`<div data-id="${id}"${id === state.selected ? ' class="selected"' : ''}>${id}: ${pcsText(graph.cfs[id])}</div>`);
  $('cf-list').innerHTML = html.join('');
  $('count').textContent = `${state.listed.length} of ${graph.cfs.length} CFs` +
    (state.listed.length > LIST_LIMIT ? ` (${from + 1} to ${from + shown.length} listed)` : '');
}

// The selected CF's row marked and scrolled to the middle of the list (only the list scrolls).
function showInList(id) {
  let row = document.querySelector(`#cf-list div[data-id="${id}"]`);
  if (!row && state.listed.includes(id)) { drawList(); row = document.querySelector(`#cf-list div[data-id="${id}"]`); }
  if (!row) return;
  row.classList.add('selected');
  const list = $('cf-list'), r = row.getBoundingClientRect(), l = list.getBoundingClientRect();
  list.scrollTop += r.top - l.top - (list.clientHeight - r.height) / 2;
}

$('cf-list').addEventListener('click', (e) => {
  const row = e.target.closest('div[data-id]');
  if (row) select(Number(row.dataset.id));
});
for (const id of ['f-num', 'f-model', 'f-kind', 'f-index']) $(id).addEventListener('input', applyFilters);
$('f-types').addEventListener('change', applyFilters);

function search() {
  const text = $('search').value.trim();
  const id = Number(text);
  if (text === '' || !Number.isInteger(id) || id < 0 || id >= graph.cfs.length) {
    $('search-msg').textContent = `no CF ${text} (ids 0 to ${graph.cfs.length - 1})`;
    return;
  }
  $('search-msg').textContent = '';
  select(id);
}
$('go').onclick = search;
$('search').addEventListener('keydown', (e) => { if (e.key === 'Enter') search(); });
// Keys, outside the inputs: up/down step through the listed CFs, space plays or pauses.
document.addEventListener('keydown', (e) => {
  if (e.target.closest('input, select, button')) return;
  if (e.key === 'ArrowDown' || e.key === 'ArrowUp') {
    const at = state.listed.indexOf(state.selected);
    const next = state.listed[Math.max(0, Math.min(state.listed.length - 1, at + (e.key === 'ArrowDown' ? 1 : -1)))];
    if (next !== undefined) { select(next); e.preventDefault(); }
  } else if (e.key === ' ' && state.replay) {
    state.replay.playing ? pause() : play();
    e.preventDefault();
  }
});
$('show-planes').onchange = () => redraw();
$('see-through').onchange = () => {
  for (const g of [groupA, groupB]) {
    g.userData.material.opacity = $('see-through').checked ? 0.45 : 1;
    g.userData.material.depthWrite = !$('see-through').checked;
  }
  render();
};

function redraw() {
  if (state.replay && state.replay.poses) setTick(state.replay.tick);
  else showCf(state.selected, null);
}

// ---------------------------------------------------------------------------------------
// Replay: a cfreplay CSV, with the trajectory's poses when given
// ---------------------------------------------------------------------------------------

const arrows = { F: new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, 0xd04010),
  M: new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, 0x8020c0) };
arrows.F.visible = arrows.M.visible = false;
for (const a of [arrows.F, arrows.M])  // drawn over the models: A's origin is inside A
  a.traverse((o) => { if (o.material) { o.material.depthTest = false; o.renderOrder = 3; } });
scene.add(arrows.F, arrows.M);

// The device where the hand holds A, when it is pressed beyond the proxy: A's edges drawn
// there, and a line from where A is rendered (the proxy) to it.
const device = new THREE.Group();
{
  const ep = [];
  for (const [i, j] of modelA.edges) ep.push(...modelA.vertices[i], ...modelA.vertices[j]);
  const eg = new THREE.BufferGeometry();
  eg.setAttribute('position', new THREE.Float32BufferAttribute(ep, 3));
  device.userData.ghost = new THREE.LineSegments(eg, new THREE.LineBasicMaterial({ color: 0xe07000, transparent: true, opacity: 0.8, depthTest: false }));
  device.userData.ghost.matrixAutoUpdate = false;
  const lg = new THREE.BufferGeometry();
  lg.setAttribute('position', new THREE.Float32BufferAttribute([0, 0, 0, 0, 0, 0], 3));
  device.userData.line = new THREE.Line(lg, new THREE.LineBasicMaterial({ color: 0xe07000, depthTest: false }));
  for (const o of [device.userData.ghost, device.userData.line]) { o.renderOrder = 4; device.add(o); }
  device.visible = false;
  scene.add(device);
}
const GAP_SHOWN_MM = 1e-6;  // below this the device is at the proxy: nothing to draw

// Draws the device at `devicePose` against A drawn at `rendered`; returns the gap (mm).
function drawGap(devicePose, rendered) {
  if (!devicePose || !rendered) { device.visible = false; return 0; }
  const a = v3(rendered.t), b = v3(devicePose.t), gap = a.distanceTo(b);
  device.visible = gap > GAP_SHOWN_MM;
  device.userData.ghost.matrix.copy(poseMatrix(devicePose));
  device.userData.ghost.matrixWorldNeedsUpdate = true;
  const pos = device.userData.line.geometry.attributes.position;
  pos.setXYZ(0, a.x, a.y, a.z);
  pos.setXYZ(1, b.x, b.y, b.z);
  pos.needsUpdate = true;
  device.userData.line.geometry.computeBoundingSphere();
  return gap;
}

function loadReplay(csvText, trajText, name) {
  pause();
  const rows = parseReplay(csvText, name, graph.cfs.length);
  let poses = null;
  if (trajText) {
    poses = parseTrajectory(trajText, 'trajectory');
    if (poses.length !== rows.length)
      throw new Error(`the trajectory has ${poses.length} poses but ${name} has ${rows.length} rows`);
  }
  // Arrow scales: the 90th percentile of the magnitudes, so that a few impact spikes do not
  // shrink every other arrow to nothing (longer arrows are capped).
  const scale = (key) => {
    const m = rows.map((r) => r[key].length()).filter((x) => x > 1e-9).sort((a, b) => a - b);
    return m.length ? m[Math.floor(0.9 * (m.length - 1))] : 1;
  };
  const maxF = scale('F'), maxM = scale('M');
  state.replay = { rows, poses, tick: 0, playing: false, maxF, maxM, name };
  $('time').max = rows.length - 1;
  $('time').disabled = false;
  $('play').disabled = false;
  $('replay-msg').textContent = `${name}: ${rows.length} ticks, ${fmt(rows[rows.length - 1].t - rows[0].t)} s` +
    (poses || rows[0].proxy ? '' : ' (no trajectory: A is drawn at the witness of each tick\'s CF)');
  $('replay-msg').className = 'muted';
  setTick(0);
  const k = rows.findIndex((row) => row.cf >= 0);  // aim at the first contact
  if (k >= 0) { setTick(k); aim(); setTick(0); }
}

function setTick(i) {
  const r = state.replay;
  if (!r) return;
  r.tick = Math.max(0, Math.min(r.rows.length - 1, i));
  const row = r.rows[r.tick];
  // A where it was rendered: the proxy pose when the CSV has it (the device may be inside
  // B), else the trajectory's pose, else the witness of the tick's CF.
  const pose = row.proxy ? row.proxy : r.poses ? r.poses[r.tick] : row.cf >= 0 ? graph.cfs[row.cf].witness : null;
  showCf(row.cf, pose, true);
  r.gap = row.proxy && r.poses ? drawGap(r.poses[r.tick], row.proxy) : drawGap(null, null);
  if (!pose && row.cf < 0) { arrows.F.visible = arrows.M.visible = false;
for (const a of [arrows.F, arrows.M])  // drawn over the models: A's origin is inside A
  a.traverse((o) => { if (o.material) { o.material.depthTest = false; o.renderOrder = 3; } }); }
  const origin = new THREE.Vector3().setFromMatrixPosition(groupA.matrix);  // moments are about A's origin
  for (const [key, vec, max] of [['F', row.F, r.maxF], ['M', row.M, r.maxM]]) {
    const a = arrows[key], len = vec.length();
    a.visible = len > 1e-9 && (pose !== null || row.cf >= 0);
    if (!a.visible) continue;
    const l = Math.min(0.3 * size * len / max, 0.6 * size);
    a.position.copy(origin);
    a.setDirection(vec.clone().divideScalar(len));
    a.setLength(l, Math.min(l * 0.3, size * 0.06), Math.min(l * 0.15, size * 0.03));
  }
  $('time').value = r.tick;
  $('tick-info').textContent =
    `tick ${r.tick + 1}/${r.rows.length}  t = ${fmt(row.t)} s  CF ${row.cf}${row.cf >= 0 ? ` {${row.pcs}}` : ''}  motion ${row.motion}  ${row.status}\n` +
    `F = (${row.F.toArray().map((x) => fmt(x, 2)).join(', ')}) N  |F| ${fmt(row.F.length(), 2)}  (orange)\n` +
    `M = (${row.M.toArray().map((x) => fmt(x, 1)).join(', ')}) N·mm  |M| ${fmt(row.M.length(), 1)}  (purple)` +
    (row.proxy && r.poses ? `\ndevice ${fmt(r.gap, 3)} mm beyond the proxy${r.gap > GAP_SHOWN_MM ? ' (orange: A where the hand holds it)' : ''}` : '');
  render();
}

let last = 0;
function frame(now) {
  const r = state.replay;
  if (!r || !r.playing) return;
  const dt = Math.min(0.1, (now - last) / 1000) * Number($('speed').value);
  last = now;
  const target = r.rows[r.tick].t + dt;
  let i = r.tick;
  while (i + 1 < r.rows.length && r.rows[i + 1].t <= target) ++i;
  if (i === r.tick && i + 1 < r.rows.length) ++i;  // at least one tick per frame
  setTick(i);
  if (r.tick >= r.rows.length - 1) { pause(); return; }
  requestAnimationFrame(frame);
}

function play() {
  const r = state.replay;
  if (!r || r.playing) return;
  if (r.tick >= r.rows.length - 1) r.tick = 0;
  r.playing = true;
  $('play').textContent = 'pause';
  last = performance.now();
  requestAnimationFrame(frame);
}

function pause() {
  if (state.replay) state.replay.playing = false;
  $('play').textContent = 'play';
}

$('play').onclick = () => (state.replay && state.replay.playing ? pause() : play());
$('time').addEventListener('input', () => { pause(); setTick(Number($('time').value)); });

const files = { replay: null, trajectory: null };
async function openFiles() {
  try {
    if (!files.replay) { $('replay-msg').textContent = 'trajectory read; now open the cfreplay CSV'; return; }
    loadReplay(await files.replay.text(), files.trajectory ? await files.trajectory.text() : null, files.replay.name);
  } catch (e) {
    $('replay-msg').textContent = String(e.message || e);
    $('replay-msg').className = 'error';
  }
}
$('replay-file').onchange = (e) => { files.replay = e.target.files[0] || null; openFiles(); };
$('trajectory-file').onchange = (e) => { files.trajectory = e.target.files[0] || null; openFiles(); };

// ---------------------------------------------------------------------------------------
// Start
// ---------------------------------------------------------------------------------------

const name = (m) => m.name || 'unnamed';
$('title').textContent = meta.graph ? meta.graph.split('/').pop() : 'cf viewer';
document.title = `cf viewer: ${$('title').textContent}`;
$('models').textContent = `A '${name(modelA)}' (${modelA.vertices.length} v, ${modelA.edges.length} e, ${modelA.faces.length} f) ` +
  `against B '${name(modelB)}' (${modelB.vertices.length} v, ${modelB.edges.length} e, ${modelB.faces.length} f); ` +
  `${graph.cfs.length} CFs, ${graph.transitions.length} transitions`;
$('legend').innerHTML = `<span class="swatch" style="background:#8fb8de"></span>A (held) ` +
  `<span class="swatch" style="background:#b8b8b0"></span>B (fixed); contact colours: one per PC`;

window.cfViewer = {
  state, graph,
  select,
  setTick,
  play,
  pause,
  loadReplay: (csv, traj, nm = 'replay.csv') => loadReplay(csv, traj, nm),
  poseA: () => groupA.matrix.toArray(),
  // The gap drawn between the proxy and the device: whether it shows, and its ends (mm).
  gap: () => ({ visible: device.visible, length: state.replay ? state.replay.gap || 0 : 0,
    ends: [0, 1].map((k) => [0, 1, 2].map((c) => device.userData.line.geometry.attributes.position.array[3 * k + c])) }),
  // Where world directions point on the screen: the normalised device coordinates of the
  // view target moved by `size` along +x, +y, +z, less the target's; and the same for the
  // triad's axes in its corner.
  screenAxes: () => {
    const ndc = (p, cam) => p.clone().project(cam);
    const o = ndc(controls.target, camera);
    const main = [[1, 0, 0], [0, 1, 0], [0, 0, 1]].map((d) => ndc(controls.target.clone().addScaledVector(v3(d), size * 0.1), camera).sub(o).toArray().slice(0, 2));
    triadView();
    const t0 = ndc(new THREE.Vector3(), triad.camera);
    const corner = [[1, 0, 0], [0, 1, 0], [0, 0, 1]].map((d) => ndc(v3(d), triad.camera).sub(t0).toArray().slice(0, 2));
    return { main, triad: corner, triadPx: triad.px, colours: TRIAD_COLOURS };
  },
  listScroll: () => {
    const list = $('cf-list'), row = list.querySelector('div.selected');
    if (!row) return null;
    const r = row.getBoundingClientRect(), l = list.getBoundingClientRect();
    const top = l.top + list.clientTop;  // the list's content, inside its border
    return { rowTop: r.top - top, rowBottom: r.bottom - top, height: list.clientHeight, scrollTop: list.scrollTop };
  },
  arrows: () => ({ F: arrows.F.visible, M: arrows.M.visible }),
};

applyFilters();
resize();
const replayText = embedded('cf-replay');
if (replayText !== null) {
  try {
    loadReplay(replayText, embedded('cf-trajectory'), meta.replay ? meta.replay.split('/').pop() : 'replay');
  } catch (e) {
    $('replay-msg').textContent = String(e.message || e);
    $('replay-msg').className = 'error';
  }
}
// The CF `--cf` names is shown (and its row scrolled into view), also beside a replay.
if (meta.cf !== undefined && meta.cf !== null) select(Number(meta.cf));
else if (state.selected < 0 && graph.cfs.length > 0 && !state.replay) select(0);
state.ready = true;
