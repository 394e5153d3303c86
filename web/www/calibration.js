// The calibration wizard: scanner calibrate run from the page (docs/web.md). The scanner leads;
// the page shows each step's instruction with the answers it takes, the camera's picture with
// the board's corners as found, where corners have been seen, each capture, and at the end the
// result beside the file in use, with Use / Keep.
const $ = (id) => document.getElementById(id);

// Colours of the coverage picture: the board's tilt (upright, leaning, flat on the table).
const tilts = [['upright', '#60a5fa', (t) => Math.abs(t) < 15],
  ['leaning', '#f59e0b', (t) => Math.abs(t) >= 15 && Math.abs(t) < 80],
  ['flat', '#34d399', (t) => Math.abs(t) >= 80]];
const labels = {
  continue: 'Continue', back: 'Take the step before again', again: 'Take it again',
  skip: 'Go on without it',
};

let call = null;      // app.js's API call (the session key on every POST)
let timer = null;     // the poll while a calibration runs
let pictures = -1;    // pictures the page has shown: a new one is fetched when this grows
let lastState = null;

const fmt = (v, d = 2) => (typeof v === 'number' ? v.toFixed(d) : '–');

function drawCoverage(captures, live) {
  const c = $('calib-coverage');
  const g = c.getContext('2d');
  g.fillStyle = '#20242a';
  g.fillRect(0, 0, c.width, c.height);
  const outline = (o, colour, dashed) => {
    g.beginPath();
    for (let k = 0; k < 4; k++) g[k ? 'lineTo' : 'moveTo'](o[2 * k] * c.width, o[2 * k + 1] * c.height);
    g.closePath();
    g.setLineDash(dashed ? [4, 3] : []);
    g.strokeStyle = colour;
    g.lineWidth = 2;
    g.stroke();
    if (!dashed) { g.globalAlpha = 0.15; g.fillStyle = colour; g.fill(); g.globalAlpha = 1; }
  };
  for (const cap of captures)
    if (cap.kind === 'board' && cap.found && cap.outline)
      outline(cap.outline, (tilts.find(([, , is]) => is(cap.tilt_deg)) || tilts[0])[1], false);
  if (live && live.outline) outline(live.outline, '#fff', true);
}

function showCaptures(events) {
  const byView = new Map(); // a view taken again: its last capture
  for (const e of events) if (e.event === 'calib_capture') byView.set(e.view, e);
  const body = $('calib-captures').tBodies[0];
  body.textContent = '';
  const caps = [...byView.values()].sort((a, b) => a.view - b.view);
  for (const c of caps) {
    const tr = body.insertRow();
    tr.insertCell().textContent = c.view;
    tr.insertCell().textContent = c.kind === 'board' ? `board ${c.placement + 1}` : 'sphere';
    tr.insertCell().textContent = `${fmt(c.angle_deg, 1)}°`;
    tr.insertCell().textContent = c.kind === 'sphere' ? `${c.points} points`
      : c.found ? `${c.corners} corners` : `not found: ${c.why}`;
  }
  return caps;
}

function showQuestion(s, events) {
  const q = s.question;
  $('calib-ask').hidden = !q;
  if (!q) return;
  const place = [...events].reverse().find((e) => e.event === 'calib_place');
  const retry = s.stage === 'calib_retry';
  $('calib-step').textContent = retry ? 'The board was not seen.'
    : place && place.kind !== 'compute' ? `Step ${place.step + 1} of ${place.steps}:` : '';
  $('calib-text').textContent = q.detail;
  const seen = s.live;
  $('calib-seen').textContent = retry || !seen ? ''
    : seen.found ? `The camera sees the board: ${seen.corners} corners.`
      : `The camera does not see the board yet: ${seen.why || 'too few corners'}.`;
  const box = $('calib-answers');
  if (box.dataset.answers !== q.answers.join() + q.detail) {
    box.dataset.answers = q.answers.join() + q.detail;
    box.textContent = '';
    for (const a of q.answers) {
      const b = document.createElement('button');
      b.textContent = labels[a] || a;
      b.dataset.answer = a;
      b.addEventListener('click', () => answer(a));
      box.append(b);
    }
  }
}

function row(body, name, fresh, old) {
  const tr = body.insertRow();
  tr.insertCell().textContent = name;
  tr.insertCell().textContent = fresh;
  tr.insertCell().textContent = old;
}

function showResult(s) {
  const r = s.result;
  $('calib-result').hidden = !r;
  if (!r) return;
  const body = $('calib-compare').tBodies[0];
  body.textContent = '';
  const u = s.in_use && !s.in_use.missing && !s.in_use.error ? s.in_use : null;
  $('calib-choose').hidden = true;
  $('calib-weak').textContent = '';
  if (r.event === 'calib_verify') {
    $('calib-result-note').textContent = 'the ball measured with the calibration in use';
    row(body, 'diameter', `${fmt(r.diameter_mm, 3)} mm`, `${fmt(r.true_mm, 3)} mm (true)`);
    row(body, 'error', `${r.error_mm >= 0 ? '+' : ''}${fmt(r.error_mm, 3)} mm`, '');
    row(body, 'sphere fit RMS', `${fmt(r.fit_rms_mm, 4)} mm`, `${r.points} points`);
    return;
  }
  if (!r.written) {
    $('calib-result-note').textContent = '';
    $('calib-weak').textContent = `Not calibrated: ${r.refused}`;
    return;
  }
  $('calib-result-note').textContent = u ? `beside ${u.file}` : 'no calibration file in use yet';
  const pm = (v, sd, d) => `${fmt(v, d)}${sd ? ` ± ${fmt(sd, d)}` : ''}`;
  row(body, 'camera RMS (px)', fmt(r.camera_rms_px, 3), u ? fmt(u.camera_rms_px, 3) : '');
  row(body, 'projector RMS (px)', fmt(r.projector_rms_px, 3), u ? fmt(u.projector_rms_px, 3) : '');
  for (const lens of ['camera', 'projector']) {
    if (!r[lens]) continue;
    for (const k of ['fx_px', 'fy_px', 'cx_px', 'cy_px'])
      row(body, `${lens} ${k.replace('_px', '')} (px)`, pm(r[lens][k], r[lens].sigma && r[lens].sigma[k], 1),
        u ? fmt(u[lens][k], 1) : '');
  }
  if (r.pose) {
    const t = r.pose.translation_mm;
    row(body, 'projector from camera (mm)', t.map((v) => fmt(v, 1)).join(', '),
      u ? u.translation_mm.map((v) => fmt(v, 1)).join(', ') : '');
  }
  if (r.axis)
    row(body, 'turntable axis point (mm)', r.axis.point_mm.map((v) => fmt(v, 1)).join(', '),
      u ? u.axis.point_mm.map((v) => fmt(v, 1)).join(', ') : '');
  if (r.predicted)
    row(body, 'predicted depth error (mm)',
      `${fmt(r.predicted.depth_centre_mm, 3)} – ${fmt(r.predicted.depth_edge_mm, 3)}`, '');
  if (r.views)
    row(body, 'each board (camera / projector px)',
      r.views.map((v) => `${v.view}: ${fmt(v.camera_rms_px, 3)}${v.projector_rms_px !== undefined
        ? ` / ${fmt(v.projector_rms_px, 3)}` : ''}`).join(', '), '');
  if (r.weak) $('calib-weak').textContent = `Weak: ${r.weak_values}. ${r.advice}`;
  const open = s.state === 'finished' && s.choice === '';
  $('calib-choose').hidden = !open;
  $('calib-choice').textContent = s.choice === 'used' ? 'In use now (the old file is kept beside it).'
    : s.choice === 'kept' ? 'The old calibration stays in use.' : '';
}

function show(s) {
  lastState = s;
  const running = s.state === 'running';
  $('calib-start').disabled = $('calib-verify').disabled = running;
  $('calib-stop').disabled = !running;
  const u = s.in_use;
  $('calib-in-use').textContent = !u ? '' : u.missing ? `No calibration file yet (${u.file}).`
    : u.error ? `The file in use does not load: ${u.error}`
      : `In use: ${u.file} (${u.modified}${u.camera_rms_px !== undefined
        ? `, camera ${fmt(u.camera_rms_px, 3)} px, projector ${fmt(u.projector_rms_px, 3)} px` : ''})${u.weak ? ` — weak: ${u.weak}` : ''}`;
  if (s.state === 'idle') return;
  const events = s.events || [];
  const caps = showCaptures(events);
  const stage = { calib_place: 'waiting for you', calib_capture: 'capturing',
    calib_retry: 'waiting for you', calibration: 'computed', calib_verify: 'measured' }[s.stage] || s.stage;
  $('calib-progress').textContent = `${s.kind === 'verify' ? 'Check' : 'Calibration'} ${s.id}: ` +
    `${s.state}${running ? ` · ${stage}` : ''} · ${caps.length} captures`;
  $('calib-error').textContent = s.error || '';
  showQuestion(s, events);
  drawCoverage(caps, running ? s.live : null);
  if (s.kind === 'calibration' && s.pictures > 0 && s.pictures !== pictures) {
    pictures = s.pictures;
    const img = $('calib-live');
    img.onload = () => { img.hidden = false; };
    img.src = `api/calibration/live.png?n=${s.pictures}-${Date.now()}`;
  }
  showResult(s);
}

async function poll() {
  clearTimeout(timer);
  try {
    const s = await call('GET', `calibration?profile=${encodeURIComponent($('calib-profile').value)}`);
    show(s);
    if (s.state === 'running') timer = setTimeout(poll, 600);
  } catch (err) {
    $('calib-error').textContent = err.message;
    timer = setTimeout(poll, 2000);
  }
}

async function answer(a) {
  for (const b of $('calib-answers').querySelectorAll('button')) b.disabled = true;
  try {
    await call('POST', 'calibration/answer', { answer: a });
  } catch (err) {
    $('calib-error').textContent = err.message;
  }
  $('calib-answers').dataset.answers = ''; // the next question draws its buttons again
  poll();
}

async function begin(verify) {
  $('calib-error').textContent = '';
  $('calib-result').hidden = true;
  $('calib-live').hidden = true;
  pictures = -1;
  try {
    await call('POST', verify ? 'calibration/verify' : 'calibration', { profile: $('calib-profile').value });
    poll();
  } catch (err) {
    $('calib-error').textContent = err.message;
  }
}

async function choose(use) {
  $('calib-choose').hidden = true;
  try {
    await call('POST', use ? 'calibration/use' : 'calibration/keep', {});
  } catch (err) {
    $('calib-error').textContent = err.message;
  }
  poll();
}

// Wire the panel; @p apiCall is app.js's call(method, path, body).
export function setupCalibration(apiCall) {
  call = apiCall;
  $('calib-legend').innerHTML = tilts.map(([n, c]) => `<i style="background:${c}"></i>${n}`).join('');
  $('calib-start').addEventListener('click', () => begin(false));
  $('calib-verify').addEventListener('click', () => begin(true));
  $('calib-stop').addEventListener('click', async () => {
    try { await call('POST', 'calibration/stop', {}); } catch (err) { $('calib-error').textContent = err.message; }
  });
  $('calib-use').addEventListener('click', () => choose(true));
  $('calib-keep').addEventListener('click', () => choose(false));
  $('calib-profile').addEventListener('change', poll);
  drawCoverage([], null);
  return { poll, state: () => lastState };
}
