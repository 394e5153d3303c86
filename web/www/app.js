// The scanner's page: rig status, start/stop/resume, live progress (Server-Sent Events), each
// view's thumbnails as it is taken, the model in a 3D viewer, downloads, the past scans.
import { Viewer } from './viewer.js';
import { setupCalibration } from './calibration.js';

const $ = (id) => document.getElementById(id);
const api = (path) => 'api/' + path;
const reasons = [['valid', '#3fa34d'], ['shadow', '#2b2b2b'], ['dark', '#2f5fb3'],
  ['low contrast', '#e3a21a'], ['saturated', '#d7263d'], ['inconsistent', '#9b4dca']];

let viewer = null;
let shown = null;       // the scan whose views and model the page shows
let thumbsShown = 0;
let events = null;      // the EventSource following a running scan

let calibration = null; // the calibration panel (calibration.js)
let session = null; // {key, header}: what a request that uses the rig carries (docs/api.md)

// The session key, fetched once: only a page of this server can read it.
async function sessionHeaders() {
  if (!session) {
    const res = await fetch(api('session'));
    if (res.status === 401) showLogin();
    if (!res.ok) throw new Error((await res.json().catch(() => ({}))).error || res.statusText);
    session = await res.json();
  }
  return { [session.header]: session.key };
}

async function call(method, path, body) {
  const init = { method, headers: method === 'POST' ? await sessionHeaders() : {} };
  if (body !== undefined) {
    init.headers['Content-Type'] = 'application/json';
    init.body = JSON.stringify(body);
  }
  const res = await fetch(api(path), init);
  const data = await res.json().catch(() => ({}));
  if (res.status === 401) showLogin();
  if (!res.ok) throw new Error(data.error || res.statusText);
  return data;
}

function showLogin() {
  $('main').hidden = true;
  $('login').hidden = false;
}

$('login').addEventListener('submit', async (e) => {
  e.preventDefault();
  try {
    await call('POST', 'login', { token: $('token').value });
    $('login').hidden = true;
    start();
  } catch (err) {
    $('login-error').textContent = err.message;
  }
});

function stageText(s) {
  const n = s.views_total, k = s.stage_views_done ?? s.views_done;
  switch (s.stage) {
    case 'starting': case 'scan_start': case 'homing': return 'starting: homing the turntable';
    case 'place_object': return 'waiting for the object to be laid for the second pass';
    case 'moving': case 'capturing': case 'saving': case 'saved':
      return `taking view ${Math.min(s.views_done + 1, n)} of ${n}`;
    case 'decoded': case 'process_start': return `decoding view ${k} of ${n}`;
    case 'registration': return 'registering the views';
    case 'fused': return `fusing view ${k} of ${n}`;
    case 'reflectance': return 'fitting the reflectance';
    case 'meshing': case 'mesh': case 'cost': return 'making the mesh';
    default: return s.stage || '';
  }
}

function showProgress(s) {
  const running = s.state === 'running';
  $('bar').max = s.views_total || 1;
  $('bar').value = s.views_done;
  let text = `Scan ${s.id}: ${s.views_done} of ${s.views_total} views`;
  if (running) {
    text += ` · ${stageText(s)}`;
    if (s.left_s >= 0 && s.stage !== 'place_object') text += ` · about ${Math.ceil(s.left_s)} s left`;
  } else {
    text += ` · ${s.state}`;
  }
  $('progress').textContent = text;
  $('error').textContent = s.error || '';
  showWarnings(s.warnings || [], s.warning_count || 0);
  $('stop').disabled = !running;
  $('start').disabled = running;
  $('resume').hidden = s.state !== 'stopped' && s.state !== 'failed';
  $('resume').dataset.id = s.id;
  // the scanner's question (two passes): what to do, and Continue once it is done
  const asking = running && s.stage === 'place_object';
  $('place').hidden = !asking;
  if (asking) {
    $('place-text').textContent = s.detail;
    $('continue').dataset.id = s.id;
    $('continue').disabled = false;
    if (!placeLive) placeLive = setInterval(() => showPlaceLive(s.id), 1000);
  } else if (placeLive) {
    clearInterval(placeLive);
    placeLive = null;
    $('place-live').hidden = true;
  }
}

// The scanner's warnings (an object the volume or the image cut, a weak calibration): a model
// that is not the whole object must not pass for it. Text only, never markup.
function showWarnings(warnings, count) {
  const list = $('warnings');
  list.replaceChildren(...warnings.map((w) => {
    const li = document.createElement('li');
    li.textContent = w;
    return li;
  }));
  if (count > warnings.length) {
    const li = document.createElement('li');
    li.textContent = `and ${count - warnings.length} more (the server's log has them)`;
    list.append(li);
  }
  list.hidden = count === 0;
}

// While the scan waits for the object to be laid, what the camera sees (the scanner writes it
// into the scan's folder about once a second, and removes it once answered).
let placeLive = null;
function showPlaceLive(id) {
  const img = $('place-live');
  img.onload = () => { img.hidden = false; };
  img.onerror = () => { img.hidden = true; };
  img.src = api(`scans/${id}/files/live.png?t=${Date.now()}`);
}

async function answerPlaced() {
  $('continue').disabled = true; // one answer: the server takes no second one either
  try {
    await call('POST', `scans/${$('continue').dataset.id}/continue`, {});
  } catch (err) {
    $('error').textContent = err.message;
    $('continue').disabled = false;
  }
}

function addThumbs(id, upTo) {
  $('thumbs-title').hidden = false;
  if (upTo > thumbsShown) refresh(); // the list of scans shows the new count
  for (; thumbsShown < upTo; thumbsShown++) {
    const fig = document.createElement('figure');
    const v = thumbsShown;
    for (const kind of ['colour', 'reasons']) {
      const img = document.createElement('img');
      img.alt = `view ${v} ${kind}`;
      img.src = api(`scans/${id}/thumbs/${v}/${kind}.png`);
      fig.append(img);
    }
    const cap = document.createElement('figcaption');
    cap.textContent = `view ${v}`;
    fig.append(cap);
    $('thumbs').append(fig);
  }
}

function showDownloads(s) {
  const box = $('downloads');
  box.textContent = '';
  if (s.state === 'running') return;
  const base = api(`scans/${s.id}/files/`);
  const link = (href, text, download) => {
    const a = document.createElement('a');
    a.href = href;
    a.textContent = text;
    if (download) a.download = '';
    else a.target = '_blank';
    box.append(a);
  };
  if (s.state === 'finished')
    for (const f of ['mesh.ply', 'mesh.obj', 'mesh.mtl', 'texture.png', 'mesh.stl', 'mesh.glb'])
      if ((f !== 'mesh.glb' || s.glb) && ((f !== 'mesh.mtl' && f !== 'texture.png') || s.texture))
        link(`${base}${f}?download=1`, f, true);
  link(api(`scans/${s.id}/archive.tar`), 'whole scan (.tar)', true);
  if (s.report) link(`${base}report.html`, 'report', false);
}

// Show scan @p s: its views, its model, its downloads.
async function open(s) {
  if (shown !== s.id) {
    shown = s.id;
    thumbsShown = 0;
    $('thumbs').textContent = '';
    viewer.clear();
    $('model-name').textContent = s.id;
  }
  addThumbs(s.id, s.views_done);
  showProgress(s);
  showDownloads(s);
  if (s.state === 'finished' && viewer.canvas.dataset.loaded !== s.id) {
    $('viewer-note').textContent = 'loading the model…';
    try {
      await viewer.load(api(`scans/${s.id}/files/`), s.glb, s.id);
      $('viewer-note').textContent = 'Drag to turn, wheel to zoom.';
    } catch (err) {
      $('viewer-note').textContent = `the model cannot be shown: ${err.message}`;
    }
  }
}

function follow(id) {
  if (events) events.close();
  events = new EventSource(api(`scans/${id}/events`));
  events.onmessage = (e) => {
    const s = JSON.parse(e.data);
    open(s);
    if (s.state !== 'running') {
      events.close();
      events = null;
      refresh();
    }
  };
}

async function startScan(resumeId) {
  $('error').textContent = '';
  $('live').checked = false; // the scan needs the camera: the picture being taken ends first
  await inflight;
  try {
    // a resume takes views as the scan did: the server picks the profile that does
    const r = resumeId ? await call('POST', `scans/${resumeId}/resume`, {})
      : await call('POST', 'scans', { profile: $('profile').value });
    $('start').disabled = true;
    follow(r.id);
    refresh();
  } catch (err) {
    $('error').textContent = err.message;
  }
}

$('start').addEventListener('click', () => startScan(null));
$('resume').addEventListener('click', () => startScan($('resume').dataset.id));
$('continue').addEventListener('click', answerPlaced);
$('stop').addEventListener('click', async () => {
  try { await call('POST', `scans/${shown}/stop`, {}); } catch (err) { $('error').textContent = err.message; }
});
$('colour').addEventListener('change', () => viewer.setColour($('colour').checked));

$('selftest-btn').addEventListener('click', async () => {
  const pre = $('selftest');
  pre.hidden = false;
  pre.textContent = 'trying each device…';
  try {
    const r = await call('POST', 'selftest');
    pre.textContent = r.table + (r.ok ? '\nevery device answered' : '\nsome device is missing');
  } catch (err) {
    pre.textContent = err.message;
  }
});

let inflight = Promise.resolve(); // the picture being taken: a scan waits for it

// One picture from the camera, lit by the projector's white. @retval whether it came
function snapshot() {
  const p = takeSnapshot();
  inflight = p.catch(() => false);
  return p;
}

async function takeSnapshot() {
  const img = $('snapshot');
  const res = await fetch(api('snapshot.png'), { method: 'POST', headers: await sessionHeaders() });
  if (!res.ok) {
    $('selftest').hidden = false;
    $('selftest').textContent = (await res.json().catch(() => ({}))).error || res.statusText;
    return false;
  }
  if (img.src) URL.revokeObjectURL(img.src);
  img.src = URL.createObjectURL(await res.blob());
  img.hidden = false;
  return true;
}

$('snapshot-btn').addEventListener('click', snapshot);

// Live: one picture after another while the box is ticked and the rig is free (a scan takes
// the camera: the server answers 409 and the live view stops).
$('live').addEventListener('change', async () => {
  while ($('live').checked) {
    if (!(await snapshot())) {
      $('live').checked = false;
      break;
    }
    await new Promise((r) => setTimeout(r, 500));
  }
});

// The rig's state and the list of scans.
async function refresh() {
  const st = await call('GET', 'status');
  const badge = $('rig-state');
  badge.textContent = st.scanning ? `scanning ${st.current}` : st.calibrating ? 'calibrating' : 'ready';
  badge.className = 'badge ' + (st.scanning || st.calibrating ? 'busy' : 'idle');
  $('lights').textContent = st.lights_and_projector;
  if (st.disk_free_bytes !== undefined) {
    const gb = (n) => (n / 1e9).toFixed(1);
    $('disk').textContent = `${gb(st.disk_free_bytes)} GB free of ${gb(st.disk_total_bytes)} GB`;
  }
  const list = await call('GET', 'scans');
  const body = $('past').tBodies[0];
  body.textContent = '';
  for (const s of list.scans) {
    const tr = body.insertRow();
    tr.insertCell().textContent = s.id;
    tr.insertCell().textContent = s.label || '';
    tr.insertCell().textContent = s.state;
    tr.insertCell().textContent = `${s.views_done} / ${s.views_total}`;
    const cell = tr.insertCell();
    cell.append(button('Open', () => (s.state === 'running' ? follow(s.id) : open(s))));
    cell.append(button('Label', () => labelScan(s)));
    const del = button('Delete', () => deleteScan(s));
    del.disabled = s.state === 'running'; // the server refuses it too (409)
    cell.append(del);
  }
  return st;
}

function button(text, onClick) {
  const b = document.createElement('button');
  b.textContent = text;
  b.addEventListener('click', onClick);
  return b;
}

// A label a person gives a scan (one line, at most 100 bytes: the server checks it again).
async function labelScan(s) {
  const label = window.prompt(`Label for scan ${s.id}`, s.label || '');
  if (label === null) return;
  try {
    await call('POST', `scans/${s.id}/label`, { label });
  } catch (err) {
    $('error').textContent = err.message;
  }
  refresh();
}

// Delete a scan and all its files, once the person has said yes.
async function deleteScan(s) {
  const name = s.label ? `${s.id} (${s.label})` : s.id;
  if (!window.confirm(`Delete scan ${name} and all its files? This cannot be undone.`)) return;
  try {
    await call('POST', `scans/${s.id}/delete`, {});
  } catch (err) {
    $('error').textContent = err.message;
  }
  refresh();
}

// ---- settings: a profile's main keys, checked by the scanner's own key table ----
async function loadSettings() {
  const name = $('settings-profile').value;
  const p = await call('GET', `profiles/${encodeURIComponent(name)}`);
  for (const [k, v] of Object.entries(p.values)) {
    const field = $('settings').elements[k];
    if (field) field.value = v;
  }
  clearFieldErrors();
}

function clearFieldErrors() {
  for (const e of document.querySelectorAll('#settings .field-error')) e.remove();
  $('settings-msg').textContent = '';
}

async function saveSettings(asNew) {
  clearFieldErrors();
  const values = {};
  for (const f of $('settings').elements) if (f.name) values[f.name] = f.value;
  const body = { values };
  if (asNew) body.save_as = $('settings-as').value;
  try {
    await call('POST', `profiles/${encodeURIComponent($('settings-profile').value)}`, body);
    $('settings-msg').textContent = asNew ? `saved as profile ${body.save_as}`
      : 'saved (the old file is kept beside it)';
    if (asNew) await listProfiles(body.save_as);
  } catch (err) {
    // the scanner's message names "[section] key": shown beside that field
    const m = /\[(\w+)\] (\w+)/.exec(err.message);
    const field = m && $('settings').elements[`${m[1]}.${m[2]}`];
    if (!field) { $('settings-msg').textContent = err.message; return; }
    const note = document.createElement('span');
    note.className = 'field-error';
    note.textContent = err.message;
    field.after(note);
  }
}

async function listProfiles(pick) {
  const st = await call('GET', 'status');
  for (const sel of [$('profile'), $('settings-profile'), $('calib-profile')]) {
    const was = sel.value;
    sel.textContent = '';
    for (const p of st.profiles) sel.add(new Option(p, p));
    sel.value = pick || was || st.profiles[0];
  }
  await loadSettings();
}

// A picture at the exposure in the field (not saved yet), and how much of it is saturated or
// dark: the numbers a person judges an exposure by.
async function pictureAtExposure() {
  const note = $('settings-picture-note');
  const exposure = Number($('settings').elements['camera.exposure_us'].value);
  note.textContent = 'taking a picture…';
  await inflight;
  const res = await fetch(api('snapshot.png'), {
    method: 'POST',
    headers: { ...(await sessionHeaders()), 'Content-Type': 'application/json' },
    body: JSON.stringify({ profile: $('settings-profile').value, exposure_us: exposure }),
  });
  if (!res.ok) {
    note.textContent = (await res.json().catch(() => ({}))).error || res.statusText;
    return;
  }
  const img = $('settings-picture');
  if (img.src) URL.revokeObjectURL(img.src);
  img.src = URL.createObjectURL(await res.blob());
  await img.decode();
  img.hidden = false;
  const c = document.createElement('canvas');
  c.width = img.naturalWidth;
  c.height = img.naturalHeight;
  const g = c.getContext('2d');
  g.drawImage(img, 0, 0);
  const px = g.getImageData(0, 0, c.width, c.height).data;
  let sum = 0, saturated = 0, dark = 0;
  for (let i = 0; i < px.length; i += 4) {
    const hi = Math.max(px[i], px[i + 1], px[i + 2]);
    sum += (px[i] + px[i + 1] + px[i + 2]) / 3;
    saturated += hi >= 250;
    dark += hi < 10;
  }
  const n = px.length / 4;
  note.dataset.mean = (sum / n).toFixed(1);
  note.textContent = `at ${exposure} µs: mean level ${(sum / n).toFixed(0)} of 255, ` +
    `${(100 * saturated / n).toFixed(1)}% saturated, ${(100 * dark / n).toFixed(1)}% dark`;
}

$('settings-picture-btn').addEventListener('click', pictureAtExposure);
$('settings-profile').addEventListener('change', loadSettings);
$('settings-save').addEventListener('click', () => saveSettings(false));
$('settings-save-as').addEventListener('click', () => saveSettings(true));

async function start() {
  $('main').hidden = false;
  if (!viewer) viewer = new Viewer($('viewer'));
  $('legend').innerHTML = reasons.map(([n, c]) => `<i style="background:${c}"></i>${n}`).join('');
  if (!calibration) calibration = setupCalibration(call);
  const st = await refresh();
  await listProfiles();
  if (st.scanning) follow(st.current);
  calibration.poll();
}

start().catch((err) => {
  if ($('login').hidden) $('rig-state').textContent = `cannot reach the scanner: ${err.message}`;
});
