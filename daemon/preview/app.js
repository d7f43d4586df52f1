// obscura preview page: follows a stream of frames (GET /v1/streams/NAME/events),
// shows the newest as AO, composite or split view (colour | composite; a deep
// frame's AO is its front layer's), sets the controls (generated from
// GET /v1/params) to the parameters the frame ran with (GET /v1/streams/NAME),
// re-runs it with those changed here, and runs a dropped EXR once.  Plain
// JavaScript, no build step.
'use strict';

const $ = (id) => document.getElementById(id);
const state = {
  stream: '',      // the followed stream
  frame: null,     // the newest frame's event data
  view: 'composite',
  exposure: 0,
  defs: [],        // the parameter table
  controls: {},    // name -> {def, control, number}: the inputs of a parameter
  asRun: {},       // name -> value the shown frame ran with (its query, else its camera)
  params: {},      // name -> value, only those changed here from asRun (or the default)
  token: sessionStorage.getItem('obscura-token') || '',
  seq: 0,          // guards against answers arriving out of order
  urls: [],        // object URLs shown now
  events: null,    // AbortController of the event stream
};

// ---- the API ---------------------------------------------------------------

async function api(path, opts = {}) {
  const headers = Object.assign({}, opts.headers || {});
  if (state.token) headers.Authorization = 'Bearer ' + state.token;
  const resp = await fetch(path, Object.assign({}, opts, { headers }));
  if (resp.status === 401) {
    $('token-box').hidden = false;
    throw new Error('the daemon needs a token: type it above');
  }
  if (!resp.ok) {
    let msg = resp.status + ' ' + resp.statusText;
    try { msg = (await resp.json()).error.message; } catch (e) { /* not our JSON */ }
    throw new Error(msg);
  }
  return resp;
}

function status(text, error) {
  $('status').textContent = text || '';
  $('status').classList.toggle('error', !!error);
}

// ---- parameters ------------------------------------------------------------

// A float slider spans its range linearly, or in log steps when the range
// covers more than three decades (radius: 0.0001 .. 10000).
function scaleOf(def) {
  if (def.type === 'float' && def.min > 0 && def.max / def.min > 1000) {
    const a = Math.log(def.min), b = Math.log(def.max);
    return { to: (v) => 1000 * (Math.log(v) - a) / (b - a), from: (s) => Math.exp(a + (b - a) * s / 1000) };
  }
  return { to: (v) => 1000 * (v - def.min) / (def.max - def.min), from: (s) => def.min + (def.max - def.min) * s / 1000 };
}

function tidy(def, v) {
  if (def.type === 'int') return Math.round(v);
  return Number(Number(v).toPrecision(4));
}

function buildParams(defs) {
  const form = $('params');
  form.textContent = '';
  state.controls = {};
  for (const def of defs) {
    if (def.type === 'mat4') continue;
    const row = document.createElement('div');
    row.className = 'param';
    row.id = 'param-' + def.name;
    row.title = def.doc || '';
    const name = document.createElement('label');
    name.className = 'name';
    name.textContent = def.name;
    row.appendChild(name);
    let control, number = null;
    if (def.type === 'string') {
      // an object-mask selector: free text, suggesting the frame's
      // Cryptomatte names and ID channels (fillObjects)
      control = document.createElement('input');
      control.type = 'text';
      control.setAttribute('list', 'objects');
      control.placeholder = 'names, id:CHANNEL=N or matte:CHANNEL';
      if (def.max) control.maxLength = def.max;
      control.style.gridColumn = '1 / 3';
      control.addEventListener('change', () => setParam(def, control.value));
    } else if (def.choices) {
      control = document.createElement('select');
      for (const c of def.choices) control.add(new Option(c, c));
      control.value = String(def.default);
      control.style.gridColumn = '1 / 3';
      control.addEventListener('change', () => setParam(def, control.value));
    } else {
      const sc = scaleOf(def);
      control = document.createElement('input');
      control.type = 'range';
      control.min = 0;
      control.max = 1000;
      control.step = def.type === 'int' ? 1000 / Math.max(1, def.max - def.min) : 1;
      control.value = sc.to(def.default);
      number = document.createElement('input');
      number.type = 'number';
      number.min = def.min;
      number.max = def.max;
      number.step = def.type === 'int' ? 1 : 'any';
      number.value = def.default;
      control.addEventListener('input', () => {
        const v = tidy(def, sc.from(Number(control.value)));
        number.value = v;
        setParam(def, v);
      });
      number.addEventListener('change', () => {
        const v = Math.min(def.max, Math.max(def.min, Number(number.value)));
        control.value = sc.to(v);
        setParam(def, tidy(def, v));
      });
    }
    control.name = def.name;
    control.setAttribute('aria-label', def.name);
    row.appendChild(control);
    if (number) row.appendChild(number);
    const reset = document.createElement('button');
    reset.type = 'button';
    reset.textContent = '↺';
    reset.addEventListener('click', () => {
      delete state.params[def.name];
      showControl(def.name);
      scheduleShow();
    });
    row.appendChild(reset);
    form.appendChild(row);
    state.controls[def.name] = { def, control, number, reset };
    showControl(def.name);
  }
}

// The value a parameter ran with on the shown frame: its query's, else
// (fov_y, near, far) its camera's, else the table's default.
function asRunOf(def) {
  return def.name in state.asRun ? state.asRun[def.name] : def.default;
}

// A control shows the value changed here, else the one the frame ran with.
function showControl(name) {
  const c = state.controls[name];
  if (!c) return;
  const v = name in state.params ? state.params[name] : asRunOf(c.def);
  if (c.number) {
    c.number.value = v;
    c.control.value = scaleOf(c.def).to(Number(v));
  } else {
    c.control.value = String(v);
  }
  c.reset.title = 'as the frame ran: ' + asRunOf(c.def) + ' (default: ' + c.def.default + ')';
  $('param-' + name).classList.toggle('changed', name in state.params);
}

// The frame's own parameters, from its entry in GET /v1/streams/NAME.
// Values changed here stay changed unless the new frame ran with them.
async function loadAsRun(f) {
  let info = null;
  try {
    const st = await (await api('/v1/streams/' + encodeURIComponent(f.stream))).json();
    info = (st.frame_info || []).find((i) => i.frame === f.frame) || null;
  } catch (e) {
    status(e.message, true);
  }
  if (state.frame !== f) return false; // a newer frame came meanwhile
  fillObjects(info);
  const given = (info && info.params) || {}, cam = (info && info.camera) || {};
  state.asRun = {};
  for (const def of state.defs) {
    if (def.type === 'mat4') continue;
    const v = def.name in given ? given[def.name] : cam[def.name];
    if (v === undefined) continue;
    const num = Number(v);
    state.asRun[def.name] = def.choices || def.type === 'string' || Number.isNaN(num) ? String(v) : tidy(def, num);
  }
  for (const name of Object.keys(state.params)) {
    const c = state.controls[name];
    if (c && String(state.params[name]) === String(asRunOf(c.def))) delete state.params[name];
  }
  for (const name of Object.keys(state.controls)) showControl(name);
  $('info-kind').textContent = f.deep ? 'deep (AO: the front layer\'s)' : 'flat';
  return true;
}

let rerunTimer = 0;
function scheduleShow() {
  clearTimeout(rerunTimer);
  rerunTimer = setTimeout(show, 150);
}

// A selector's escapes: ',', '*', '?', '\\' and a leading '@' or '!' are literal
// with a backslash before them (README: Object masks).
function escapeName(n) {
  return n.replace(/[\\,*?]/g, (c) => '\\' + c).replace(/^[@!]/, (c) => '\\' + c);
}

// The suggestions of the selector controls: every Cryptomatte name of the
// shown frame (each layer also as @LAYER:*), and id:CHANNEL= per ID channel.
function fillObjects(info) {
  const list = $('objects');
  list.textContent = '';
  for (const l of (info && info.cryptomatte) || []) {
    list.appendChild(new Option('@' + l.name + ':*', '@' + l.name + ':*'));
    for (const n of l.names) list.appendChild(new Option(l.name + ': ' + n, escapeName(n)));
  }
  for (const c of (info && info.id_channels) || []) list.appendChild(new Option('ID channel', 'id:' + c + '='));
}

// A value set here: a change when it differs from the frame's (a re-run
// with it; the frame's other parameters are the daemon's to apply).
function setParam(def, value) {
  if (String(value) === String(asRunOf(def))) delete state.params[def.name];
  else state.params[def.name] = value;
  $('param-' + def.name).classList.toggle('changed', def.name in state.params);
  scheduleShow();
}

function query(obj) {
  return Object.entries(obj).map(([k, v]) => k + '=' + encodeURIComponent(v)).join('&');
}

function paramQuery() {
  return query(state.params);
}

// A dropped EXR is a new frame: it runs with what the controls show
// (where that is not the default), not only with what was changed here.
function shownQuery() {
  const shown = {};
  for (const [name, c] of Object.entries(state.controls)) {
    const v = name in state.params ? state.params[name] : asRunOf(c.def);
    if (String(v) !== String(c.def.default)) shown[name] = v;
  }
  return query(shown);
}

// ---- the image -------------------------------------------------------------

// The AO image of the frame: a deep frame's front layer's (output=ao_front).
function aoOutput() {
  return state.frame && state.frame.deep ? 'ao_front' : 'ao';
}

function frameUrl(output, format) {
  const f = state.frame;
  let q = 'output=' + output + '&format=' + format;
  if (format === 'png' && output !== 'ao' && output !== 'ao_front') q += '&exposure=' + state.exposure;
  if (format === 'exr') q += '&float=1';
  const pq = paramQuery();
  if (pq && output !== 'color') q += '&' + pq;
  return '/v1/streams/' + encodeURIComponent(f.stream) + '/frames/' + f.frame + '?' + q;
}

function timingsOf(resp) {
  const t = {};
  for (const part of (resp.headers.get('Server-Timing') || '').split(',')) {
    const m = /^\s*(\w+);dur=([\d.]+)/.exec(part);
    if (m) t[m[1]] = Number(m[2]);
  }
  return t;
}

function ms(v) { return v === undefined ? '-' : v.toFixed(1) + ' ms'; }

function showInfo(f, t) {
  $('info-frame').textContent = f ? f.frame + ' (' + f.stream + ')' : '-';
  $('info-size').textContent = f ? f.width + ' × ' + f.height : '-';
  $('info-kind').textContent = f ? (f.deep ? 'deep (AO: the front layer\'s)' : 'flat') : '-';
  $('info-queue').textContent = ms(t.queue);
  $('info-decode').textContent = ms(t.decode);
  $('info-gl').textContent = ms(t.gl);
  $('info-encode').textContent = ms(t.encode);
}

// Fetches the images of the current view for the newest frame.
async function show() {
  const f = state.frame;
  if (!f) return;
  const seq = ++state.seq;
  const split = state.view === 'split';
  const wanted = state.view === 'ao' ? [aoOutput()] : split ? [f.color ? 'color' : aoOutput(), 'composite'] : ['composite'];
  try {
    const resps = await Promise.all(wanted.map((o) => api(frameUrl(o, 'png'))));
    const blobs = await Promise.all(resps.map((r) => r.blob()));
    if (seq !== state.seq) return; // a newer request is under way
    for (const u of state.urls) URL.revokeObjectURL(u);
    state.urls = blobs.map((b) => URL.createObjectURL(b));
    $('img-base').src = state.urls[0];
    $('img-top').hidden = !split;
    $('divider').hidden = !split;
    if (split) $('img-top').src = state.urls[1];
    $('stage').hidden = false;
    $('empty').hidden = true;
    fit();
    const rerun = timingsOf(resps[resps.length - 1]);
    const t = Object.keys(state.params).length ? rerun : Object.assign({}, f.timings, { encode: rerun.encode });
    showInfo(f, t);
    $('stage').dataset.frame = f.frame;
    status(Object.keys(state.params).length ? 're-run with ' + decodeURIComponent(paramQuery()) : '');
    updateDownloads();
  } catch (e) {
    if (seq === state.seq) status(e.message, true);
  }
}

// The frame as large as the viewer allows (small frames are scaled up).
function fit() {
  const f = state.frame;
  if (!f) return;
  const v = $('viewer').getBoundingClientRect();
  const k = Math.min((v.width - 32) / f.width, (v.height - 32) / f.height);
  $('img-base').style.width = Math.max(1, Math.floor(f.width * k)) + 'px';
}
window.addEventListener('resize', fit);

function updateDownloads() {
  if (!state.frame) return;
  const main = state.view === 'ao' ? aoOutput() : 'composite';
  $('dl-exr').href = frameUrl('both', 'exr');
  $('dl-exr').download = state.frame.stream + '.' + state.frame.frame + '.exr';
  $('dl-png').href = frameUrl(main, 'png');
  $('dl-png').download = state.frame.stream + '.' + state.frame.frame + '.' + main + '.png';
}

// With a token the links cannot carry it: fetch, then save the blob.
for (const id of ['dl-exr', 'dl-png']) {
  $(id).addEventListener('click', async (ev) => {
    if (!state.token) return;
    ev.preventDefault();
    try {
      const blob = await (await api($(id).getAttribute('href'))).blob();
      const a = document.createElement('a');
      a.href = URL.createObjectURL(blob);
      a.download = $(id).download;
      a.click();
      setTimeout(() => URL.revokeObjectURL(a.href), 10000);
    } catch (e) { status(e.message, true); }
  });
}

// The split view's divider: the composite covers the colour right of it.
function setSplit(frac) {
  frac = Math.min(1, Math.max(0, frac));
  $('img-top').style.clipPath = 'inset(0 0 0 ' + (frac * 100) + '%)';
  $('divider').style.left = (frac * 100) + '%';
}
$('divider').addEventListener('pointerdown', (ev) => {
  const stage = $('stage');
  $('divider').setPointerCapture(ev.pointerId);
  const move = (e) => {
    const r = stage.getBoundingClientRect();
    setSplit((e.clientX - r.left) / r.width);
  };
  const up = () => {
    $('divider').removeEventListener('pointermove', move);
    $('divider').removeEventListener('pointerup', up);
  };
  $('divider').addEventListener('pointermove', move);
  $('divider').addEventListener('pointerup', up);
});
setSplit(0.5);

// ---- streams and their events ------------------------------------------------

async function loadStreams() {
  let list;
  try {
    list = await (await api('/v1/streams')).json();
  } catch (e) {
    status(e.message, true);
    return;
  }
  const sel = $('stream');
  const names = list.streams.map((s) => s.name);
  const have = Array.from(sel.options).map((o) => o.value).filter((v) => v);
  if (names.join() !== have.join()) {
    sel.textContent = '';
    if (!names.length) sel.add(new Option('(none yet)', ''));
    for (const n of names) sel.add(new Option(n, n));
  }
  if (!state.stream && names.length) {
    const newest = list.streams.slice().sort((a, b) => b.updated - a.updated)[0];
    follow(newest.name);
  } else {
    sel.value = state.stream;
  }
}

// Server-Sent Events read with fetch (EventSource cannot send a token).
async function follow(name) {
  if (state.events) state.events.abort();
  state.stream = name;
  state.frame = null;
  $('stream').value = name;
  if (!name) return;
  const ctl = new AbortController();
  state.events = ctl;
  while (!ctl.signal.aborted) {
    try {
      const resp = await api('/v1/streams/' + encodeURIComponent(name) + '/events', { signal: ctl.signal });
      const reader = resp.body.getReader();
      const dec = new TextDecoder();
      let buf = '';
      for (;;) {
        const { value, done } = await reader.read();
        if (done) break;
        buf += dec.decode(value, { stream: true });
        let cut;
        while ((cut = buf.indexOf('\n\n')) >= 0) {
          onEvent(buf.slice(0, cut));
          buf = buf.slice(cut + 2);
        }
      }
    } catch (e) {
      if (ctl.signal.aborted) return;
      status('event stream: ' + e.message, true);
    }
    await new Promise((r) => setTimeout(r, 2000)); // reconnect
  }
}

function onEvent(text) {
  let type = 'message', data = '';
  for (const line of text.split('\n')) {
    if (line.startsWith('event:')) type = line.slice(6).trim();
    else if (line.startsWith('data:')) data += line.slice(5).trim();
  }
  if (type === 'frame') {
    const f = JSON.parse(data);
    state.frame = f;
    loadAsRun(f).then((current) => { if (current) show(); });
  } else if (type === 'end') {
    status('stream ended: ' + JSON.parse(data).reason);
  }
}

// ---- a dropped EXR -----------------------------------------------------------

async function runDropped(file) {
  status('running ' + file.name + ' …');
  const name = 'drop';
  const q = shownQuery();
  try {
    await api('/v1/streams/' + name + '/frames?output=composite&format=png' + (q ? '&' + q : ''), {
      method: 'POST', headers: { 'Content-Type': 'image/x-exr' }, body: file,
    });
    status(file.name + ' done');
    await loadStreams();
    if (state.stream !== name) follow(name);
  } catch (e) {
    status(file.name + ': ' + e.message, true);
  }
}

let dragDepth = 0;
document.addEventListener('dragenter', (ev) => { ev.preventDefault(); dragDepth++; $('drop-overlay').hidden = false; });
document.addEventListener('dragleave', () => { if (--dragDepth <= 0) { dragDepth = 0; $('drop-overlay').hidden = true; } });
document.addEventListener('dragover', (ev) => ev.preventDefault());
document.addEventListener('drop', (ev) => {
  ev.preventDefault();
  dragDepth = 0;
  $('drop-overlay').hidden = true;
  const file = ev.dataTransfer && ev.dataTransfer.files[0];
  if (file) runDropped(file);
});

// ---- controls ---------------------------------------------------------------

$('stream').addEventListener('change', () => follow($('stream').value));
for (const r of document.querySelectorAll('input[name=view]')) {
  r.addEventListener('change', () => { state.view = r.value; show(); });
}
$('exposure').addEventListener('input', () => {
  state.exposure = Number($('exposure').value);
  $('exposure-value').textContent = state.exposure + ' EV';
  clearTimeout(rerunTimer);
  rerunTimer = setTimeout(show, 100);
});
$('token').value = state.token;
$('token').addEventListener('change', () => {
  state.token = $('token').value;
  sessionStorage.setItem('obscura-token', state.token);
  start();
});
$('reset-all').addEventListener('click', () => {
  state.params = {};
  for (const name of Object.keys(state.controls)) showControl(name);
  show();
});

async function start() {
  try {
    state.defs = (await (await api('/v1/params')).json()).params;
    buildParams(state.defs);
  } catch (e) {
    status(e.message, true);
    return;
  }
  await loadStreams();
}
start();
setInterval(loadStreams, 3000);
