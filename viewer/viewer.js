// The page `plant view` serves (docs/view.md): the plant as the GLB `plant run -o x.glb` writes,
// drawn with three.js; the server's events bring each new derivation, the controls send params,
// the seed and the step back. Instanced organs arrive as EXT_mesh_gpu_instancing, which three's
// GLTFLoader turns into InstancedMesh.
import * as THREE from '/three/three.module.js';
import { OrbitControls } from '/three/addons/controls/OrbitControls.js';
import { GLTFLoader } from '/three/addons/loaders/GLTFLoader.js';

const $ = (id) => document.getElementById(id);
const view = $('view');

// Multisampling, unless WebGL runs on a software rasteriser (SwiftShader, llvmpipe: a machine
// without a GPU, headless chromium), where it makes every frame several times slower.
function softwareGL() {
  const gl = document.createElement('canvas').getContext('webgl2');
  const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
  const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
  if (gl) gl.getExtension('WEBGL_lose_context')?.loseContext();
  return /swiftshader|llvmpipe|softpipe/i.test(name);
}
const renderer = new THREE.WebGLRenderer({ antialias: !softwareGL(), preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setClearColor(0x1d2126);
view.appendChild(renderer.domElement);

const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
camera.position.set(3, 2, 5);
const controls = new OrbitControls(camera, renderer.domElement);
scene.add(new THREE.HemisphereLight(0xeef4ff, 0x4a4030, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.2);
sun.position.set(4, 10, 6);
scene.add(sun);
scene.add(camera);
const fill = new THREE.DirectionalLight(0xffffff, 0.6);
fill.position.set(-0.4, 0.2, 1);
camera.add(fill); // a light from the viewer's side keeps the front lit while orbiting

let grid = null;     // the ground grid, sized on the first plant
let plant = null;    // the glTF scene shown
let framed = false;  // the camera is framed once; later models keep it
const loader = new GLTFLoader();

// What the tests and the benchmark read (tests/view/view.mjs).
const state = {
  version: 0,        // the server's version of the derivation shown (or failed)
  shownVersion: 0,   // the version whose plant is on screen (a failed version keeps the one before)
  step: -1,          // the step shown
  modules: 0,        // its module count
  error: null,       // the diagnostic shown, if any
  drawnAt: 0,        // Date-comparable time (ms) when the last model was first rendered
  loads: 0,          // models put on screen
  params: [],
  picked: null,      // the server's answer to the last click (/api/pick), once it arrived
  // Clicks at a point of the canvas (CSS pixels from its top left) as a user would.
  clickAt: (x, y) => pickAt(x, y),
  // The canvas position (CSS pixels) of a point in the plant's own coordinates.
  screenOf: (p) => {
    const v = plant.localToWorld(new THREE.Vector3(p[0], p[1], p[2])).project(camera);
    const r = renderer.domElement.getBoundingClientRect();
    return { x: (v.x + 1) / 2 * r.width, y: (1 - v.y) / 2 * r.height };
  },
  instanced: () => {
    const out = [];
    if (plant) plant.traverse((o) => { if (o.isInstancedMesh) out.push({ name: o.name, count: o.count }); });
    return out;
  },
  screenBox: () => screenBox(),
  names: () => { const out = []; if (plant) plant.traverse((o) => { if (o.name) out.push(o.name); }); return out; },
  showGrid: (on) => { if (grid) grid.visible = on; renderer.render(scene, camera); },
};
window.plantView = state;

let server = null;           // the last state from the server
const glbCache = new Map();  // `${version}:${step}` -> ArrayBuffer, so moving the slider back is instant
const edited = {};           // params changed on the page
let seedEdited = null;
let followLast = true;       // the step slider sits on the last step

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', () => { resize(); requestRender(); });
resize();

// Frames are drawn on demand (the camera moved, a model arrived), not continuously: a page left
// open costs nothing, and the machine's cores go to deriving.
let frameWaiters = [];
let frameQueued = false;
function requestRender() {
  if (frameQueued) return;
  frameQueued = true;
  requestAnimationFrame(() => {
    frameQueued = false;
    renderer.render(scene, camera);
    const waiters = frameWaiters;
    frameWaiters = [];
    for (const w of waiters) w();
  });
}
controls.addEventListener('change', requestRender);
const nextFrame = () => new Promise((resolve) => { frameWaiters.push(resolve); requestRender(); });


function disposeTree(root) {
  root.traverse((o) => {
    if (o.geometry) o.geometry.dispose();
    if (o.material) for (const m of [].concat(o.material)) { for (const v of Object.values(m)) if (v && v.isTexture) v.dispose(); m.dispose(); }
  });
}

// The camera looks at the plant's bounding box from the front and a little above; the grid lies
// under it, a few times its width.
function frame(box) {
  const size = box.getSize(new THREE.Vector3());
  const center = box.getCenter(new THREE.Vector3());
  const radius = Math.max(size.length() / 2, 1e-3);
  const dist = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.05;
  camera.near = dist / 1000;
  camera.far = dist * 100;
  camera.position.copy(center).add(new THREE.Vector3(0, size.y * 0.15, dist));
  camera.updateProjectionMatrix();
  controls.target.copy(center);
  controls.update();
  if (grid) { scene.remove(grid); grid.geometry.dispose(); grid.material.dispose(); }
  const extent = Math.max(size.x, size.z, size.y) * 3;
  const cell = Math.pow(10, Math.floor(Math.log10(Math.max(extent / 20, 1e-6))));
  const cells = Math.min(200, Math.max(2, Math.round(extent / cell)));
  grid = new THREE.GridHelper(cells * cell, cells, 0x556070, 0x363c44);
  grid.position.set(center.x, box.min.y, center.z);
  scene.add(grid);
}

// The plant's box on the screen, in CSS pixels of the page: what the tests look at.
function screenBox() {
  if (!plant) return null;
  const box = new THREE.Box3().setFromObject(plant);
  const r = renderer.domElement.getBoundingClientRect();
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  for (let k = 0; k < 8; ++k) {
    const p = new THREE.Vector3(k & 1 ? box.max.x : box.min.x, k & 2 ? box.max.y : box.min.y, k & 4 ? box.max.z : box.min.z).project(camera);
    const x = r.left + (p.x + 1) / 2 * r.width, y = r.top + (1 - p.y) / 2 * r.height;
    x0 = Math.min(x0, x); y0 = Math.min(y0, y); x1 = Math.max(x1, x); y1 = Math.max(y1, y);
  }
  return { x: Math.max(x0, r.left), y: Math.max(y0, r.top), width: Math.min(x1, r.right) - Math.max(x0, r.left), height: Math.min(y1, r.bottom) - Math.max(y0, r.top) };
}

async function fetchModel(version, step) {
  const key = `${version}:${step}`;
  if (glbCache.has(key)) return glbCache.get(key);
  const res = await fetch(`/api/model.glb?step=${step}&v=${version}`);
  if (!res.ok) throw new Error(await res.text());
  const bytes = await res.arrayBuffer();
  for (const k of glbCache.keys()) if (!k.startsWith(`${version}:`)) glbCache.delete(k);
  glbCache.set(key, bytes);
  return bytes;
}

let showing = Promise.resolve();
// Puts step `step` of the server's current version on screen (one at a time, the newest wins).
function show(step) {
  const version = server.plant;
  showing = showing.then(async () => {
    if (version !== server.plant) return; // a newer one is on its way
    const t0 = performance.now();
    const bytes = await fetchModel(version, step);
    const t1 = performance.now();
    const gltf = await loader.parseAsync(bytes, '');
    const t2 = performance.now();
    if (version !== server.plant) return;
    const old = plant;
    if (old) scene.remove(old);
    plant = gltf.scene;
    plant.name = 'plant';
    scene.add(plant);
    if (!framed) { frame(new THREE.Box3().setFromObject(plant)); framed = true; }
    state.shownVersion = version;
    state.step = step;
    state.modules = server.modules[step];
    status();
    await nextFrame();
    state.drawnAt = performance.timeOrigin + performance.now();
    state.timing = { fetch: t1 - t0, parse: t2 - t1, draw: performance.now() - t2 };
    // disposed only now: the new plant's materials have taken over the old one's shader programs
    if (old) disposeTree(old);
    state.loads += 1;
  }).catch((e) => showError(String(e.message || e)));
  return showing;
}

function showError(text) {
  state.error = text;
  $('error').textContent = text;
  $('error').style.display = text ? 'block' : 'none';
}

function status() {
  if (!server || !server.modules) { $('status').textContent = 'no plant yet'; return; }
  const last = server.modules.length - 1;
  $('status').textContent = `${state.modules} modules, step ${state.step} of ${last}` +
    (server.derive_ms !== undefined ? ` (derived in ${server.derive_ms.toFixed(0)} ms)` : '');
  $('step-label').textContent = `${state.step} / ${last}`;
}

// A numeric field for a param and, when the grammar gives it a range (`param r = 0.9 in 0.5 ..
// 1.0;`), a slider over the range beside it; both carry data-param and are kept in step.
function paramControl(p) {
  const label = document.createElement('label');
  label.textContent = p.name;
  const input = document.createElement('input');
  input.type = 'number';
  input.step = 'any';
  input.value = p.value;
  input.dataset.param = p.name;
  let slider = null;
  if (p.low !== undefined && p.high !== undefined) {
    slider = document.createElement('input');
    slider.type = 'range';
    setRange(slider, input, p);
    slider.value = String(p.value);
    slider.dataset.param = p.name;
    slider.addEventListener('input', () => {
      input.value = slider.value;
      edited[p.name] = Number(slider.value);
      sendControlsSoon();
    });
    label.appendChild(slider);
  }
  input.addEventListener('change', () => {
    const v = Number(input.value);
    if (!Number.isFinite(v) || input.value.trim() === '') return;
    if (slider) slider.value = String(v);
    edited[p.name] = v;
    sendControls();
  });
  label.appendChild(input);
  return label;
}

// A slider's range and step, and its field's: a count (the grammar wrote the default and both
// bounds as whole numbers, `param N_S = 5 in 1 .. 12;`) moves by whole steps; anything else does
// not snap (the value is the grammar's, not a multiple of a step).
function setRange(slider, input, p) {
  for (const e of [slider, input]) { e.min = String(p.low); e.max = String(p.high); }
  slider.step = p.whole ? '1' : 'any';
}

// While a slider is dragged: one request in flight at a time, the latest value sent after it.
let controlsInFlight = false;
let controlsPending = false;
async function sendControlsSoon() {
  if (controlsInFlight) {
    controlsPending = true;
    return;
  }
  controlsInFlight = true;
  try {
    await sendControls();
  } finally {
    controlsInFlight = false;
    if (controlsPending) {
      controlsPending = false;
      sendControlsSoon();
    }
  }
}

function updateControls() {
  const params = server.params || [];
  state.params = params;
  const box = $('params');
  // rebuilt when the params or which have ranges change; a range whose bounds moved (a bound
  // reading another param being dragged) is updated in place, so the slider under the pointer stays
  const names = params.map((p) => `${p.name}:${p.low !== undefined}`).join(',');
  if (box.dataset.names !== names) {
    box.replaceChildren(...params.map(paramControl));
    box.dataset.names = names;
    if (!params.length) box.textContent = 'none';
  } else {
    for (const p of params) {
      const slider = box.querySelector(`input[type="range"][data-param="${CSS.escape(p.name)}"]`);
      const field = box.querySelector(`input[type="number"][data-param="${CSS.escape(p.name)}"]`);
      if (slider && field) setRange(slider, field, p);
      for (const input of [slider, field])
        if (input && document.activeElement !== input) input.value = p.value;
    }
  }
  if (document.activeElement !== $('seed') && server.seed !== undefined) $('seed').value = server.seed;
  const slider = $('step');
  const last = server.modules.length - 1;
  slider.max = String(last);
  if (followLast || Number(slider.value) > last) slider.value = String(last);
  if ($('command-line').style.display === 'block') $('command-line').textContent = commandText();
  updateEdits();
}

// The command line that grows what is shown, and the hook to add for the page's edits.
function commandText() {
  if (!server) return '';
  return server.command + (server.edit_hook ? `\n# with the edits made here, added to the grammar:\n${server.edit_hook}` : '');
}

// Editing (climbers, docs/view.md): a row per edit method of the grammar's environments, its
// arguments filled from the pick (a module id, the picked point as a target) and editable; the
// call runs before the step after the one shown, as the REPL's edits do.
function updateEdits() {
  const methods = server.edit_methods || [];
  $('edit-box').style.display = methods.length ? 'block' : 'none';
  const key = methods.map((m) => `${m.env}.${m.method}(${m.args})`).join(',');
  const box = $('edit-methods');
  if (box.dataset.key !== key) {
    box.dataset.key = key;
    box.replaceChildren(...methods.map(editRow));
  }
  $('edit-list').textContent = (server.edits || []).map((e) => `before step ${e.step + 1}: ${e.call}`).join('\n') || 'no edits';
}

function editRow(m) {
  const row = document.createElement('div');
  const button = document.createElement('button');
  button.textContent = `${m.env}.${m.method}`;
  button.title = m.doc;
  button.dataset.edit = m.method;
  row.appendChild(button);
  const takesId = /module id/.test(m.doc);
  const inputs = m.args.map((type, k) => {
    const input = document.createElement('input');
    input.type = 'text';
    input.size = type === 'vec3' ? 14 : 6;
    input.dataset.arg = k === 0 && takesId ? 'id' : type;
    input.value = type === 'vec3' ? '0, 0, 0' : '0';
    input.placeholder = k === 0 && takesId ? 'module id' : type === 'vec3' ? 'x, y, z' : 'number';
    row.appendChild(input);
    return input;
  });
  button.addEventListener('click', async () => {
    const args = inputs.map((input) => {
      const xs = input.value.split(',').map((t) => Number(t.trim()));
      return input.dataset.arg === 'vec3' ? xs : xs[0];
    });
    const body = { step: state.step, env: m.env, method: m.method, args };
    const res = await fetch('/api/edit', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
    if (!res.ok) showError(await res.text());
  });
  return row;
}

// A pick fills the edit rows: its module's identity, and its point as a target (pull).
function fillEdits(j) {
  if (!j.found || j.id === undefined) return;
  for (const input of document.querySelectorAll('#edit-methods input[data-arg="id"]')) input.value = String(j.id);
  const at = j.to || j.at;
  if (at) for (const row of document.querySelectorAll('#edit-methods div')) {
    const vecs = row.querySelectorAll('input[data-arg="vec3"]');
    if (row.querySelector('input[data-arg="id"]') && vecs.length) vecs[0].value = at.map((v) => +v.toFixed(4)).join(', ');
  }
}
$('edit-undo').addEventListener('click', async () => {
  const res = await fetch('/api/edit', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ undo: true }) });
  if (!res.ok) showError(await res.text());
});

async function sendControls() {
  const body = { params: edited, seed: seedEdited };
  const res = await fetch('/api/controls', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
  if (!res.ok) showError(await res.text());
  // the new version arrives as an event
}

// A new state from the server: a new derivation, or a failed one (the last plant stays).
function onState(next) {
  if (server && next.version === server.version) return; // sent again: nothing new
  server = next;
  state.eventAt = performance.timeOrigin + performance.now();
  state.version = next.version;
  $('file').textContent = next.file;
  showError(next.error || '');
  if (!next.modules) { status(); return; }
  updateControls();
  // a failed derivation keeps the plant shown; a new one replaces it
  if (next.plant !== state.shownVersion || Number($('step').value) !== state.step) show(Number($('step').value));
}

$('step').addEventListener('input', () => {
  const slider = $('step');
  followLast = Number(slider.value) === Number(slider.max);
  if (server && server.kept && !server.kept[Number(slider.value)]) {
    showError(`step ${slider.value} was not kept (the derivation is too large to keep every step)`);
    return;
  }
  if (server) show(Number(slider.value));
});
// Stepping and playing through the kept steps: a climber's growth along its wall, a plant's
// development. Play shows each step once the one before is on screen, at most 5 a second.
function goToStep(k) {
  const slider = $('step');
  const last = Number(slider.max);
  slider.value = String(Math.max(0, Math.min(last, k)));
  slider.dispatchEvent(new Event('input'));
}
let playing = null;
function stopPlaying() {
  if (playing) clearTimeout(playing);
  playing = null;
  $('play').textContent = 'play';
}
async function playNext() {
  const slider = $('step');
  if (Number(slider.value) >= Number(slider.max)) { stopPlaying(); return; }
  goToStep(Number(slider.value) + 1);
  await showing;
  if (playing) playing = setTimeout(playNext, 200);
}
$('play').addEventListener('click', () => {
  if (playing) { stopPlaying(); return; }
  const slider = $('step');
  if (Number(slider.value) >= Number(slider.max)) goToStep(0);
  $('play').textContent = 'pause';
  playing = setTimeout(playNext, 0);
});
$('step-back').addEventListener('click', () => { stopPlaying(); goToStep(Number($('step').value) - 1); });
$('step-forward').addEventListener('click', () => { stopPlaying(); goToStep(Number($('step').value) + 1); });
$('seed').addEventListener('change', () => {
  const s = $('seed').value.trim();
  if (!/^\d+$/.test(s)) { showError('the seed is a whole number'); return; }
  seedEdited = s;
  sendControls();
});
$('save-d').addEventListener('click', () => {
  const line = $('command-line');
  line.textContent = commandText();
  line.style.display = 'block';
  if (navigator.clipboard && server) navigator.clipboard.writeText(commandText()).catch(() => {});
});

function download(name, blob) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}
const stem = () => (server ? server.file.replace(/^.*\//, '').replace(/\.plant$/, '') : 'plant');
$('download-glb').addEventListener('click', async () => {
  if (!server || state.step < 0) return;
  download(`${stem()}-step${state.step}.glb`, new Blob([await fetchModel(state.shownVersion, state.step)]));
});
$('download-png').addEventListener('click', () => {
  renderer.render(scene, camera);
  renderer.domElement.toBlob((blob) => download(`${stem()}-step${state.step}.png`, blob));
});

// Picking: the clicked mesh (and instance) is outlined by a box and named; the server says which
// module drew it (/api/pick: name, identity, parameters, graph node) and its segment is marked.
const raycaster = new THREE.Raycaster();
let marker = null;
let segmentMarker = null;
renderer.domElement.addEventListener('click', (ev) => {
  const r = renderer.domElement.getBoundingClientRect();
  pickAt(ev.clientX - r.left, ev.clientY - r.top);
});

function pickAt(x, y) {
  if (!plant) return;
  const r = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(x / r.width * 2 - 1, -y / r.height * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  const hit = raycaster.intersectObject(plant, true)[0];
  if (marker) { scene.remove(marker); marker.dispose(); marker = null; }
  if (!hit) { $('pick').textContent = 'nothing there'; requestRender(); return; }
  const o = hit.object;
  const box = new THREE.Box3();
  if (o.isInstancedMesh && hit.instanceId !== undefined) {
    const m = new THREE.Matrix4();
    o.getMatrixAt(hit.instanceId, m);
    o.geometry.computeBoundingBox();
    box.copy(o.geometry.boundingBox).applyMatrix4(m.premultiply(o.matrixWorld));
  } else {
    box.setFromObject(o);
  }
  marker = new THREE.Box3Helper(box, 0xffd040);
  scene.add(marker);
  requestRender();
  const names = [];
  for (let p = o; p && p !== plant; p = p.parent) if (p.name) names.unshift(p.name);
  const what = `${names.join(' / ') || '(unnamed)'}` +
    (o.isInstancedMesh ? `\ninstance ${hit.instanceId} of ${o.count}` : '') +
    `\nat ${hit.point.toArray().map((v) => v.toFixed(3)).join(', ')}`;
  $('pick').textContent = what;
  if (segmentMarker) { segmentMarker.removeFromParent(); segmentMarker.geometry.dispose(); segmentMarker = null; }
  state.picked = null;
  if (names[0] === 'obstacles') return;
  // in the plant's own coordinates: the point hit and, for a placed organ or instance, where
  // its placement stands
  const local = (v) => plant.worldToLocal(v.clone()).toArray();
  const q = new URLSearchParams({ step: String(state.step) });
  const p = local(hit.point);
  q.set('x', p[0]); q.set('y', p[1]); q.set('z', p[2]);
  if (names.length === 1 && names[0] === 'tubes') {
    q.set('kind', 'tube');
  } else {
    const m = new THREE.Matrix4();
    if (o.isInstancedMesh && hit.instanceId !== undefined) o.getMatrixAt(hit.instanceId, m);
    let top = o;
    while (top.parent && top.parent !== plant) top = top.parent;
    const placed = o.isInstancedMesh ? m.premultiply(o.matrixWorld) : top.matrixWorld;
    const origin = local(new THREE.Vector3().setFromMatrixPosition(placed));
    q.set('kind', 'organ'); q.set('ox', origin[0]); q.set('oy', origin[1]); q.set('oz', origin[2]);
  }
  const shown = plant;
  fetch(`/api/pick?${q}`).then((res) => (res.ok ? res.json() : null)).then((j) => {
    if (!j || plant !== shown) return;
    state.picked = j;
    fillEdits(j);
    $('pick').textContent = pickText(j) + '\n\n' + what;
    if (j.from && j.to) {
      const g = new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(...j.from), new THREE.Vector3(...j.to)]);
      segmentMarker = new THREE.Line(g, new THREE.LineBasicMaterial({ color: 0xff5030, depthTest: false }));
      segmentMarker.renderOrder = 10;
      plant.add(segmentMarker);
      requestRender();
    }
  }).catch(() => {});
}

// The server's answer as text: the module with its identity and parameters, then its node.
function pickText(j) {
  if (!j.found) return 'no module drew this';
  const value = (v) => (Array.isArray(v) ? `(${v.map((x) => +x.toPrecision(6)).join(', ')})` : String(+v.toPrecision(6)));
  const params = (j.params || []).map((p) => (p.name.startsWith('#') ? value(p.value) : `${p.name} = ${value(p.value)}`));
  let text = `${j.module}${j.id !== undefined ? ' #' + j.id : ''}${params.length ? `(${params.join(', ')})` : ''}`;
  if (j.interpreted) text += '\n(made by an interpretation rule)';
  if (j.node) text += `\nnode ${j.node.path}\n` + j.node.text.split('\n').slice(1).map((l) => l.trim()).filter(Boolean).join('\n');
  return text;
}

const events = new EventSource('/api/events');
events.addEventListener('model', (ev) => onState(JSON.parse(ev.data)));
