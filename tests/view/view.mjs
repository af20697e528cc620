// Browser tests of `plant view` (docs/view.md): headless Debian chromium driven by puppeteer-core.
//   node view.mjs PLANT SOURCE_DIR [--bench]
// Each check prints "ok - ..." or "not ok - ..." and the run exits 1 when any failed. With --bench
// it measures save-to-pixels latency only (bench/view-latency).
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import puppeteer from 'puppeteer-core';

const [plant, sourceDir, mode] = process.argv.slice(2);
const bench = mode === '--bench';
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'plant-view-test-'));
const servers = [];
let failures = 0;

function check(ok, what, detail = '') {
  console.log(`${ok ? 'ok' : 'not ok'} - ${what}${detail ? ` (${detail})` : ''}`);
  if (!ok) failures += 1;
}

// Starts `plant view FILE --port 0` and resolves to its URL.
function startView(file, extra = []) {
  return new Promise((resolve, reject) => {
    const child = spawn(plant, ['view', file, '--port', '0', ...extra], { stdio: ['ignore', 'pipe', 'inherit'] });
    servers.push(child);
    let out = '';
    child.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (m) resolve({ url: m[0], child });
    });
    child.on('exit', (code) => reject(new Error(`plant view exited with ${code}: ${out}`)));
  });
}

// A raw request (no path normalisation, any Host header).
function request(url, requestPath, headers = {}, body = undefined) { // a POST when given a body
  const u = new URL(url);
  return new Promise((resolve, reject) => {
    const method = body === undefined ? 'GET' : 'POST';
    const req = http.request({ host: u.hostname, port: u.port, path: requestPath, headers, method }, (res) => {
      const chunks = [];
      res.on('data', (c) => chunks.push(c));
      res.on('end', () => resolve({ status: res.statusCode, body: Buffer.concat(chunks) }));
    });
    req.on('error', reject);
    req.end(body);
  });
}

async function waitFor(page, fn, arg, timeout = 5000) {
  await page.waitForFunction(fn, { timeout, polling: 10 }, arg);
}

// Pixels in the plant's screen box that differ from the background (the grid hidden).
function paintedPixels(page) {
  return page.evaluate(() => {
    window.plantView.showGrid(false);
    const c = document.querySelector('#view canvas');
    const b = window.plantView.screenBox();
    const r = c.getBoundingClientRect();
    const s = c.width / r.width;
    const tmpCanvas = document.createElement('canvas');
    tmpCanvas.width = c.width; tmpCanvas.height = c.height;
    const ctx = tmpCanvas.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const w = Math.max(1, Math.floor(b.width * s)), h = Math.max(1, Math.floor(b.height * s));
    const d = ctx.getImageData(Math.floor((b.x - r.left) * s), Math.floor((b.y - r.top) * s), w, h).data;
    let n = 0;
    for (let k = 0; k < d.length; k += 4)
      if (Math.abs(d[k] - 0x1d) + Math.abs(d[k + 1] - 0x21) + Math.abs(d[k + 2] - 0x26) > 12) n += 1;
    window.plantView.showGrid(true);
    return { painted: n, total: w * h };
  });
}

// Writes `text` to `file` and resolves to the milliseconds from the write to the new model's
// first frame, with the module count then shown.
async function saveAndWait(page, file, text) {
  const before = await page.evaluate(() => window.plantView.loads);
  const t0 = Date.now();
  fs.writeFileSync(file, text);
  await waitFor(page, (n) => window.plantView.loads > n, before);
  const r = await page.evaluate((t) => ({ ms: window.plantView.drawnAt - t, event: window.plantView.eventAt - t, modules: window.plantView.modules, timing: window.plantView.timing }), t0);
  if (process.env.VIEW_TIMING) console.error(JSON.stringify(r));
  return r;
}

async function openPage(browser, url, errors) {
  const page = await browser.newPage();
  await page.setViewport({ width: 1000, height: 700 });
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(url);
  await waitFor(page, () => window.plantView && window.plantView.loads > 0, null, 20000);
  return page;
}

function median(xs) { const s = [...xs].sort((a, b) => a - b); return s[Math.floor(s.length / 2)]; }

// Save-to-pixels latency of `grammar`: `edits` alternate two versions of the file.
async function latency(browser, grammar, mutate, rounds) {
  const file = path.join(tmp, path.basename(grammar));
  const original = fs.readFileSync(grammar, 'utf8');
  fs.writeFileSync(file, original);
  const { url, child } = await startView(file);
  const errors = [];
  const page = await openPage(browser, url, errors);
  const times = [];
  for (let k = 0; k < rounds; ++k) times.push((await saveAndWait(page, file, k % 2 ? original : mutate(original))).ms);
  await page.close();
  child.kill('SIGINT');
  return { grammar: path.relative(sourceDir, grammar), median_ms: median(times), max_ms: Math.max(...times), rounds };
}

async function securityChecks(url) {
  const port = new URL(url).port;
  const good = await request(url, '/api/state', { Host: `127.0.0.1:${port}` });
  check(good.status === 200, 'the state is served to a loopback Host', `status ${good.status}`);
  const foreign = await request(url, '/api/state', { Host: `attacker.example:${port}` });
  check(foreign.status === 403, 'a foreign Host header is refused', `status ${foreign.status}`);
  const origin = await request(url, '/api/state', { Host: `127.0.0.1:${port}`, Origin: 'http://attacker.example' });
  check(origin.status === 403, 'a foreign Origin is refused', `status ${origin.status}`);
  const dots = await request(url, '/../../etc/passwd', { Host: `127.0.0.1:${port}` });
  check(dots.status === 400 && !dots.body.toString().includes('root:'), 'a path with .. is refused', `status ${dots.status}`);
  const abs = await request(url, '/etc/passwd', { Host: `127.0.0.1:${port}` });
  check(abs.status === 404 && !abs.body.toString().includes('root:'), 'a file system path is not served', `status ${abs.status}`);
}

async function roseChecks(browser) {
  const grammar = path.join(sourceDir, 'grammars/rose/fig12c.plant');
  const file = path.join(tmp, 'fig12c.plant');
  const original = fs.readFileSync(grammar, 'utf8');
  fs.writeFileSync(file, original);
  const { url } = await startView(file);
  await securityChecks(url);
  const errors = [];
  const page = await openPage(browser, url, errors);
  await page.evaluate(() => { window.notReloaded = true; });
  const px = await paintedPixels(page);
  check(px.painted > px.total * 0.02, 'the plant is drawn (pixels differ from the background in its box)', `${px.painted} of ${px.total}`);

  // a save reaches the page
  const m0 = await page.evaluate(() => window.plantView.modules);
  const saved = await saveAndWait(page, file, original.replace('N_S = 5', 'N_S = 3'));
  check(saved.modules !== m0 && saved.ms < 2000, 'a save reaches the page within 2 s', `${m0} -> ${saved.modules} modules in ${saved.ms.toFixed(0)} ms`);
  check(await page.evaluate(() => window.notReloaded === true), 'without reloading the page');
  check((await page.$eval('#status', (e) => e.textContent)).includes(`${saved.modules} modules`), 'the page shows the module count');

  // a syntax error shows its diagnostic; the plant stays
  const shown = await page.evaluate(() => window.plantView.shownVersion);
  fs.writeFileSync(file, original.replace('seed 12;', 'seed 12 12;'));
  await waitFor(page, () => window.plantView.error);
  const error = await page.$eval('#error', (e) => ({ text: e.textContent, shown: getComputedStyle(e).display !== 'none' }));
  check(error.shown && /fig12c\.plant:\d+:\d+/.test(error.text) && error.text.includes('^'), 'a syntax error shows file:line:col, the line and a caret', JSON.stringify(error.text.split('\n')[0]));
  check(await page.evaluate((v) => window.plantView.shownVersion === v, shown), 'the last good plant stays');
  const px2 = await paintedPixels(page);
  check(px2.painted > px2.total * 0.02, 'and is still drawn');
  const fixed = await saveAndWait(page, file, original);
  check(!(await page.evaluate(() => window.plantView.error)) && fixed.modules === m0, 'fixing the error clears it', `${fixed.modules} modules`);

  // the rose library's params have ranges (stdlib/rose.plant), so they get sliders
  const roseSliders = await page.$$eval('input[type="range"][data-param]', (es) => Object.fromEntries(es.map((e) => [e.dataset.param, [e.min, e.max, e.step]])));
  check(JSON.stringify(roseSliders.N_S) === '["1","12","1"]' && roseSliders.theta && Math.abs(Number(roseSliders.theta[1]) - Math.PI / 2) < 1e-9 &&
    roseSliders.theta[2] === 'any' && JSON.stringify(roseSliders.droop_reading) === '["0","1","1"]' &&
    roseSliders.sigma_inter && roseSliders.sigma_inter[2] === 'any',
    'the rose\'s params get sliders over their ranges, counts moving by whole steps', JSON.stringify(roseSliders));

  // a param changed on the page derives again
  const loads = await page.evaluate(() => window.plantView.loads);
  await page.$eval('input[type="number"][data-param="N_S"]', (e) => { e.value = '2'; e.dispatchEvent(new Event('change')); });
  await waitFor(page, (n) => window.plantView.loads > n, loads);
  const afterParam = await page.evaluate(() => window.plantView.modules);
  check(afterParam !== m0, 'changing a param derives again', `${m0} -> ${afterParam} modules`);
  const line = await page.evaluate(() => { document.getElementById('save-d').click(); return document.getElementById('command-line').textContent; });
  check(line.includes('-D N_S=2'), '"Save as -D" shows the command line', line);
  // a value out of the param's range (1 .. 12) derives to an error, and never reaches "Save as -D"
  // (sent from here, not the page, so that the page's own controls stay as they were)
  const port = new URL(url).port;
  const post = (params) => request(url, '/api/controls', { Host: `127.0.0.1:${port}`, 'Content-Type': 'application/json' },
    JSON.stringify({ params }));
  const sent = (await post({ N_S: 99 })).status;
  await waitFor(page, () => document.getElementById('error').textContent.includes('range'), undefined);
  const line2 = await page.evaluate(() => { document.getElementById('save-d').click(); return document.getElementById('command-line').textContent; });
  check(sent === 200 && !line2.includes('N_S=99') && line2.includes('-D N_S=2'), 'a value out of its range is left out of "Save as -D"', `${sent}: ${line2}`);
  await post({ N_S: 2 });
  await waitFor(page, () => !document.getElementById('error').textContent, undefined);

  // the step slider shows step k
  const k = 3;
  const expected = await page.evaluate((s) => { const e = document.getElementById('step'); e.value = String(s); e.dispatchEvent(new Event('input')); return window.plantView.params && null; }, k);
  void expected;
  await waitFor(page, (s) => window.plantView.step === s, k);
  const state = JSON.parse((await request(url, '/api/state', { Host: new URL(url).host })).body);
  const stepModules = await page.evaluate(() => window.plantView.modules);
  check(stepModules === state.modules[k] && (await page.$eval('#status', (e) => e.textContent)).includes(`${state.modules[k]} modules, step ${k}`), 'the step slider shows step k\'s module count', `step ${k}: ${stepModules}`);
  const t0 = Date.now();
  await page.evaluate(() => { const e = document.getElementById('step'); e.value = e.max; e.dispatchEvent(new Event('input')); });
  await waitFor(page, (n) => window.plantView.modules === n, state.modules.at(-1));
  await page.evaluate(() => { const e = document.getElementById('step'); e.value = '3'; e.dispatchEvent(new Event('input')); });
  await waitFor(page, () => window.plantView.step === 3);
  check(Date.now() - t0 < 1000, 'moving back to a kept step is quick', `${Date.now() - t0} ms`);
  await page.click('#step-forward');
  await waitFor(page, () => window.plantView.step === 4);
  await page.click('#step-back');
  await waitFor(page, () => window.plantView.step === 3);
  check(true, 'the step buttons move one step on and back');
  await page.click('#play');
  await waitFor(page, () => window.plantView.step >= 6);
  await page.click('#play'); // pause
  const paused = await page.evaluate(() => window.plantView.step);
  await new Promise((r) => setTimeout(r, 600));
  const later = await page.evaluate(() => window.plantView.step);
  check(later <= paused + 1 && later < state.modules.length - 1, 'play shows the steps in turn and pause stops', `paused at ${paused}, then ${later}`);
  check(errors.length === 0, 'no console error', errors.join(' | '));
  await page.close();
}

// The JSON chunk of a GLB.
function glbJson(bytes) {
  const length = bytes.readUInt32LE(12);
  return JSON.parse(bytes.subarray(20, 20 + length).toString('utf8'));
}

async function climberChecks(browser) {
  const { url } = await startView(path.join(sourceDir, 'grammars/climbers/fig01_column.plant'));
  const errors = [];
  const page = await openPage(browser, url, errors);
  const names = await page.evaluate(() => window.plantView.names());
  check(names.some((n) => n.includes('obstacles')), 'a climber\'s obstacles are drawn', names.slice(0, 6).join(', '));
  // an edit from the page: pick a segment at step 20, cut it, see fewer modules after it, undo
  const host = { Host: new URL(url).host };
  const stateOf = async () => JSON.parse((await request(url, '/api/state', host)).body);
  const before = await stateOf();
  await page.evaluate(() => { const e = document.getElementById('step'); e.value = '20'; e.dispatchEvent(new Event('input')); });
  await waitFor(page, () => window.plantView.step === 20);
  let picked = null;
  // (low on the column first: a cut there takes a shoot with it, where a cut near a tip can
  // take fewer modules than the plant then grows otherwise, its physics being chaotic)
  for (const y of [0.3, 0.5, 0.8, 1.1, 1.4]) {
    const seg = JSON.parse((await request(url, `/api/pick?step=20&x=0&y=${y}&z=0.2`, host)).body);
    if (!seg.found) continue;
    const mid = seg.from.map((v, k) => (v + seg.to[k]) / 2);
    await page.evaluate(() => { window.plantView.picked = null; });
    await page.evaluate((p) => window.plantView.clickAt(p.x, p.y), await page.evaluate((m) => window.plantView.screenOf(m), mid));
    try { await waitFor(page, () => window.plantView.picked, null, 2000); } catch { continue; }
    picked = await page.evaluate(() => window.plantView.picked);
    if (picked.found && picked.module === 'Seg') break;
  }
  check(picked && picked.module === 'Seg' && (await page.$eval('#edit-methods input[data-arg="id"]', (e) => e.value)) === String(picked.id),
    'clicking a climber\'s segment fills the edit rows with its identity', picked ? `Seg #${picked.id}` : 'nothing picked');
  // (waits for the edit's state event: moving the step slider above loads a model of its own)
  await page.click('#edit-methods button[data-edit="cut"]');
  await waitFor(page, () => document.getElementById('edit-list').textContent.includes('ivy.cut('), null, 20000);
  const cut = await stateOf();
  const list = await page.$eval('#edit-list', (e) => e.textContent);
  // (the cut part falls for the climber's fall_time, 1 s or ten steps, then its modules leave the
  // string: the module count falls from one step to the next, which the plant left alone never
  // does, its physics being chaotic enough that the two runs' counts may cross)
  const drops = (m) => m.slice(21).filter((n, k) => n < m[20 + k]).length;
  check(cut.modules[20] === before.modules[20] && drops(cut.modules) > 0 && drops(before.modules) === 0 &&
    list.includes(`before step 21: ivy.cut(${picked && picked.id});`),
    'the cut button cuts the branch before the next step, and the page lists the edit',
    `steps 21-${cut.modules.length - 1}: ${cut.modules.slice(21).join(' ')} modules (left alone ${before.modules.slice(21).join(' ')}); ${list}`);
  await page.click('#edit-undo');
  await waitFor(page, () => document.getElementById('edit-list').textContent === 'no edits', null, 20000);
  check((await stateOf()).modules.at(-1) === before.modules.at(-1), 'undo edit restores the plant');
  check(errors.length === 0, 'no console error (climber)', errors.join(' | '));
  await page.close();
}

// A param with a declared range (`param n = 3 in 1 .. 8;`) gets a slider over the range, and
// dragging it derives again.
async function rangeChecks(browser) {
  const file = path.join(tmp, 'ranged.plant');
  fs.writeFileSync(file, 'param n = 3 in 1 .. 8;\nparam s = 1.0 in 0 .. 3;\nparam free = 2;\naxiom: A(n);\nderive 10;\n' +
    'rules { A(x) : x > 0 -> F(1) A(x - 1); }\n');
  const { url } = await startView(file);
  const errors = [];
  const page = await openPage(browser, url, errors);
  const sliders = await page.$$eval('input[type="range"][data-param]', (es) => es.map((e) => ({ name: e.dataset.param, min: e.min, max: e.max, value: e.value, step: e.step })));
  check(sliders.length === 2 && sliders[0].name === 'n' && sliders[0].min === '1' && sliders[0].max === '8' && sliders[0].value === '3',
    'a ranged param gets a slider over its range, an unranged one none', JSON.stringify(sliders));
  check(sliders[0].step === '1' && sliders[1] && sliders[1].name === 's' && sliders[1].step === 'any',
    'a count (written whole) moves by whole steps, a measure written 1.0 does not snap', JSON.stringify(sliders));
  const m0 = await page.evaluate(() => window.plantView.modules);
  const loads = await page.evaluate(() => window.plantView.loads);
  await page.$eval('input[type="range"][data-param="n"]', (e) => { e.value = '8'; e.dispatchEvent(new Event('input')); });
  await waitFor(page, (n) => window.plantView.loads > n && window.plantView.modules !== 4, loads);
  const m1 = await page.evaluate(() => window.plantView.modules);
  const field = await page.$eval('input[type="number"][data-param="n"]', (e) => e.value);
  check(m0 === 4 && m1 === 9 && field === '8', 'dragging the slider derives again and updates the field', `${m0} -> ${m1} modules, field ${field}`);
  check(errors.length === 0, 'no console error (ranged params)', errors.join(' | '));
  await page.close();
}

// Clicking a branch names the module that drew it (identity, parameters) and marks its segment;
// on a bonsai, the branch's decomposition graph node.
async function pickChecks(browser) {
  const file = path.join(tmp, 'pick.plant');
  fs.writeFileSync(file, 'module A(len);\nderive 1;\naxiom: A(2);\nwidth_scale 0.2;\n' +
    'rules { A(l) -> F(l) [ +(90) F(l / 2) ] F(l * 1.5); }\n');
  let { url } = await startView(file);
  const errors = [];
  let page = await openPage(browser, url, errors);
  const at = await page.evaluate(() => window.plantView.screenOf([0, 3.5, 0]));
  await page.evaluate((p) => window.plantView.clickAt(p.x, p.y), at);
  await waitFor(page, () => window.plantView.picked);
  let picked = await page.evaluate(() => window.plantView.picked);
  const text = await page.$eval('#pick', (e) => e.textContent);
  check(picked.found && picked.module === 'F' && picked.id === 7 && picked.params[0].value === 3 && picked.to[1] === 5,
    'clicking a branch names its module, identity and parameters', JSON.stringify(picked).slice(0, 200));
  check(text.startsWith('F #7(3)'), 'and the page shows them', JSON.stringify(text.split('\n')[0]));
  await page.close();
  ({ url } = await startView(path.join(sourceDir, 'grammars/bonsai/chokkan.plant')));
  page = await openPage(browser, url, errors);
  const trunk = await page.evaluate(() => window.plantView.screenOf([0, 0.08, 0]));
  await page.evaluate((p) => window.plantView.clickAt(p.x, p.y), trunk);
  await waitFor(page, () => window.plantView.picked);
  picked = await page.evaluate(() => window.plantView.picked);
  const shown = await page.$eval('#pick', (e) => e.textContent);
  check(picked.node && picked.node.path === '/' && shown.includes('node /\ncrown = silhouette'),
    'clicking a bonsai\'s trunk shows its graph node and where its values come from', JSON.stringify(shown.split('\n').slice(0, 3)));
  check(errors.length === 0, 'no console error (picking)', errors.join(' | '));
  await page.close();
}

async function instanceChecks(browser) {
  const grammar = path.join(sourceDir, 'grammars/willow/fig06a.plant');
  const { url } = await startView(grammar);
  const errors = [];
  const page = await openPage(browser, url, errors);
  const drawn = (await page.evaluate(() => window.plantView.instanced())).map((m) => m.count).sort((a, b) => a - b);
  const gltf = glbJson((await request(url, '/api/model.glb', { Host: new URL(url).host })).body);
  const expected = [];
  for (const node of gltf.nodes || []) {
    const ext = node.extensions && node.extensions.EXT_mesh_gpu_instancing;
    if (!ext || node.mesh === undefined) continue;
    const count = gltf.accessors[Object.values(ext.attributes)[0]].count;
    for (let p = 0; p < gltf.meshes[node.mesh].primitives.length; ++p) expected.push(count);
  }
  expected.sort((a, b) => a - b);
  check(expected.length > 0 && JSON.stringify(drawn) === JSON.stringify(expected),
    'an instanced file is drawn as InstancedMesh with the GLB\'s instance counts',
    `${drawn.length} InstancedMesh, ${drawn.reduce((a, b) => a + b, 0)} instances; expected ${expected.length}, ${expected.reduce((a, b) => a + b, 0)}`);
  const px = await paintedPixels(page);
  check(px.painted > px.total * 0.02, 'the willow is drawn', `${px.painted} of ${px.total}`);
  check(errors.length === 0, 'no console error (willow)', errors.join(' | '));
  await page.close();
}

const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
try {
  if (bench) {
    const rose = await latency(browser, path.join(sourceDir, 'grammars/rose/fig12c.plant'), (t) => t.replace('N_S = 5', 'N_S = 4'), 10);
    const abop = await latency(browser, path.join(sourceDir, 'grammars/abop/fig1_9a.plant'), (t) => t + '\n# edited\n', 10);
    for (const r of [rose, abop]) console.log(JSON.stringify(r));
  } else {
    await roseChecks(browser);
    await instanceChecks(browser);
    await rangeChecks(browser);
    await pickChecks(browser);
    await climberChecks(browser);
    // the latency is measured here and reported; its 300 ms target is checked by bench/run-view,
    // not by a test that a loaded machine or a sanitizer build would fail
    const rose = await latency(browser, path.join(sourceDir, 'grammars/rose/fig12c.plant'), (t) => t.replace('N_S = 5', 'N_S = 4'), 4);
    console.log(`# the rose's save-to-pixels latency: median ${rose.median_ms.toFixed(0)} ms (target 300 ms, bench/run-view)`);
  }
} catch (e) {
  check(false, 'the browser test ran to the end', String(e.stack || e));
} finally {
  await browser.close();
  for (const s of servers) s.kill('SIGINT');
  fs.rmSync(tmp, { recursive: true, force: true });
}
process.exit(failures ? 1 : 0);
