// Browser test of `cfinspect --html` (ctest: cfinspect:viewer). Writes the viewer of a graph
// with cfreplay's replay of a trajectory, opens it from file:// in headless Chromium
// (playwright-core, Debian's /usr/bin/chromium, SwiftShader WebGL) and checks what a person
// would: the PCs listed and highlighted for a selected CF, the filters, the neighbours, a
// canvas that is not blank, a replay that animates (embedded and opened in the page), no
// console errors, and no request for anything but the page itself.
//
//   node viewer_test.mjs --cfinspect BIN --cfreplay BIN --graph G.json --trajectory P.csv
//                        --press PRESS.csv --out DIR [--screenshots DIR]
// PRESS.csv is a trajectory whose device goes into B, so that the proxy holds A back.
//
// Exit 0: passed; 1: failed; 77: skipped (no Chromium or no npm packages), which is a failure
// under CI=true, where the set-up scripts install them.
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const args = {};
for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
for (const k of ['cfinspect', 'cfreplay', 'graph', 'trajectory', 'press', 'out'])
  if (!args[k]) { console.error(`viewer_test: missing --${k}`); process.exit(2); }

function skip(why) {
  if (process.env.CI === 'true') { console.error(`viewer_test: FAILED: ${why} (CI must run this test)`); process.exit(1); }
  console.log(`viewer_test: SKIPPED: ${why}`);
  process.exit(77);
}
const chromium = process.env.CF_CHROMIUM || '/usr/bin/chromium';
if (!existsSync(chromium)) skip(`no Chromium at ${chromium} (Debian package chromium; bash scripts/install-deps.sh installs it)`);
let playwright;
try { playwright = await import('playwright-core'); } catch { skip('no playwright-core (bash scripts/install-npm.sh runs npm ci in tools/cfinspect/viewer)'); }

let passed = 0, failed = 0;
function check(ok, what, detail = '') {
  if (ok) { ++passed; console.log(`ok   ${what}`); } else { ++failed; console.log(`FAIL ${what}${detail ? `: ${detail}` : ''}`); }
}

// --- the pages -------------------------------------------------------------------------
const out = resolve(args.out);
mkdirSync(out, { recursive: true });
const replayCsv = join(out, 'replay.csv'), replayPage = join(out, 'replay.html'), plainPage = join(out, 'graph.html');
execFileSync(args.cfreplay, ['--graph', args.graph, '--trajectory', args.trajectory, '-o', replayCsv], { stdio: 'inherit' });
const html = (extra) => execFileSync(args.cfinspect, [args.graph, '--fast', ...extra], { encoding: 'utf8' });
check(/wrote .*graph\.html \(viewer of \d+ CFs\)/.test(html(['--html', plainPage])), 'cfinspect --html writes the page');
html(['--html', replayPage, '--replay', replayCsv, '--trajectory', args.trajectory]);
// A device pressed into B, and the last CF named with --cf.
const pressCsv = join(out, 'press.csv'), pressPage = join(out, 'press.html'), lastPage = join(out, 'last.html');
execFileSync(args.cfreplay, ['--graph', args.graph, '--trajectory', args.press, '-o', pressCsv], { stdio: 'inherit' });
html(['--html', pressPage, '--replay', pressCsv, '--trajectory', args.press]);

// What the test expects comes from the files, not from the page.
const graph = JSON.parse(readFileSync(args.graph, 'utf8'));
const replayRows = readFileSync(replayCsv, 'utf8').trim().split('\n').slice(1).map((l) => l.split(','));
const KIND = { v: 'vertex', e: 'edge', f: 'face' };
const pcText = (pc) => `${pc.type}:${pc.a}:${pc.b}`;
// A CF with two PCs of different element kinds and neighbours of two kinds or more, if any.
const kinds = (id) => new Set(graph.transitions.filter((t) => t.from === id).map((t) => t.kind));
html(['--html', lastPage, '--cf', String(graph.cfs.length - 1)]);
const cf = graph.cfs.find((c) => c.pcs.length === 2 && c.pcs[0].type[0] !== c.pcs[1].type[0] && c.pcs[0].type[2] !== c.pcs[1].type[2] && kinds(c.id).size >= 2) ||
  graph.cfs.find((c) => c.pcs.length === 2) || graph.cfs[0];

// --- the browser -----------------------------------------------------------------------
const browser = await playwright.chromium.launch({ executablePath: chromium, headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'] });
const errors = [];
async function open(file) {
  const page = await browser.newPage({ viewport: { width: 1400, height: 820 } });
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`${file}: console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`${file}: page error: ${e.message}`));
  // Offline: the page may load nothing but itself (and data: or blob: URLs).
  page.on('request', (r) => { if (!/^(data|blob):/.test(r.url()) && r.url() !== pathToFileURL(file).href) errors.push(`${file}: fetched ${r.url()}`); });
  await page.goto(pathToFileURL(file).href);
  try {
    await page.waitForFunction(() => window.cfViewer && window.cfViewer.state.ready, null, { timeout: 20000 });
  } catch (e) {
    throw new Error(`${file} did not get ready: ${errors.join('; ') || e.message}`);
  }
  return page;
}
// Pixels of the WebGL canvas (drawn with preserveDrawingBuffer): how many are not the
// white background, how many distinct colours, and how many are near each given colour.
const pixels = (page, colours = []) => page.evaluate((cols) => {
  const src = document.querySelector('#view canvas');
  const c = document.createElement('canvas');
  c.width = src.width; c.height = src.height;
  const ctx = c.getContext('2d');
  ctx.drawImage(src, 0, 0);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  const rgb = cols.map((h) => [1, 3, 5].map((i) => parseInt(h.slice(i, i + 2), 16)));
  const near = rgb.map(() => 0), seen = new Set();
  let ink = 0, sum = 0;
  for (let i = 0; i < d.length; i += 4) {
    if (d[i] < 250 || d[i + 1] < 250 || d[i + 2] < 250) ++ink;
    seen.add((d[i] >> 3) << 10 | (d[i + 1] >> 3) << 5 | d[i + 2] >> 3);
    sum = (sum * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) % 1000000007;
    rgb.forEach((q, k) => { if (Math.abs(d[i] - q[0]) + Math.abs(d[i + 1] - q[1]) + Math.abs(d[i + 2] - q[2]) < 24) ++near[k]; });
  }
  return { total: d.length / 4, ink, colours: seen.size, near, sum };
}, colours);

try {
  // Select a CF by its id, as a person would.
  const page = await open(plainPage);
  check(await page.locator('#cf-list div[data-id]').count() === Math.min(graph.cfs.length, 2000), 'the CF list lists the CFs');
  await page.fill('#search', String(cf.id));
  await page.press('#search', 'Enter');
  const shown = await page.evaluate(() => window.cfViewer.state.selected);
  check(shown === cf.id, `searching id ${cf.id} selects it`, `selected ${shown}`);
  const listed = await page.$$eval('#pcs li', (lis) => lis.map((li) => li.dataset.pc));
  check(JSON.stringify(listed) === JSON.stringify(cf.pcs.map(pcText)), `CF ${cf.id}'s PCs are listed`, `${listed} vs ${cf.pcs.map(pcText)}`);
  const hl = await page.evaluate(() => window.cfViewer.state.highlighted);
  const want = cf.pcs.map((pc) => ({ pc: pcText(pc), a: { model: 'A', kind: KIND[pc.type[0]], index: pc.a }, b: { model: 'B', kind: KIND[pc.type[2]], index: pc.b } }));
  const strip = ({ model, kind, index }) => ({ model, kind, index });
  check(JSON.stringify(hl.map(({ pc, a, b }) => ({ pc, a: strip(a), b: strip(b) }))) === JSON.stringify(want),
    'the contacting elements of A and B are highlighted', JSON.stringify(hl));
  // And drawn where those elements are: A's at the witness pose (x_B = R x_A + t).
  const { R, t } = cf.witness;
  const atWitness = (p) => R.map((row, i) => row[0] * p[0] + row[1] * p[1] + row[2] * p[2] + t[i]);
  const centre = (model, kind, index, pose) => {
    const ids = kind === 'v' ? [index] : kind === 'e' ? model.edges[index] : model.faces[index].loops.flat();
    const ps = ids.map((i) => pose(model.vertices[i]));
    return [0, 1, 2].map((k) => (Math.min(...ps.map((p) => p[k])) + Math.max(...ps.map((p) => p[k]))) / 2);
  };
  const far = (p, q) => Math.hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
  const off = cf.pcs.map((pc, k) => Math.max(far(hl[k].a.drawnAt, centre(graph.models.A, pc.type[0], pc.a, atWitness)),
    far(hl[k].b.drawnAt, centre(graph.models.B, pc.type[2], pc.b, (p) => p))));
  check(off.every((d) => d < 1e-3), 'the highlights are drawn at the elements, A\'s at the witness pose', `off by ${off} mm`);
  const m = await page.evaluate(() => window.cfViewer.poseA());  // column-major 4x4
  check([0, 1, 2].every((i) => [0, 1, 2].every((j) => Math.abs(m[4 * j + i] - R[i][j]) < 1e-12) && Math.abs(m[12 + i] - t[i]) < 1e-12),
    'A is drawn at the witness pose');
  check(new Set(hl.map((h) => h.colour)).size === cf.pcs.length, 'one colour per PC');
  const px = await pixels(page, hl.map((h) => h.colour));
  check(px.ink > px.total * 0.02 && px.colours > 20, 'the canvas is not blank', JSON.stringify(px));
  check(px.near.some((n) => n > 20), 'a highlight colour is on the canvas', JSON.stringify(px.near));
  const freedoms = await page.textContent('#freedoms');
  check(cf.dof === undefined || freedoms.includes(`${cf.dof} dof`), 'the freedoms are stated', freedoms);
  if (args.screenshots) await page.screenshot({ path: join(args.screenshots, 'viewer-cf.png') });

  // Neighbours by kind, one click away.
  for (const kind of ['gain', 'lose', 'change']) {
    const n = graph.transitions.filter((t) => t.from === cf.id && t.kind === kind).length;
    check(await page.locator(`#neighbours button[data-kind="${kind}"]`).count() === n, `${n} ${kind} neighbours listed`);
  }
  await page.locator('#cf-list div[data-id]').first().click();  // a click on a row selects it
  await page.keyboard.press('ArrowDown');
  const second = await page.evaluate(() => [window.cfViewer.state.selected, window.cfViewer.state.listed[1]]);
  check(second[0] === second[1], 'the down arrow selects the next listed CF', JSON.stringify(second));
  await page.fill('#search', String(cf.id));
  await page.press('#search', 'Enter');
  const nb = page.locator('#neighbours button.nb').first();
  const to = Number(await nb.getAttribute('data-to'));
  await nb.click();
  check(await page.evaluate(() => window.cfViewer.state.selected) === to, `clicking a neighbour selects CF ${to}`);

  // Filters: number of PCs, PC type, an element of B.
  await page.selectOption('#f-num', '1');
  for (const t of ['f-f', 'e-f', 'f-e', 'f-v', 'e-e']) await page.uncheck(`#f-types input[data-type="${t}"]`);
  const vf = graph.cfs.filter((c) => c.pcs.length === 1 && c.pcs[0].type === 'v-f').length;
  check(await page.evaluate(() => window.cfViewer.state.listed.length) === vf, `filters: ${vf} CFs of one v-f PC`);
  await page.selectOption('#f-num', '');
  for (const t of ['f-f', 'e-f', 'f-e', 'f-v', 'e-e']) await page.check(`#f-types input[data-type="${t}"]`);
  await page.selectOption('#f-model', 'B');
  await page.selectOption('#f-kind', 'f');
  await page.fill('#f-index', '0');
  const onFace0 = graph.cfs.filter((c) => c.pcs.some((pc) => pc.type[2] === 'f' && pc.b === 0)).length;
  check(await page.evaluate(() => window.cfViewer.state.listed.length) === onFace0, `filters: ${onFace0} CFs touching face 0 of B`);

  // A replay opened in the page.
  await page.setInputFiles('#trajectory-file', args.trajectory);
  await page.setInputFiles('#replay-file', replayCsv);
  await page.waitForFunction(() => window.cfViewer.state.replay !== null, null, { timeout: 10000 });
  const opened = await page.evaluate(() => ({ rows: window.cfViewer.state.replay.rows.length, poses: !!window.cfViewer.state.replay.poses }));
  check(opened.rows === replayRows.length && opened.poses, 'a replay CSV and its trajectory open in the page', JSON.stringify(opened));
  await page.close();

  // The embedded replay animates: A moves, the tick's CF is shown, the arrows are drawn.
  const rp = await open(replayPage);
  const first = await rp.evaluate(() => ({ tick: window.cfViewer.state.replay.tick, pose: window.cfViewer.poseA() }));
  const px0 = await pixels(rp);
  await rp.click('#play');
  // Until the replay is past tick 10, not for a fixed time: headless Chromium renders in
  // software, and on a loaded 2-core machine a frame can take most of a second.
  await rp.waitForFunction(() => window.cfViewer.state.replay.tick > 10, null, { timeout: 30000 }).catch(() => {});
  await rp.click('#play');  // pause
  const later = await rp.evaluate(() => ({ tick: window.cfViewer.state.replay.tick, pose: window.cfViewer.poseA(),
    selected: window.cfViewer.state.selected, arrows: window.cfViewer.arrows(), info: document.querySelector('#tick-info').textContent }));
  check(first.tick === 0 && later.tick > 10, 'play advances the ticks', `${first.tick} -> ${later.tick}`);
  check(JSON.stringify(first.pose) !== JSON.stringify(later.pose), 'A moves');
  const row = replayRows[later.tick];
  check(later.selected === Number(row[1]) && later.info.includes(`motion ${row[3]}`), `tick ${later.tick}: CF ${row[1]} and motion ${row[3]} shown`, later.info);
  check(later.arrows.F, 'the force arrow is drawn');
  // A is drawn where it was rendered: cfreplay's proxy pose columns of that tick.
  const hdr = readFileSync(replayCsv, 'utf8').split('\n')[0].split(',');
  const pt = ['proxy_tx', 'proxy_ty', 'proxy_tz'].map((c) => Number(row[hdr.indexOf(c)]));
  const drawn = [later.pose[12], later.pose[13], later.pose[14]];  // Matrix4.toArray: column-major
  check(hdr.indexOf('proxy_tx') > 0 && pt.every((x, i) => Math.abs(x - drawn[i]) < 1e-6),
    `tick ${later.tick}: A at the proxy pose (${pt.join(', ')})`, JSON.stringify(later.pose));
  check((await pixels(rp)).sum !== px0.sum, 'the canvas changes as the replay runs');
  // The time slider: the tick whose CF is the most frequent contact.
  const k = replayRows.findIndex((r) => r[1] !== '-1' && r[1] === replayRows[replayRows.length >> 1][1]);
  await rp.locator('#time').fill(String(k));
  check(await rp.evaluate(() => window.cfViewer.state.replay.tick) === k, `the time slider goes to tick ${k}`);
  if (args.screenshots) await rp.screenshot({ path: join(args.screenshots, 'viewer-replay.png') });
  await rp.close();

  // y up, as the models are drawn and gravity points; B's axes in a triad in the corner.
  const lp = await open(lastPage);
  const axes = await lp.evaluate(() => window.cfViewer.screenAxes());
  const [, upMain] = axes.main, [, upTriad] = axes.triad;
  check(upMain[1] > 0 && upMain[1] > 2 * Math.abs(upMain[0]), 'the world\'s +y points up on the screen', JSON.stringify(axes.main));
  check(upTriad[1] > 0 && upTriad[1] > 2 * Math.abs(upTriad[0]), 'the triad\'s y axis points up', JSON.stringify(axes.triad));
  const corner = await lp.evaluate(({ triadPx: px, colours }) => {
    const src = document.querySelector('#view canvas');
    const c = document.createElement('canvas');
    c.width = src.width; c.height = src.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(src, 0, 0);
    const s = Math.round(px * (window.devicePixelRatio || 1));
    const d = ctx.getImageData(0, c.height - s, s, s).data;
    const rgb = colours.map((h) => [1, 3, 5].map((i) => parseInt(h.slice(i, i + 2), 16)));
    const near = (i, q) => Math.abs(d[i] - q[0]) + Math.abs(d[i + 1] - q[1]) + Math.abs(d[i + 2] - q[2]) < 40;
    const n = [0, 0, 0];
    for (let i = 0; i < d.length; i += 4) rgb.forEach((q, k) => { if (near(i, q)) ++n[k]; });
    return n;
  }, axes);
  check(corner.every((n) => n > 20), 'the triad\'s three axes are drawn in the lower left corner', JSON.stringify(corner));
  // --cf: that CF selected, its row scrolled into the list's view.
  const last = graph.cfs.length - 1;
  check(await lp.evaluate(() => window.cfViewer.state.selected) === last, `--cf ${last} selects it`);
  const sc = await lp.evaluate(() => window.cfViewer.listScroll());
  check(sc !== null && sc.rowTop >= 0 && sc.rowBottom <= sc.height && (graph.cfs.length < 50 || sc.scrollTop > 0),
    `CF ${last}'s row is scrolled into view`, JSON.stringify(sc));
  await lp.close();

  // The device pressed beyond the proxy: drawn, and the gap between them, at the tick of
  // the deepest press (from the files: the trajectory's pose against cfreplay's proxy pose).
  const pressRows = readFileSync(pressCsv, 'utf8').trim().split('\n');
  const ph = pressRows[0].split(',');
  const device = readFileSync(args.press, 'utf8').trim().split('\n').filter((l) => l && !l.startsWith('#')).slice(1)
    .map((l) => l.split(',').slice(1, 4).map(Number));
  let deepest = 0, gapMax = -1;
  pressRows.slice(1).forEach((l, i) => {
    const f = l.split(','), p = ['proxy_tx', 'proxy_ty', 'proxy_tz'].map((c) => Number(f[ph.indexOf(c)]));
    const g = Math.hypot(...p.map((x, k) => x - device[i][k]));
    if (g > gapMax) { gapMax = g; deepest = i; }
  });
  const pp = await open(pressPage);
  await pp.evaluate((k) => window.cfViewer.setTick(k), deepest);
  const gap = await pp.evaluate(() => window.cfViewer.gap());
  check(gapMax > 1 && gap.visible && Math.abs(gap.length - gapMax) < 1e-6 * Math.max(1, gapMax) &&
    gap.ends[1].every((x, k) => Math.abs(x - device[deepest][k]) < 1e-4),
    `tick ${deepest}: the device drawn ${gapMax.toFixed(3)} mm beyond the proxy`, JSON.stringify(gap));
  const info = await pp.textContent('#tick-info');
  check(info.includes(`device ${gapMax.toFixed(3)} mm beyond the proxy`), 'the gap is stated', info);
  if (args.screenshots) await pp.screenshot({ path: join(args.screenshots, 'viewer-press.png') });
  await pp.evaluate(() => window.cfViewer.select(0));
  check(!(await pp.evaluate(() => window.cfViewer.gap())).visible, 'a CF chosen by hand hides the device');
  await pp.close();
} catch (e) {
  check(false, 'the browser session', e.stack || String(e));
} finally {
  await browser.close();
}
check(errors.length === 0, 'no console errors and nothing fetched', errors.join('\n'));
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
