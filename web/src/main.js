// The nurbsx web page: drop a STEP, IGES or model-JSON file; the page calls the public API
// (/v1/info, /v1/validate, /v1/tessellate as binary glTF, /v1/convert) and shows the part,
// its structure, its diagnostics, and converts it.
import './style.css';
import { ApiError, bytes, getJson, locationText, mediaType, post } from './api.js';
import { Viewer } from './viewer.js';

const $ = (id) => document.getElementById(id);
const el = (tag, props = {}, ...children) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'class') e.className = v;
    else if (k === 'dataset') Object.assign(e.dataset, v);
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (v !== undefined && v !== null && v !== false) e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children.flat()) if (c != null) e.append(c);
  return e;
};
const num = (x, digits = 6) => (typeof x === 'number' ? Number(x.toPrecision(digits)).toString() : String(x));

/** What is loaded: the file, the info and validate replies, and the ids in the view. */
const state = {
  file: null,
  info: null,
  validation: null,
  limits: null,
  /** face id -> face (structure), surface entity id -> face */
  faces: new Map(),
  facesBySurface: new Map(),
  entities: new Map(),
  /** assembly instance path -> instance (structure.instances of /v1/info) */
  instances: new Map(),
  /** The file's text (sent again to /v1/measure) and its media type. */
  text: null,
  type: null,
  /** The part's size: the diagonal of the control points' bounding box. */
  size: 0,
  /** Counts measure requests: a reply for an older selection is dropped. */
  measureSeq: 0,
  view: { faces: [], curves: [] },
  busy: false,
};

const viewer = new Viewer($('view'), (id) => select(id, 'view'));
getJson('/limits')
  .then((l) => {
    state.limits = l;
  })
  .catch(() => {});

// ---- Status line -------------------------------------------------------------------------

function status(text, { busy = false, progress = null } = {}) {
  $('status-text').textContent = text;
  $('spinner').hidden = !busy;
  const bar = $('progress');
  bar.hidden = progress == null;
  if (progress != null) bar.value = progress;
  document.body.classList.toggle('busy', busy);
}

// ---- Opening a file ----------------------------------------------------------------------

$('file').addEventListener('change', (e) => {
  const f = e.target.files?.[0];
  if (f) open(f);
  e.target.value = '';
});
window.addEventListener('dragover', (e) => {
  e.preventDefault();
  document.body.classList.add('dragging');
});
window.addEventListener('dragleave', (e) => {
  if (e.relatedTarget == null) document.body.classList.remove('dragging');
});
window.addEventListener('drop', (e) => {
  e.preventDefault();
  document.body.classList.remove('dragging');
  const f = e.dataTransfer?.files?.[0];
  if (f) open(f);
});

/** Throws, before anything is sent, when a request carrying the file as JSON text is over the body limit. */
function withinLimit(body, what) {
  const limit = state.limits?.max_body_bytes;
  if (limit != null && body.length > limit) {
    throw new ApiError(413, 'limit.body_bytes', `the ${what} request carries the file as JSON text, ${bytes(body.length)}, over the limit of ${bytes(limit)}`);
  }
}

/** The message for a file over the server's body limit. */
function tooLarge(size, limit) {
  return `${state.file?.name ?? 'The file'} is ${bytes(size)}: the server accepts at most ${bytes(limit)} per request (nurbsx serve --max-body). Nothing was uploaded.`;
}

async function open(file) {
  if (state.busy) return;
  state.busy = true;
  state.file = file;
  state.info = null;
  state.validation = null;
  state.faces.clear();
  state.facesBySurface.clear();
  state.entities.clear();
  state.instances.clear();
  state.text = null;
  viewer.clear();
  $('view-empty').hidden = false;
  $('view-empty').textContent = 'Working…';
  $('view-count').textContent = '';
  $('left-out').hidden = true;
  $('fit').disabled = true;
  $('convert-go').disabled = true;
  $('convert-result').replaceChildren();
  $('tree').replaceChildren(el('p', { class: 'muted' }, 'Reading…'));
  $('diagnostics').replaceChildren(el('p', { class: 'muted' }, 'Checking…'));
  showSelection(null);
  try {
    await load(file);
  } finally {
    state.busy = false;
  }
}

async function load(file) {
  const limit = state.limits?.max_body_bytes;
  if (limit != null && file.size > limit) {
    status(tooLarge(file.size, limit));
    $('view-empty').textContent = 'File too large for this server.';
    $('tree').replaceChildren(el('p', { class: 'muted' }, 'Nothing loaded.'));
    $('diagnostics').replaceChildren(el('p', { class: 'muted' }, 'Nothing checked.'));
    return;
  }
  const type = mediaType(file.name);
  const text = await file.text();
  state.text = text;
  state.type = type;
  // The tessellation request carries the file inside JSON (POST /v1/tessellate).
  const tessBody = type === 'application/json'
    ? `{"geometry":${text},"tolerance":TOL,"format":"glb"}`
    : JSON.stringify({ file: text, tolerance: 0, format: 'glb' }).replace(/"tolerance":0/, '"tolerance":TOL');
  // Three uploads go at once; the bar shows their bytes together.
  const sent = [0, 0, 0];
  const total = file.size * 2 + tessBody.length;
  const progress = (i) => (n) => {
    sent[i] = n;
    const s = sent.reduce((a, b) => a + b, 0);
    if (s >= total * 0.999) status(`Uploaded ${bytes(file.size)}; the server is working…`, { busy: true });
    else status(`Uploading ${file.name}: ${bytes(s)} of ${bytes(total)}`, { busy: true, progress: s / total });
  };
  status(`Uploading ${file.name}…`, { busy: true, progress: 0 });
  const infoP = post('/v1/info', file, { contentType: type, onUpload: progress(0) });
  const validP = post('/v1/validate', file, { contentType: type, onUpload: progress(1) });
  const [info, valid] = await Promise.allSettled([infoP, validP]);
  if (valid.status === 'fulfilled') {
    state.validation = valid.value.body;
    renderDiagnostics(state.validation);
  } else {
    renderDiagnostics(null, valid.reason);
  }
  if (info.status === 'rejected') {
    fail(info.reason);
    $('tree').replaceChildren(el('p', { class: 'muted' }, 'The file could not be read: see Diagnostics.'));
    return;
  }
  state.info = info.value.body;
  index(state.info);
  renderTree(state.info);
  $('convert-go').disabled = false;
  // The chord tolerance: 1/1000 of the control points' bounding box (the part lies within it).
  state.size = partSize(state.info);
  const tol = state.size > 0 ? state.size / 1000 : 1e-3;
  status('Tessellating…', { busy: true });
  try {
    const body = tessBody.replace('TOL', String(tol));
    withinLimit(body, 'tessellation');
    const r = await post('/v1/tessellate', body, {
      contentType: 'application/json', responseType: 'arraybuffer', onUpload: progress(2),
    });
    state.view = await viewer.load(r.body);
    showLeftOut(r.xhr.getResponseHeader('x-nurbsx-left-out'));
    $('view-empty').hidden = state.view.faces.length + state.view.curves.length > 0;
    $('view-empty').textContent = 'Nothing to draw.';
    $('fit').disabled = false;
    $('view-count').textContent =
      `${state.view.faces.length} face mesh${state.view.faces.length === 1 ? '' : 'es'}, ${state.view.curves.length} curve${state.view.curves.length === 1 ? '' : 's'} drawn (chord tolerance ${num(tol, 3)} ${state.info.units.name})`;
    const d = state.validation;
    status(`${file.name}: ${state.info.format.toUpperCase()}, ${state.info.entities.length} entities${d ? `, ${d.errors} error(s), ${d.warnings} warning(s)` : ''}.`);
    document.body.dataset.loaded = 'true';
  } catch (e) {
    fail(e, 'The view could not be built');
  }
}

/** The tessellation's X-Nurbsx-Left-Out diagnostics, under the view. */
function showLeftOut(header) {
  let list = [];
  try {
    list = JSON.parse(header ?? '[]');
  } catch {
    list = [{ code: 'reply', message: 'the server did not say what the view leaves out' }];
  }
  $('left-out').replaceChildren(...list.map((d) => el('li', {}, el('code', {}, d.code), ' ', d.message)));
  $('left-out').hidden = list.length === 0;
}

function fail(e, what = 'The file could not be read') {
  let msg = e instanceof ApiError ? e.message : String(e);
  if (e instanceof ApiError && e.status === 413 && e.code === 'limit.body_bytes') {
    msg = `the request is larger than this server accepts (${e.message}); ${state.file?.name} is ${bytes(state.file?.size ?? 0)}`;
  } else if (e instanceof ApiError && e.status === 413) {
    msg = `The reply would be too large for this server: ${e.message}`;
  } else if (e instanceof ApiError && e.location) {
    const where = locationText(e.location);
    if (where) msg += ` (${where})`;
  }
  status(`${what}: ${msg}`);
  $('view-empty').hidden = false;
  $('view-empty').textContent = `${what}.`;
  document.body.dataset.loaded = 'error';
}

/** The diagonal of all control points' bounding box (0 without any); the part lies within it. */
function partSize(info) {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  const visit = (p) => {
    if (Array.isArray(p) && typeof p[0] === 'number') {
      for (let k = 0; k < Math.min(3, p.length); k += 1) {
        lo[k] = Math.min(lo[k], p[k]);
        hi[k] = Math.max(hi[k], p[k]);
      }
    } else if (Array.isArray(p)) p.forEach(visit);
  };
  for (const e of info.entities) visit(e.geometry.control_points);
  const d = Math.hypot(...hi.map((h, k) => (Number.isFinite(h - lo[k]) ? h - lo[k] : 0)));
  return d;
}

function index(info) {
  for (const e of info.entities) state.entities.set(e.id, e);
  for (const f of info.structure?.faces ?? []) {
    state.faces.set(f.id, f);
    if (f.surface) state.facesBySurface.set(f.surface, f);
  }
  for (const i of info.structure?.instances ?? []) state.instances.set(i.path, i);
}

/** The faces an assembly instance places, itself or through the instances under it. */
function instanceFaces(inst) {
  const s = state.info.structure;
  const solids = new Map(s.solids.map((x) => [x.id, x]));
  const shells = new Map(s.shells.map((x) => [x.id, x]));
  const faces = [];
  const ofShell = (id) => faces.push(...(shells.get(id)?.face_ids ?? []));
  for (const i of s.instances) {
    if (i.path !== inst.path && !i.path.startsWith(`${inst.path}/`)) continue;
    for (const id of i.places) {
      if (solids.has(id)) solids.get(id).shell_ids.forEach(ofShell);
      else if (shells.has(id)) ofShell(id);
      else if (state.faces.has(id)) faces.push(id);
    }
  }
  return faces;
}

// ---- Selection ---------------------------------------------------------------------------

/** Tree keys of assembly instances: `instance:` and the instance's path. */
const INSTANCE = 'instance:';

/**
 * Selects a face, entity or assembly instance from the view, the tree or a diagnostic:
 * highlights it (an instance: all its faces) everywhere.
 */
function select(key, from) {
  const inst = key?.startsWith(INSTANCE) ? state.instances.get(key.slice(INSTANCE.length)) : null;
  const face = key && !inst ? (state.faces.get(key) ?? state.facesBySurface.get(key)) : null;
  // The ids that name the same thing: a face and its surface entity; an instance's faces.
  const ids = new Set(inst ? [key, ...instanceFaces(inst)] : [key, face?.id, face?.surface].filter(Boolean));
  viewer.highlight([...ids]);
  for (const row of document.querySelectorAll('[data-select]')) {
    const on = ids.has(row.dataset.select);
    row.setAttribute('aria-pressed', on ? 'true' : 'false');
    if (on && from !== 'tree' && (!inst || row.dataset.select === key)) {
      row.closest('details')?.setAttribute('open', '');
      row.scrollIntoView({ block: 'nearest' });
    }
  }
  if (inst) showInstance(inst, ids);
  else showSelection(key, face);
}

function facts(id, rows) {
  const panel = $('selection');
  panel.dataset.id = id;
  panel.replaceChildren(el('h2', { id: 'selection-title' }, 'Selection'), el('dl', { class: 'facts' }, rows));
}

function showSelection(id, face = null) {
  const panel = $('selection');
  if (!id) {
    delete panel.dataset.id;
    panel.replaceChildren(el('h2', { id: 'selection-title' }, 'Selection'),
      el('p', { class: 'muted' }, 'Click a face or curve in the view, a row of the structure or a diagnostic.'));
    return;
  }
  const rows = [];
  const row = (k, v) => rows.push(el('dt', {}, k), el('dd', {}, v));
  if (face) {
    row('Face', face.id);
    if (face.shape) row('Shape in the file', String(face.shape));
    row('Loops', `${face.loops} (${face.edges} edge uses)`);
    row('Area', face.area != null ? `${num(face.area)} ${state.info.units.name}² (trimmed, from the structure)` : `not measured: ${face.area_error ?? 'unknown'}`);
  }
  const entityId = face?.surface ?? id;
  const e = state.entities.get(entityId);
  let measured = null;
  if (e) {
    row(face ? 'Surface entity' : 'Entity', e.id);
    row('Kind', `${e.rational ? 'rational ' : ''}B-spline ${e.kind} (${e.dimension}-D)`);
    row('Degree', e.degree.join(' × '));
    row('Poles', e.poles.join(' × '));
    row('Knots', knotsOf(e));
    row('Layout', e.layout.join(', '));
    row('Domain', e.domain.map(([a, b]) => `[${num(a)}, ${num(b)}]`).join(' × '));
    if (e.source?.line != null) row('Source', `line ${e.source.line}${e.source.entity ? `, ${e.source.entity}` : ''}`);
    // A curve's length, a free surface's area: exact from /v1/measure (a face's area is
    // the trimmed one above).
    if (e.kind === 'curve' || !face) {
      measured = el('dd', { id: 'measured' });
      rows.push(el('dt', {}, e.kind === 'curve' ? 'Length' : 'Area (whole surface)'), measured);
    }
  } else if (!face) {
    row('Id', id);
  }
  if (!viewer.has(id) && !(face && (viewer.has(face.id) || viewer.has(face.surface)))) {
    row('In the view', 'not drawn');
  }
  facts(face?.id ?? id, rows);
  if (measured) measure(e, measured);
}

/**
 * Fills `out` with the entity's length (curve) or area (surface) over its whole domain from
 * POST /v1/measure (adaptive Gauss-Kronrod, with its error estimate). While the request
 * runs, or when it fails, a curve shows its drawn polyline's length and says so.
 */
async function measure(e, out) {
  const seq = ++state.measureSeq;
  const units = state.info.units.name;
  const quantity = e.kind === 'curve' ? 'length' : 'area';
  const unit = quantity === 'length' ? units : `${units}²`;
  const polyline = quantity === 'length' ? viewer.polylineLength(e.id) : null;
  const rough = polyline != null ? `≈ ${num(polyline)} ${unit} (drawn polyline, within the chord tolerance)` : '';
  const show = (stateName, text) => {
    out.dataset.state = stateName;
    out.textContent = text;
  };
  show('measuring', `${rough ? `${rough}; ` : ''}measuring exactly…`);
  // Asked-for error: 1e-10 of the part's size (squared for an area), 1e-9 at the least.
  const size = Math.max(state.size, 1);
  const tolerance = Math.max(1e-9, quantity === 'length' ? size * 1e-10 : size * size * 1e-10);
  const fields = JSON.stringify({ entity: e.id, tolerance }).slice(1);
  const body = state.type === 'application/json'
    ? `{"geometry":${state.text},${fields}`
    : `{"file":${JSON.stringify(state.text)},${fields}`;
  try {
    withinLimit(body, 'measure');
    const r = await post('/v1/measure', body, { contentType: 'application/json' });
    const q = r.body.entities?.find((m) => m.id === e.id)?.[quantity];
    if (!q) throw new Error(`the reply has no ${quantity} for ${e.id}`);
    if (seq !== state.measureSeq) return;
    out.dataset.value = String(q.value);
    out.dataset.error = String(q.error_estimate);
    show('exact', `${num(q.value, 12)} ${unit} ± ${q.error_estimate.toExponential(1)} over the domain `
      + `(adaptive Gauss–Kronrod, ${q.pieces} pieces${q.converged ? '' : '; the asked-for error was not reached'})`);
  } catch (err) {
    if (seq !== state.measureSeq) return;
    show('failed', `${rough ? `${rough}; ` : ''}the exact measure failed: ${err.message}`);
  }
}

/** A placement's rotation as "θ° about (axis)" and its translation (rows [R | T]). */
function placementText(m) {
  const [[a, b, c, tx], [d, e, f, ty], [g, h, i, tz]] = m;
  const angle = Math.acos(Math.min(1, Math.max(-1, (a + e + i - 1) / 2)));
  const axis = [h - f, c - g, d - b];
  const n = Math.hypot(...axis);
  const deg = (angle * 180) / Math.PI;
  const det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
  let rot;
  if (Math.abs(det - 1) > 1e-6) rot = `not a rotation (determinant ${num(det, 4)})`;
  else if (deg < 1e-9) rot = 'none';
  else if (n < 1e-9) rot = `${num(deg, 6)}° (see the matrix)`;
  else rot = `${num(deg, 6)}° about (${axis.map((x) => num(Math.abs(x / n) < 1e-9 ? 0 : x / n, 6)).join(', ')})`;
  const rows = m.map((r) => `[${r.slice(0, 3).map((x) => num(x, 6)).join('  ')} | ${num(r[3], 6)}]`).join('\n');
  return `translation (${[tx, ty, tz].map((x) => num(x, 9)).join(', ')})\nrotation ${rot}\n${rows}`;
}

function showInstance(inst, ids) {
  const faces = [...ids].filter((id) => state.faces.has(id));
  const drawn = faces.filter((id) => viewer.has(id)).length;
  const rows = [];
  const row = (k, v, props = {}) => rows.push(el('dt', {}, k), el('dd', props, v));
  row('Instance', inst.path);
  row('Product', inst.product);
  row('Placed by', inst.id);
  row('Level', String(inst.depth));
  row('Faces', `${faces.length} (${drawn} drawn)`);
  row('Placement in its parent', placementText(inst.placement), { id: 'placement' });
  row('Placement in the root', placementText(inst.world), { id: 'placement-root' });
  facts(INSTANCE + inst.path, rows);
}

function knotsOf(e) {
  const g = e.geometry;
  const lists = Object.keys(g)
    .filter((k) => k.startsWith('knots'))
    .map((k) => `${k.replace('knots', '').replace('_', '') || ''}${k === 'knots' ? '' : ': '}[${g[k].map((x) => num(x)).join(', ')}]`);
  return lists.join('; ') || '—';
}

// ---- Structure tree ----------------------------------------------------------------------

function selectButton(id, label, extra = '') {
  return el('button', {
    type: 'button', class: 'row', 'aria-pressed': 'false', dataset: { select: id },
    onclick: () => select(id, 'tree'),
  }, el('span', { class: 'row-id' }, label), extra ? el('span', { class: 'muted' }, ` ${extra}`) : null);
}

function faceRow(f) {
  const area = f.area != null ? `area ${num(f.area, 5)}` : 'area not measured';
  return el('li', { class: 'face' }, selectButton(f.id, `Face ${f.id}`, `${f.shape ?? ''} ${area}`.trim()));
}

function renderTree(info) {
  const s = info.structure;
  const parts = [];
  const units = info.units.name;
  const curveRow = (e) => el('li', {}, selectButton(e.id, `Curve ${e.id}`, `degree ${e.degree[0]}, ${e.poles[0]} poles`));
  if (s) {
    const shellById = new Map(s.shells.map((sh) => [sh.id, sh]));
    const solidById = new Map(s.solids.map((so) => [so.id, so]));
    const placed = new Set();
    const shellNode = (sh) => {
      placed.add(sh.id);
      const faces = sh.face_ids.map((id) => state.faces.get(id)).filter(Boolean);
      faces.forEach((f) => placed.add(f.id));
      return el('li', {}, el('details', { open: true },
        el('summary', {}, `Shell ${sh.id}`, el('span', { class: 'muted' }, ` ${sh.closed ? 'closed' : 'open'}, ${sh.faces} faces`)),
        el('ul', {}, faces.map(faceRow))));
    };
    const solidNode = (so) => {
      placed.add(so.id);
      const vol = so.volume != null ? `, volume ${num(so.volume, 6)} ${units}³` : '';
      return el('li', { class: 'solid' }, el('details', { open: true },
        el('summary', {}, `Solid ${so.id}${so.name ? ` “${so.name}”` : ''}`, el('span', { class: 'muted' }, ` ${so.faces} faces${vol}`)),
        el('ul', {}, so.shell_ids.map((id) => shellById.get(id)).filter(Boolean).map(shellNode))));
    };
    // Assembly instances, nested by path (the list is depth first, so a parent comes before
    // its children), each with what it places itself, then the instances under it.
    const lists = new Map();
    for (const inst of s.instances ?? []) {
      const key = INSTANCE + inst.path;
      const cut = inst.path.lastIndexOf('/');
      const parent = cut > 0 ? lists.get(inst.path.slice(0, cut)) : null;
      const items = inst.places.map((id) => {
        if (solidById.has(id)) return solidNode(solidById.get(id));
        if (shellById.has(id)) return shellNode(shellById.get(id));
        if (state.faces.has(id)) {
          placed.add(id);
          return faceRow(state.faces.get(id));
        }
        return el('li', {}, selectButton(id, `Edge ${id}`));
      });
      const list = el('ul', {}, items);
      lists.set(inst.path, list);
      const faces = instanceFaces(inst).length;
      const node = el('li', { class: 'instance' }, el('details', { open: true },
        el('summary', {}, el('button', {
          type: 'button', class: 'row', 'aria-pressed': 'false', dataset: { select: key },
          onclick: (e) => {
            e.preventDefault(); // select, do not fold
            select(key, 'tree');
          },
        }, el('span', { class: 'row-id' }, inst.path.slice(cut + 1)),
        el('span', { class: 'muted' }, ` instance of ${inst.product}, ${faces} face${faces === 1 ? '' : 's'}`))),
        list));
      if (parent) parent.append(node);
      else parts.push(node);
    }
    if (s.assemblies > 0 && !(s.instances ?? []).length) parts.push(el('li', { class: 'muted' }, `${s.assemblies} assembl${s.assemblies === 1 ? 'y' : 'ies'}`));
    for (const so of s.solids) if (!placed.has(so.id)) parts.push(solidNode(so));
    for (const sh of s.shells) if (!placed.has(sh.id)) parts.push(shellNode(sh));
    const loose = s.faces.filter((f) => !placed.has(f.id));
    if (loose.length) {
      parts.push(el('li', {}, el('details', { open: true },
        el('summary', {}, `Faces in no shell (${loose.length})`), el('ul', {}, loose.map(faceRow)))));
    }
  } else {
    const surfaces = info.entities.filter((e) => e.kind === 'surface');
    if (surfaces.length) {
      parts.push(el('li', {}, el('details', { open: true }, el('summary', {}, `Surfaces (${surfaces.length})`),
        el('ul', {}, surfaces.map((e) => el('li', {}, selectButton(e.id, `Surface ${e.id}`, `degree ${e.degree.join('×')}`)))))));
    }
  }
  // In a part, free geometry (role "free": used by no face or edge) is listed apart from the
  // edge curves; a file without faces has only free geometry.
  const curves3 = info.entities.filter((e) => e.kind === 'curve' && e.dimension === 3);
  const free = curves3.filter((e) => e.role === 'free');
  const edges = curves3.filter((e) => e.role !== 'free');
  if (free.length) {
    parts.push(el('li', {}, el('details', { open: true, id: 'free-curves' }, el('summary', {}, `${s ? 'Free curves' : 'Curves'} (${free.length})`),
      el('ul', {}, free.map(curveRow)))));
  }
  const freeSurfaces = s ? info.entities.filter((e) => e.kind === 'surface' && e.role === 'free') : [];
  if (freeSurfaces.length) {
    parts.push(el('li', {}, el('details', { open: true }, el('summary', {}, `Free surfaces (${freeSurfaces.length})`),
      el('ul', {}, freeSurfaces.map((e) => el('li', {}, selectButton(e.id, `Surface ${e.id}`, `degree ${e.degree.join('×')}`)))))));
  }
  if (edges.length) {
    parts.push(el('li', {}, el('details', { open: false }, el('summary', {}, `Edge curves (${edges.length})`),
      el('ul', {}, edges.map(curveRow)))));
  }
  const instances = s?.instances?.length ?? 0;
  const summary = s
    ? `${instances ? `${instances} assembly instance(s), ` : ''}${s.solids.length} solid(s), ${s.shells.length} shell(s), ${s.faces.length} face(s), ${s.edges} edges, ${s.vertices} vertices; area ${num(s.area, 6)} ${units}²`
    : `${info.entities.length} entities, no faces (loose geometry)`;
  $('tree').replaceChildren(
    el('p', { id: 'tree-summary', dataset: { faces: String(s?.faces.length ?? 0), solids: String(s?.solids.length ?? 0), shells: String(s?.shells.length ?? 0), instances: String(instances) } }, summary),
    el('ul', { class: 'tree' }, parts),
  );
}

// ---- Diagnostics -------------------------------------------------------------------------

function renderDiagnostics(report, error) {
  const box = $('diagnostics');
  if (!report) {
    box.replaceChildren(el('p', { class: 'error' }, `Validation failed: ${error?.message ?? error}`));
    return;
  }
  const head = el('p', { id: 'diag-summary', class: report.valid ? 'ok' : 'error' },
    `${report.valid ? 'Valid' : 'Not valid'}: ${report.errors} error(s), ${report.warnings} warning(s), ${report.entities} entities read.`);
  const items = report.diagnostics.map((d) => {
    const where = locationText(d.location);
    const body = [
      el('span', { class: `sev ${d.severity}` }, d.severity),
      ' ', el('code', {}, d.code), ' ', d.message,
      where ? el('span', { class: 'where' }, ` — ${where}`) : null,
    ];
    const id = d.location?.entity;
    return el('li', { class: 'diag' }, id
      ? el('button', { type: 'button', class: 'row', 'aria-pressed': 'false', dataset: { select: id }, onclick: () => select(id, 'diagnostic') }, body)
      : el('div', { class: 'row' }, body));
  });
  box.replaceChildren(head, items.length ? el('ul', { class: 'diags' }, items) : el('p', { class: 'muted' }, 'No diagnostics.'));
}

// ---- View controls -----------------------------------------------------------------------

$('fit').addEventListener('click', () => viewer.fit());
$('show-edges').addEventListener('change', (e) => viewer.setLinesVisible(e.target.checked));

// ---- Convert -----------------------------------------------------------------------------

$('convert').addEventListener('submit', async (e) => {
  e.preventDefault();
  const file = state.file;
  if (!file || state.busy) return;
  const [to, variant] = $('target').value.split(':');
  const q = new URLSearchParams({ to });
  if (to === 'step') q.set('schema', variant);
  if (to === 'iges' && variant === '186') q.set('iges_brep', 'true');
  if ($('units').value) q.set('units', $('units').value);
  if ($('verify').checked) q.set('verify', 'true');
  const out = $('convert-result');
  out.replaceChildren();
  state.busy = true;
  $('convert-go').disabled = true;
  status(`Converting ${file.name}…`, { busy: true, progress: 0 });
  try {
    const r = await post(`/v1/convert?${q}`, file, {
      contentType: mediaType(file.name), accept: 'application/json',
      onUpload: (n) => status(`Uploading for conversion: ${bytes(n)} of ${bytes(file.size)}`, { busy: true, progress: n / file.size }),
    });
    const { report, file: text } = r.body;
    const base = file.name.replace(/\.[^.]*$/, '');
    const name = `${base}.${to === 'step' ? 'step' : 'igs'}`;
    const url = URL.createObjectURL(new Blob([text], { type: to === 'step' ? 'model/step' : 'model/iges' }));
    const link = el('a', { href: url, download: name, id: 'download' }, `Download ${name} (${bytes(text.length)})`);
    out.replaceChildren(link, renderReport(report));
    link.click();
    status(`Converted ${file.name} to ${name}.`);
  } catch (err) {
    out.replaceChildren(el('p', { class: 'error', id: 'convert-error' }, `Conversion failed: ${err.message}${err.location ? ` (${locationText(err.location)})` : ''}`));
    status(`Conversion failed: ${err.message}`);
  } finally {
    state.busy = false;
    $('convert-go').disabled = false;
  }
});

function renderReport(report) {
  const rows = [];
  const row = (k, v) => rows.push(el('dt', {}, k), el('dd', {}, v));
  row('Entities', `${report.entities_in} read, ${report.entities_out} written (${report.output_format}, ${report.units.name})`);
  const p = report.verify_part;
  if (p) {
    row('Verified', p.ok ? 'yes: the re-read output matches' : 'NO: the re-read output differs');
    row('Faces', `${p.faces_in} → ${p.faces_out}`);
    row('Solids', `${p.solids_in} → ${p.solids_out}`);
    if (p.measured) {
      row('Area', `${num(p.area_in)} → ${num(p.area_out)} (relative ${p.area_relative.toExponential(2)})`);
      row('Volume', `${num(p.volume_in)} → ${num(p.volume_out)} (relative ${p.volume_relative.toExponential(2)})`);
      row('Centroid', `moved ${p.centroid_relative.toExponential(2)} of the part's size`);
    } else {
      row('Area, volume', `not compared: ${p.unmeasured_faces} face(s) could not be measured`);
    }
  } else if (report.verify) {
    const worst = report.verify.reduce((a, d) => (d.relative > (a?.relative ?? -1) ? d : a), null);
    row('Verified', report.verify.every((d) => d.ok) ? `yes: ${report.verify.length} entities re-read` : 'NO');
    if (worst) row('Largest deviation', `${num(worst.max_deviation, 3)} ${report.units.name} (relative ${worst.relative.toExponential(2)}, ${worst.input_id})`);
  }
  const warn = report.diagnostics.filter((d) => d.severity !== 'info');
  row('Diagnostics', warn.length ? warn.map((d) => `${d.code}: ${d.message}`).join('\n') : 'none');
  return el('dl', { class: 'facts', id: 'verify-report' }, rows);
}

// For scripted checks (the browser tests): the ids in the view, the highlighted ones, the
// camera, and a face's or curve's screen point.
window.nurbsxPage = {
  view: () => state.view,
  highlighted: () => viewer.picked,
  camera: () => ({ position: viewer.camera.position.toArray(), target: viewer.controls.target.toArray() }),
  screenPointOf: (id, t) => viewer.screenPointOf(id, t),
};
