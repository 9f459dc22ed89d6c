// Browser tests of the web page against a real `nurbsx serve` on the loopback interface,
// in Debian's headless Chromium (playwright-core drives it; no browser is downloaded).
//
//   node tests/e2e.mjs            (from web/, after `npm run build` and `cargo build`)
//
// Environment: NURBSX_BIN (default ../target/debug/nurbsx), CHROMIUM (default
// /usr/bin/chromium), E2E_OUT (screenshots and the downloaded file; default
// ../target/web-e2e), E2E_PART (default the FreeCAD sample extrude_bspline.step, a B-spline extrusion solid),
// E2E_README_SHOT (when set: also writes the README's picture of the page to that path).
// Exit status 0 when every check passes; each failed check is printed.
import { spawn, execFileSync } from 'node:child_process';
import { createServer } from 'node:net';
import { mkdirSync, readFileSync } from 'node:fs';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const repo = resolve(here, '..', '..');
const bin = resolve(process.env.NURBSX_BIN ?? join(repo, 'target', 'debug', 'nurbsx'));
const browserPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
const out = resolve(process.env.E2E_OUT ?? join(repo, 'target', 'web-e2e'));
const part = resolve(process.env.E2E_PART ?? join(repo, 'samples', 'freecad', 'parts', 'extrude_bspline.step'));
const broken = join(repo, 'tests', 'bad_inputs', 'step_bad_real.step');
const parts = join(repo, 'samples', 'freecad', 'parts');
/** FreeCAD's assembly sample: `Bracket` twice and `Pin`, placed (samples/freecad/parts/generate.py). */
const assembly = join(parts, 'assembly_links.step');
/**
 * The placements generate.py gave the assembly's instances: translation, rotation angle in
 * degrees and axis (Bracket_1 at the origin, unrotated).
 */
const PLACEMENTS = {
  Bracket_2: { t: [40, 0, 0], angle: 30, axis: [Math.SQRT1_2, Math.SQRT1_2, 0] },
  Pin_1: { t: [10, 5, -5], angle: 15, axis: [0, 1, 0] },
};
/** FreeCAD's cone frustum r 20 -> 10, height 25, with a bore of r 5 (generate.py). */
const cone = join(parts, 'cone_frustum_bore.step');
const CONE_RADII = [20, 10, 5];
/** FreeCAD's cylinder r 5, h 12 lateral face as a NURBS (samples/freecad/generate.py). */
const cylinder = join(repo, 'samples', 'freecad', 'surf_cylinder_nurbs.step');
/** The whole run is bounded: past this the processes are killed and the run fails. */
const DEADLINE_MS = 240_000;
mkdirSync(out, { recursive: true });

let failures = 0;
function check(ok, what, detail = '') {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}${detail ? `: ${detail}` : ''}`);
  if (!ok) failures += 1;
}

/** `nurbsx <args> --json` parsed (the CLI is the independent reference for the page). */
function cli(...args) {
  try {
    return JSON.parse(execFileSync(bin, [...args, '--json'], { encoding: 'utf8', maxBuffer: 256 << 20 }));
  } catch (e) {
    // validate exits non-zero for an invalid file but still prints its report.
    if (e.stdout) return JSON.parse(e.stdout);
    throw e;
  }
}

function freePort() {
  return new Promise((ok, fail) => {
    const s = createServer();
    s.once('error', fail);
    s.listen(0, '127.0.0.1', () => {
      const { port } = s.address();
      s.close(() => ok(port));
    });
  });
}

const children = [];
async function serve(...extra) {
  const port = await freePort();
  const child = spawn(bin, ['serve', '--addr', `127.0.0.1:${port}`, ...extra], {
    stdio: ['ignore', 'ignore', 'inherit'],
    env: { ...process.env, RUST_LOG: 'warn' },
  });
  children.push(child);
  const base = `http://127.0.0.1:${port}`;
  for (let i = 0; i < 100; i += 1) {
    try {
      if ((await fetch(`${base}/healthz`)).ok) return base;
    } catch {
      // not listening yet
    }
    await new Promise((r) => setTimeout(r, 100));
  }
  throw new Error(`nurbsx serve did not come up on ${base}`);
}

let browser;
function stopAll() {
  for (const c of children) if (c.exitCode == null) c.kill('SIGKILL');
  browser?.close().catch(() => {});
}
const timer = setTimeout(() => {
  console.log(`FAIL the browser tests took longer than ${DEADLINE_MS / 1000} s`);
  stopAll();
  process.exit(1);
}, DEADLINE_MS);

/** Drops a file on the page as a user's drag and drop does (a `drop` event with files). */
async function drop(page, path) {
  const data = readFileSync(path).toString('base64');
  const dt = await page.evaluateHandle(({ data, name }) => {
    const raw = Uint8Array.from(atob(data), (c) => c.charCodeAt(0));
    const t = new DataTransfer();
    t.items.add(new File([raw], name));
    return t;
  }, { data, name: basename(path) });
  await page.dispatchEvent('#view', 'dragover', { dataTransfer: dt });
  await page.dispatchEvent('#view', 'drop', { dataTransfer: dt });
}

async function partTest(base) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  page.on('pageerror', (e) => check(false, 'no script error on the page', e.message));
  await page.goto(base);
  check((await page.title()).includes('nurbsx'), 'GET / serves the web page');
  await drop(page, part);
  await page.waitForSelector('body[data-loaded]', { timeout: 60_000 });
  check(await page.getAttribute('body', 'data-loaded') === 'true', 'the part loads', await page.textContent('#status-text'));

  const info = cli('info', part);
  const s = info.structure;
  const faceIds = new Set(s.faces.map((f) => f.id));
  const surfaceToFace = new Map(s.faces.filter((f) => f.surface).map((f) => [f.surface, f.id]));
  const summary = await page.$eval('#tree-summary', (e) => ({ ...e.dataset }));
  check(Number(summary.faces) === s.faces.length, 'tree face count = nurbsx info', `${summary.faces} vs ${s.faces.length}`);
  check(Number(summary.solids) === s.solids.length, 'tree solid count = nurbsx info', `${summary.solids} vs ${s.solids.length}`);
  check(Number(summary.shells) === s.shells.length, 'tree shell count = nurbsx info', `${summary.shells} vs ${s.shells.length}`);
  const rows = await page.$$eval('#tree li.face [data-select]', (b) => b.map((x) => x.dataset.select));
  check(rows.length === s.faces.length && rows.every((id) => faceIds.has(id)) && new Set(rows).size === rows.length,
    'one tree row per face of nurbsx info', `${rows.length} rows`);
  const solidRows = await page.$$eval('#tree li.solid', (x) => x.length);
  check(solidRows === s.solids.length, 'one tree node per solid', `${solidRows}`);
  const freeIds = info.entities.filter((e) => e.kind === 'curve' && e.dimension === 3 && e.role === 'free').map((e) => e.id);
  const freeRows = await page.$$eval('#free-curves [data-select]', (b) => b.map((x) => x.dataset.select));
  check(freeRows.length === freeIds.length && freeRows.every((id) => freeIds.includes(id)),
    'the free curves listed apart are those nurbsx info calls free', `${freeRows.length} rows, ${freeIds.length} free`);

  const view = await page.evaluate(() => window.nurbsxPage.view());
  const shown = view.faces.filter((id) => faceIds.has(id) || surfaceToFace.has(id));
  check(view.faces.length > 0 && shown.length === view.faces.length, 'every face mesh in the view is a face of the part (by id)',
    `${view.faces.length} meshes, ${shown.length} named by a face or its surface`);
  const meshFaces = new Set(view.faces.map((id) => (faceIds.has(id) ? id : surfaceToFace.get(id))));
  console.log(`     ${meshFaces.size} of ${s.faces.length} faces have a mesh; ${view.curves.length} curves drawn`);

  // Pick: hide curves (so the ray meets a face), click a face's mesh where it projects.
  await page.uncheck('#show-edges');
  let picked = null;
  for (const id of view.faces.slice(0, 12)) {
    const p = await page.evaluate((i) => window.nurbsxPage.screenPointOf(i), id);
    if (!p) continue;
    await page.mouse.click(p.x, p.y);
    picked = await page.getAttribute('#selection', 'data-id');
    if (picked) break;
  }
  check(picked != null && faceIds.has(picked), 'clicking a face in the view shows its face id', String(picked));
  if (picked) {
    const pressed = await page.getAttribute(`#tree [data-select="${picked}"]`, 'aria-pressed');
    check(pressed === 'true', 'the picked face is highlighted in the tree');
    const text = await page.textContent('#selection');
    check(/Degree/.test(text) && /Poles/.test(text) && /Knots/.test(text) && /Area/.test(text),
      'the selection panel shows degree, poles, knots and area');
  }
  await page.check('#show-edges');
  // A tree row selects too (keyboard: focus and Enter).
  const firstRow = page.locator('#tree li.face button').first();
  await firstRow.focus();
  await page.keyboard.press('Enter');
  check(await page.getAttribute('#selection', 'data-id') === rows[0], 'Enter on a tree row selects that face');
  await page.screenshot({ path: join(out, 'part.png') });

  // Convert to IGES (144), download, read the file back with the CLI.
  await page.selectOption('#target', 'iges:144');
  const [download] = await Promise.all([
    page.waitForEvent('download', { timeout: 120_000 }),
    page.click('#convert-go'),
  ]);
  const saved = join(out, download.suggestedFilename());
  await download.saveAs(saved);
  check(saved.endsWith('.igs'), 'the download is an IGES file', basename(saved));
  const back = cli('info', saved);
  check(back.format === 'iges', 'nurbsx info reads the downloaded file as IGES');
  check(back.structure?.faces.length === s.faces.length, 'the downloaded IGES has the part\'s faces',
    `${back.structure?.faces.length} vs ${s.faces.length}`);
  const verify = await page.textContent('#verify-report');
  check(/Verified\s*yes/.test(verify), 'the page shows the verification figures', verify.replace(/\s+/g, ' ').slice(0, 160));
  await page.screenshot({ path: join(out, 'part-converted.png') });

  // Phone-sized viewport: nothing wider than the screen, controls reachable.
  await page.setViewportSize({ width: 390, height: 844 });
  const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
  check(overflow <= 0, 'no horizontal scrolling at 390 px', `${overflow} px too wide`);
  check(await page.isVisible('label[for=file]') && await page.isVisible('#fit'), 'open and Fit visible at 390 px');
  await page.screenshot({ path: join(out, 'part-phone.png'), fullPage: true });
  await page.close();
}

async function assemblyTest(base) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.on('pageerror', (e) => check(false, 'no script error on the page', e.message));
  await page.goto(base);
  await drop(page, assembly);
  await page.waitForSelector('body[data-loaded]', { timeout: 60_000 });
  check(await page.getAttribute('body', 'data-loaded') === 'true', 'the assembly loads', await page.textContent('#status-text'));
  const s = cli('info', assembly).structure;
  const inst = s.instances ?? [];
  const rows = await page.$$eval('#tree li.instance', (l) => l.map((li) => {
    const b = li.querySelector(':scope > details > summary [data-select]');
    let depth = 0;
    for (let p = li; p; p = p.parentElement.closest('li.instance')) depth += 1;
    return { key: b.dataset.select, name: b.querySelector('.row-id').textContent, text: b.textContent, depth };
  }));
  check(inst.length > 0 && rows.length === inst.length, 'one tree node per assembly instance of nurbsx info', `${rows.length} vs ${inst.length}`);
  check(Number(await page.getAttribute('#tree-summary', 'data-instances')) === inst.length, 'the tree summary counts the instances');
  check(rows.every((r, k) => inst[k] && r.key === `instance:${inst[k].path}` && r.name === inst[k].path.split('/').pop() && r.depth === inst[k].depth
      && r.text.includes(`instance of ${inst[k].product}`)),
    'the instances\' names, products, order and nesting are those of nurbsx info', rows.map((r) => `${r.name}@${r.depth}`).join(' '));
  // An instance's faces, from nurbsx info: what it and the instances under it place.
  const solids = new Map(s.solids.map((x) => [x.id, x]));
  const shells = new Map(s.shells.map((x) => [x.id, x]));
  const facesOf = (path) => s.instances.filter((i) => i.path === path || i.path.startsWith(`${path}/`))
    .flatMap((i) => i.places).flatMap((id) => (solids.get(id)?.shell_ids ?? [id]))
    .flatMap((id) => shells.get(id)?.face_ids ?? (s.faces.some((f) => f.id === id) ? [id] : []));
  for (const i of inst) {
    await page.click(`#tree [data-select="instance:${i.path}"]`);
    const lit = new Set(await page.evaluate(() => window.nurbsxPage.highlighted()));
    const want = facesOf(i.path);
    check(want.length > 0 && lit.size === want.length && want.every((id) => lit.has(id)),
      `clicking instance ${i.path} highlights exactly its faces in the view`, `${lit.size} highlighted, ${want.length} faces`);
    check(await page.getAttribute('#selection', 'data-id') === `instance:${i.path}`, `the facts panel shows instance ${i.path}`);
    const expected = PLACEMENTS[i.path];
    if (!expected) continue;
    const text = await page.textContent('#placement');
    const t = /translation \(([^)]*)\)/.exec(text)?.[1].split(', ').map(Number) ?? [];
    const r = /rotation ([\d.e+-]+)° about \(([^)]*)\)/.exec(text);
    const axis = r?.[2].split(', ').map(Number) ?? [];
    check(t.length === 3 && t.every((x, k) => Math.abs(x - expected.t[k]) < 1e-6)
        && r && Math.abs(Number(r[1]) - expected.angle) < 1e-4 && axis.every((x, k) => Math.abs(x - expected.axis[k]) < 1e-5),
      `${i.path}'s placement shown is generate.py's: ${expected.angle}° about (${expected.axis.map((x) => x.toFixed(4))}), moved by (${expected.t})`,
      text.replace(/\s+/g, ' '));
  }
  // Keyboard: Enter on an instance selects it and leaves its branch open.
  const first = `#tree [data-select="instance:${inst[0].path}"]`;
  await page.focus(first);
  await page.keyboard.press('Enter');
  check(await page.getAttribute('#selection', 'data-id') === `instance:${inst[0].path}`
      && await page.$eval(first, (b) => b.closest('details').open),
    'Enter on an instance selects it and does not fold it');
  // The view with the keyboard: Shift+arrow orbits, arrow pans, + zooms in.
  const camera = () => page.evaluate(() => window.nurbsxPage.camera());
  const dist = (c) => Math.hypot(...c.position.map((x, k) => x - c.target[k]));
  await page.focus('#view');
  let before = await camera();
  await page.keyboard.press('Shift+ArrowLeft');
  let after = await camera();
  check(Math.abs(dist(after) - dist(before)) < 1e-6 * dist(before) && after.position.some((x, k) => Math.abs(x - before.position[k]) > 1e-6 * dist(before))
      && after.target.every((x, k) => x === before.target[k]), 'Shift+arrow on the view orbits (same distance, same target)');
  before = after;
  await page.keyboard.press('ArrowLeft');
  after = await camera();
  check(after.target.some((x, k) => Math.abs(x - before.target[k]) > 1e-6 * dist(before)), 'an arrow key on the view pans (the target moves)');
  before = after;
  await page.keyboard.press('+');
  after = await camera();
  check(Math.abs(dist(after) - 0.8 * dist(before)) < 1e-6 * dist(before), '+ on the view zooms in (distance × 0.8)');
  await page.click('#fit');
  await page.click(`#tree [data-select="instance:${inst.at(-1)?.path}"]`);
  await page.screenshot({ path: join(out, 'assembly.png') });
  await page.setViewportSize({ width: 390, height: 844 });
  const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
  check(overflow <= 0, 'no horizontal scrolling at 390 px with the assembly tree', `${overflow} px too wide`);
  await page.screenshot({ path: join(out, 'assembly-phone.png'), fullPage: true });
  await page.close();
}

async function lengthTest(base) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.on('pageerror', (e) => check(false, 'no script error on the page', e.message));
  await page.goto(base);
  await drop(page, cone);
  await page.waitForSelector('body[data-loaded]', { timeout: 60_000 });
  // The circle edges: curves in one plane z = const whose control points come no nearer the
  // axis than one of the radii generate.py used (a NURBS circle's middle poles lie on it).
  const circles = cli('info', cone).entities.filter((e) => e.kind === 'curve' && e.dimension === 3).flatMap((e) => {
    const cp = e.geometry.control_points;
    const r = Math.min(...cp.map((p) => Math.hypot(p[0], p[1])));
    const flat = cp.every((p) => Math.abs(p[2] - cp[0][2]) < 1e-9);
    const radius = CONE_RADII.find((x) => Math.abs(x - r) < 1e-9);
    return flat && radius ? [{ id: e.id, radius }] : [];
  });
  check(circles.length === 4, 'the cone has its 4 circle edges (r 20, 10, 5, 5)', circles.map((c) => `${c.id} r ${c.radius}`).join(', '));
  let picked = null;
  for (const c of circles) {
    for (const t of [0.25, 0.5, 0.75, 0.1, 0.4, 0.6, 0.9]) {
      const p = await page.evaluate(([id, f]) => window.nurbsxPage.screenPointOf(id, f), [c.id, t]);
      if (!p) continue;
      await page.mouse.click(p.x, p.y);
      if (await page.getAttribute('#selection', 'data-id') === c.id) {
        picked = c;
        break;
      }
    }
    if (picked) break;
  }
  check(picked != null, 'clicking a circle edge in the view selects it', picked?.id ?? 'none picked');
  if (picked) {
    await page.waitForSelector('#measured:not([data-state=measuring])', { timeout: 30_000 });
    const m = await page.$eval('#measured', (e) => ({ ...e.dataset, text: e.textContent }));
    const exact = 2 * Math.PI * picked.radius;
    const shown = Number(/^[\d.e+-]+/.exec(m.text)?.[0]);
    check(m.state === 'exact' && Math.abs(shown - exact) <= 1e-9 * exact && Number(m.error) < 1e-6 && /±/.test(m.text),
      `the length shown for the r ${picked.radius} circle is 2πr = ${exact.toPrecision(12)} with its error estimate`, m.text);
  }
  // When the measure fails, the polyline's length is shown, and said to be one.
  await page.route('**/v1/measure', (r) => r.abort());
  const other = circles.find((c) => c.id !== picked?.id);
  if (other) {
    if (!(await page.isVisible(`#tree [data-select="${other.id}"]`))) await page.click('#tree summary:has-text("Edge curves")');
    await page.click(`#tree [data-select="${other.id}"]`);
    await page.waitForSelector('#measured:not([data-state=measuring])', { timeout: 30_000 });
    const m = await page.$eval('#measured', (e) => ({ ...e.dataset, text: e.textContent }));
    const rough = Number(/≈ ([\d.e+-]+)/.exec(m.text)?.[1]);
    const exact = 2 * Math.PI * other.radius;
    check(m.state === 'failed' && /drawn polyline/.test(m.text) && /failed/.test(m.text) && rough < exact && rough > exact * 0.99,
      'a failed measure shows the polyline length (inscribed: a little under 2πr) and says so', m.text);
  }
  await page.close();
}

/** A free surface's area, with the file sent as model JSON: 2π r h of the cylinder. */
async function areaTest(base) {
  const json = join(out, 'surf_cylinder_nurbs.json');
  execFileSync(bin, ['clamp', cylinder, '-o', json], { stdio: 'ignore' }); // model JSON, faces dropped
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.on('pageerror', (e) => check(false, 'no script error on the page', e.message));
  await page.goto(base);
  await drop(page, json);
  await page.waitForSelector('body[data-loaded]', { timeout: 60_000 });
  const surfaces = cli('info', json).entities.filter((e) => e.kind === 'surface');
  check(surfaces.length === 1, 'the model JSON holds the one cylinder surface', `${surfaces.length}`);
  await page.click(`#tree [data-select="${surfaces[0]?.id}"]`);
  await page.waitForSelector('#measured:not([data-state=measuring])', { timeout: 30_000 });
  const m = await page.$eval('#measured', (e) => ({ ...e.dataset, text: e.textContent }));
  const exact = 2 * Math.PI * 5 * 12;
  const shown = Number(/^[\d.e+-]+/.exec(m.text)?.[0]);
  check(m.state === 'exact' && Math.abs(shown - exact) <= 1e-9 * exact && /±/.test(m.text),
    `the area shown for the free cylinder surface is 2πrh = ${exact.toPrecision(12)} with its error estimate`, m.text);
  await page.close();
}

/** The README's picture: FreeCAD's filleted box with its first fillet selected. */
async function readmeShot(base, path) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(base);
  const box = join(parts, 'box_fillet_chamfer_hole.step');
  await drop(page, box);
  await page.waitForSelector('body[data-loaded=true]', { timeout: 60_000 });
  const fillet = cli('info', box).structure.faces.find((f) => f.shape === 'cylinder');
  await page.click(`#tree [data-select="${fillet.id}"]`);
  await page.screenshot({ path });
  console.log(`     README picture: ${path}`);
  await page.close();
}

async function brokenTest(base) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(base);
  await drop(page, broken);
  await page.waitForSelector('body[data-loaded]', { timeout: 60_000 });
  const [report] = cli('validate', broken);
  const summary = await page.textContent('#diag-summary');
  check(/Not valid/.test(summary), 'a broken file is reported not valid', summary);
  // Errors and warnings (the page also lists the reader's notes, which the CLI prints apart).
  const items = await page.$$eval('#diagnostics li.diag', (l) => l.map((x) => x.textContent)
    .filter((t) => /^(error|warning)/.test(t.trim())));
  const expected = report.diagnostics.filter((d) => d.severity !== 'info');
  check(items.length === expected.length && expected.length > 0, 'as many errors and warnings as nurbsx validate', `${items.length} vs ${expected.length}`);
  const first = expected[0];
  check(items.length > 0 && items[0].includes(first.code) && items[0].includes(first.message)
      && items[0].includes(`line ${first.location.line}:${first.location.column}`) && items[0].includes(first.location.entity),
    'the first error shows its code, message, line:column and entity', items[0]);
  const status = await page.textContent('#status-text');
  check(/could not be (read|built)/.test(status), 'the status line says what failed', status);
  // Clicking a located diagnostic selects its entity.
  await page.click('#diagnostics li.diag button');
  check(await page.getAttribute('#selection', 'data-id') === first.location.entity, 'clicking the diagnostic selects its entity');
  await page.screenshot({ path: join(out, 'broken.png') });
  await page.close();
}

async function tooLargeTest() {
  const base = await serve('--max-body', '2KiB');
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(base);
  await page.waitForFunction(() => document.readyState === 'complete');
  await page.waitForTimeout(200);
  await drop(page, part);
  await page.waitForFunction(() => /accepts at most/.test(document.getElementById('status-text').textContent), null, { timeout: 10_000 });
  const status = await page.textContent('#status-text');
  check(/2\.0 KiB/.test(status), 'a file over the body limit gets a clear message', status);
  await page.close();
}

try {
  const base = await serve();
  browser = await chromium.launch({
    executablePath: browserPath,
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  await partTest(base);
  await assemblyTest(base);
  await lengthTest(base);
  await areaTest(base);
  await brokenTest(base);
  if (process.env.E2E_README_SHOT) await readmeShot(base, resolve(process.env.E2E_README_SHOT));
  await tooLargeTest();
} catch (e) {
  check(false, 'the browser tests ran to the end', e.stack ?? String(e));
} finally {
  clearTimeout(timer);
  stopAll();
}
console.log(failures ? `${failures} check(s) failed` : 'all browser checks passed');
console.log(`screenshots: ${out}`);
process.exit(failures ? 1 : 0);
