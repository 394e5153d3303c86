// make test-browser: the web interface on the simulator, driven through Debian's Chromium
// (playwright-core, no browser download) and through raw HTTP. Every check prints ok or FAIL;
// the exit status is the number of failures. Pictures of the page go to BUILD/browser/.
//   node tests/browser/browser_test.mjs BUILD
import { chromium } from 'playwright-core';
import { execFileSync, spawn } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';

const build = process.argv[2] || 'build';
const out = path.resolve(build, 'browser');
fs.rmSync(out, { recursive: true, force: true });
fs.mkdirSync(out, { recursive: true });
const scans = path.join(out, 'scans');
const scanner = path.resolve(build, 'scanner');
let failures = 0;
let lastServer = null; // its messages are printed when the test fails
const servers = [];    // every server started: none outlives the test

function check(ok, what) {
  console.log(`${ok ? 'ok' : 'FAIL'}: ${what}`);
  if (!ok) failures++;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// scanner serve with @p args; resolves with its address once it says it listens.
function serve(args) {
  return new Promise((resolve, reject) => {
    const proc = spawn(scanner, ['serve', ...args], { stdio: ['ignore', 'pipe', 'pipe'] });
    servers.push(proc);
    let text = '';
    proc.stderr.on('data', (d) => { text += d; });
    proc.stdout.on('data', (d) => {
      const m = /(http:\/\/[^/]+\/)/.exec(String(d));
      if (m) {
        lastServer = { proc, url: m[1].replace('0.0.0.0', '127.0.0.1'), log: () => text };
        resolve(lastServer);
      }
    });
    proc.on('exit', (code, signal) => reject(Object.assign(new Error(`exited ${code}: ${text}`), { code, text })));
  });
}

function stopServer(s) {
  return new Promise((resolve) => {
    if (s.proc.exitCode !== null) return resolve(s.proc.exitCode);
    s.proc.on('exit', (code) => resolve(code));
    s.proc.kill('SIGTERM');
  });
}

// A raw request: the path goes out exactly as written ("..", "%2e" and all).
function raw(url, method, rawPath, headers = {}, body = null) {
  const u = new URL(url);
  return new Promise((resolve, reject) => {
    // a fresh connection each time: the server closes idle ones, which a pooled socket would hit
    const req = http.request({ host: u.hostname, port: u.port, method, path: rawPath, headers, agent: false }, (res) => {
      const chunks = [];
      res.on('data', (c) => chunks.push(c));
      res.on('end', () => resolve({ status: res.statusCode, headers: res.headers, body: Buffer.concat(chunks) }));
    });
    req.on('error', reject);
    if (body !== null) req.write(body);
    req.end();
  });
}

const json = { 'Content-Type': 'application/json' };
// The session key a request that uses the rig carries (docs/api.md): what the page gets.
const keyed = async (url) => {
  const r = await raw(url, 'GET', '/api/session');
  const s = JSON.parse(r.body);
  return { ...json, [s.header]: s.key };
};
const port = 20000 + (process.pid % 20000);

async function waitFor(what, fn, timeoutMs) {
  const until = Date.now() + timeoutMs;
  for (;;) {
    const v = await fn();
    if (v) return v;
    if (Date.now() > until) throw new Error(`timed out waiting for ${what}`);
    await sleep(250);
  }
}

const scanState = async (url, id) =>
  JSON.parse((await raw(url, 'GET', `/api/scans/${id}`)).body.toString());

// ---- the page, as a person uses it ----
async function pageTest(browser) {
  const s = await serve(['--config', 'config/sim.ini', '--listen', `127.0.0.1:${port}`, '--scans', scans]);
  check(true, `scanner serve listens at ${s.url}`);
  const page = await browser.newPage({ viewport: { width: 1400, height: 1000 }, acceptDownloads: true });
  page.on('pageerror', (e) => check(false, `no error in the page's JavaScript (${e.message})`));
  await page.goto(s.url);
  await page.waitForSelector('#main:not([hidden])');
  // the badge says "connecting" until the page's first status answer
  await page.waitForFunction(() => !/connecting/.test(document.getElementById('rig-state').textContent));
  check((await page.textContent('#rig-state')) === 'ready', 'the page says the rig is ready');
  check((await page.textContent('#lights')) === 'off', 'lights and projector are off while idle');

  // the live camera view: pictures one after another, until a scan takes the camera
  await page.check('#live');
  await page.waitForFunction(() => { const i = document.getElementById('snapshot'); return !i.hidden && i.naturalWidth === 1280; },
    null, { timeout: 30000 });
  const first = await page.getAttribute('#snapshot', 'src');
  await page.waitForFunction((f) => document.getElementById('snapshot').src !== f, first, { timeout: 30000 });
  check(true, 'the live camera view shows one picture after another (1280 wide)');
  await page.click('#start'); // live is still on: the scan waits for the picture being taken
  await page.waitForFunction(() => /views/.test(document.getElementById('progress').textContent));
  check(!(await page.isChecked('#live')), 'starting a scan ends the live view');
  const busy = await raw(s.url, 'POST', '/api/scans', await keyed(s.url), '{}');
  check(busy.status === 409, `a second scan while one runs is refused with 409 (${busy.status})`);
  await page.waitForFunction(() => document.querySelectorAll('#thumbs figure').length >= 4 &&
    [...document.querySelectorAll('#thumbs img')].every((i) => i.complete), null, { timeout: 120000 });
  await page.screenshot({ path: path.join(out, 'page-scanning.png') });
  const during = await page.textContent('#progress');
  check(/taking view \d of 8/.test(during), `progress names the view being taken ("${during}")`);
  await page.waitForFunction(() => /8 of 8 views · finished/.test(document.getElementById('progress').textContent),
    null, { timeout: 180000 });
  check(true, 'progress reached 8 of 8 and the scan finished');
  const warned = await page.evaluate(() => {
    const w = document.getElementById('warnings');
    return w === null ? 'no #warnings list' : w.hidden ? '' : w.textContent;
  });
  check(warned === '', `the bunny, inside the volume and the image, shows no warning ("${warned}")`);
  await page.waitForFunction(() => document.getElementById('viewer').dataset.loaded, null, { timeout: 60000 });
  const id = await page.evaluate(() => document.getElementById('viewer').dataset.loaded);
  await sleep(300);
  await page.screenshot({ path: path.join(out, 'page-finished.png') });

  // the viewer drew the model: pixels unlike the background, coloured with colour on
  const pixels = () => page.evaluate(() => {
    const c = document.getElementById('viewer');
    const t = document.createElement('canvas');
    t.width = c.width; t.height = c.height;
    const g = t.getContext('2d');
    g.drawImage(c, 0, 0);
    const d = g.getImageData(0, 0, t.width, t.height).data;
    let model = 0, colourful = 0;
    for (let i = 0; i < d.length; i += 4) {
      const r = d[i], gr = d[i + 1], b = d[i + 2];
      if (Math.abs(r - 0x20) + Math.abs(gr - 0x24) + Math.abs(b - 0x2a) > 30) model++;
      if (Math.max(r, gr, b) - Math.min(r, gr, b) > 60) colourful++;
    }
    return { model, colourful, total: d.length / 4 };
  });
  const on = await pixels();
  check(on.model > 0.03 * on.total, `the viewer drew the model (${on.model} of ${on.total} pixels differ from the background)`);
  await page.click('#colour');
  await sleep(300);
  const off = await pixels();
  check(on.colourful > 5 * off.colourful + 100,
    `colour off greys the model (${on.colourful} coloured pixels with colour, ${off.colourful} without)`);

  const thumbs = await page.evaluate(() => [...document.querySelectorAll('#thumbs img')].filter((i) => i.complete && i.naturalWidth > 0).length);
  check(thumbs === 16, `every view has its colour and reason-map thumbnail (${thumbs} of 16 shown)`);

  const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#downloads a:text-is("mesh.ply")')]);
  const got = fs.readFileSync(await dl.path());
  const disk = fs.readFileSync(path.join(scans, id, 'mesh.ply'));
  check(got.equals(disk), `the downloaded mesh.ply is the file on disk (${got.length} bytes)`);
  const report = await raw(s.url, 'GET', `/api/scans/${id}/files/report.html`);
  check(report.status === 200 && /<h1>Scan /.test(report.body) && (report.body.toString().match(/<img /g) || []).length >= 29,
    'report.html is served, with the model and every view\'s pictures');
  const tar = await raw(s.url, 'GET', `/api/scans/${id}/archive.tar`);
  check(tar.status === 200 && tar.body.includes(Buffer.from(`${id}/mesh.ply`)), `the scan folder downloads as one tar (${tar.body.length} bytes)`);
  const snap = await raw(s.url, 'POST', '/api/snapshot.png', await keyed(s.url), '{}');
  check(snap.status === 200 && snap.body.subarray(1, 4).toString() === 'PNG', 'the camera\'s picture is a PNG');

  // stop a scan from the page, then resume it to the end
  await page.click('#start');
  await page.waitForFunction(() => /^Scan \S+: [2-7] of 8/.test(document.getElementById('progress').textContent), null, { timeout: 60000 });
  await page.click('#stop');
  await page.waitForFunction(() => /stopped/.test(document.getElementById('progress').textContent), null, { timeout: 60000 });
  const stoppedText = await page.textContent('#progress');
  const stoppedId = /^Scan (\S+):/.exec(stoppedText)[1];
  const kept = (await scanState(s.url, stoppedId)).views_done;
  check(kept >= 2 && kept < 8, `a stopped scan keeps its finished views (${kept}; "${stoppedText}")`);
  check(!fs.existsSync(path.join(scans, stoppedId, 'mesh.ply')) && fs.existsSync(path.join(scans, stoppedId, 'report.html')),
    'the stopped scan has a report of what it has, and no model');
  const st = JSON.parse((await raw(s.url, 'GET', '/api/status')).body);
  check(st.lights_and_projector === 'off' && !st.scanning, 'after the stop the rig is idle, lights and projector off');
  await page.click('#resume');
  await page.waitForFunction(() => /8 of 8 views · finished/.test(document.getElementById('progress').textContent), null, { timeout: 180000 });
  check(fs.existsSync(path.join(scans, stoppedId, 'mesh.ply')), 'resume finished the stopped scan');
  const rows = await page.$$eval('#past tbody tr', (trs) => trs.length);
  check(rows === 2, `the list of scans shows both (${rows})`);

  await pathTests(s.url, id);
  await foreignPageTests(browser, s.url);
  await phoneTests(browser, s.url, id);

  // scans to manage: a label given on the page, a delete asked first (no: kept; yes: gone)
  const row = `#past tbody tr:has(td:text-is("${stoppedId}"))`;
  page.once('dialog', (d) => d.accept('Vase, front'));
  await page.click(`${row} button:text-is("Label")`);
  await page.waitForFunction((sid) => [...document.querySelectorAll('#past tbody tr')]
    .some((tr) => tr.cells[0].textContent === sid && tr.cells[1].textContent === 'Vase, front'), stoppedId);
  check(true, 'a label given on the page is listed beside its scan');
  page.once('dialog', (d) => d.dismiss());
  await page.click(`${row} button:text-is("Delete")`);
  await page.waitForTimeout(500);
  check(fs.existsSync(path.join(scans, stoppedId)) && (await page.$$(row)).length === 1,
    'a delete the person says no to deletes nothing');
  page.once('dialog', (d) => d.accept());
  await page.click(`${row} button:text-is("Delete")`);
  await page.waitForFunction(() => document.querySelectorAll('#past tbody tr').length === 1);
  check(!fs.existsSync(path.join(scans, stoppedId)), 'a delete the person says yes to removes the scan from the list and the disk');
  check(/GB free of/.test(await page.textContent('#disk')), 'the page says how much of the disk is free');

  // shutting the server down mid-scan stops the scan in order
  const started = JSON.parse((await raw(s.url, 'POST', '/api/scans', await keyed(s.url), '{}')).body);
  await waitFor('a view', async () => (await scanState(s.url, started.id)).views_done >= 1, 60000);
  const code = await stopServer(s);
  check(code === 0, `the server shuts down cleanly during a scan (exit ${code})`);
  check(/stopping scan/.test(s.log()) && /safe state: lights and projector off/.test(s.log()),
    'it stopped the scan, which put the rig in its safe state');
  check(fs.existsSync(path.join(scans, started.id, 'view_000', 'view.ini')), 'the views finished before are kept');
  await page.close();
}

// ---- two passes from the page: the scanner's question shown, answered with Continue ----
async function twoPassTest(browser) {
  // make run-complete's bunny, the simulated person waiting to be asked as a real one would
  const root = path.resolve('.');
  const cfg = fs.readFileSync('config/sim-complete.ini', 'utf8')
    .replace(/^calibration = .*$/m, `calibration = ${root}/config/sim-calib.ini`)
    .replace(/^mesh_file = \.\.\//m, `mesh_file = ${root}/`)
    .replace(/^\[sim\]$/m, '[sim]\nperson = asked');
  fs.writeFileSync(path.join(out, 'two-pass.ini'), cfg);
  const passScans = path.join(out, 'two-pass-scans');
  const s = await serve(['--config', path.join(out, 'two-pass.ini'), '--listen', `127.0.0.1:${port + 2}`, '--scans', passScans]);
  const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  page.on('pageerror', (e) => check(false, `no error in the page's JavaScript (${e.message})`));
  await page.goto(s.url);
  await page.waitForSelector('#main:not([hidden])');
  const early = await raw(s.url, 'POST', '/api/scans/nothing-runs/continue', await keyed(s.url), '{}');
  check(early.status === 409, `Continue when no scan asks anything is refused (${early.status})`);
  await page.click('#start');
  await page.waitForSelector('#place:not([hidden])', { timeout: 180000 });
  const asked = await page.textContent('#place-text');
  const id = (await raw(s.url, 'GET', '/api/status').then((r) => JSON.parse(r.body))).current;
  check(/lay the object on its side/.test(asked) && (await scanState(s.url, id)).views_done === 8,
    `after the first turn the page says what to do ("${asked}"), the first pass's 8 views kept`);
  await page.waitForFunction(() => { const i = document.getElementById('place-live'); return !i.hidden && i.naturalWidth === 1280; },
    null, { timeout: 30000 });
  check(true, 'while it waits, the page shows what the camera sees (the laid object)');
  await page.screenshot({ path: path.join(out, 'page-second-pass.png') });
  const noKey = await raw(s.url, 'POST', `/api/scans/${id}/continue`, json, '{}');
  check(noKey.status === 403, `Continue without the session key is refused (${noKey.status})`);
  await page.click('#continue');
  const twice = await raw(s.url, 'POST', `/api/scans/${id}/continue`, await keyed(s.url), '{}');
  check(twice.status === 409, `a second Continue to one question is refused (${twice.status})`);
  await page.waitForFunction(() => /16 of 16 views · finished/.test(document.getElementById('progress').textContent), null, { timeout: 300000 });
  check(await page.isHidden('#place'), 'the question goes once answered');
  check(!fs.existsSync(path.join(passScans, id, 'live.png')), 'and its live picture leaves the scan folder');
  const dir = path.join(passScans, id);
  const cmp = execFileSync(path.resolve(build, 'mesh-compare'), ['--align', path.join(dir, 'mesh.ply'), path.join(dir, 'truth_mesh.ply')]).toString();
  const within = Number((/truth -> result: mean [0-9.]+ mm, within 1 mm ([0-9.]+)%/.exec(cmp) || [])[1]);
  check(within >= 98, `the two passes from the page make the complete model: ${within}% of the truth within 1 mm (make run-complete's target 98%)`);

  // settings on the page (this profile is the test's own copy): refused beside the field, kept
  await page.fill('#settings [name="scan.views"]', 'abc');
  await page.click('#settings-save');
  await page.waitForSelector('#settings .field-error');
  const said = await page.textContent('#settings .field-error');
  const beside = await page.evaluate(() => document.querySelector('#settings .field-error').previousElementSibling.name);
  check(beside === 'scan.views' && /\[scan\] views/.test(said), `a wrong value is refused, the scanner's words beside its field ("${said}")`);
  // a picture at an exposure typed in (not saved): brighter at a longer one
  const levels = [];
  for (const e of ['2000', '40000']) {
    await page.fill('#settings [name="camera.exposure_us"]', e);
    await page.click('#settings-picture-btn');
    await page.waitForFunction((x) => new RegExp(`^at ${x} µs`).test(document.getElementById('settings-picture-note').textContent), e, { timeout: 30000 });
    levels.push(Number(await page.getAttribute('#settings-picture-note', 'data-mean')));
  }
  check(levels[1] > levels[0] + 5, `a picture at the exposure typed in: brighter at 40000 µs than at 2000 (${levels.join(' < ')})`);
  const badExposure = await raw(s.url, 'POST', '/api/snapshot.png', await keyed(s.url), '{"exposure_us": 5}');
  check(badExposure.status === 400, `an exposure out of range is refused (${badExposure.status})`);
  await page.locator('#settings-panel').screenshot({ path: path.join(out, 'page-settings.png') });
  await page.fill('#settings [name="scan.views"]', '6');
  await page.selectOption('#settings [name="colour.method"]', 'multi');
  await page.click('#settings-save');
  await page.waitForFunction(() => /saved/.test(document.getElementById('settings-msg').textContent));
  const saved = fs.readFileSync(path.join(out, 'two-pass.ini'), 'utf8');
  check(/^views = 6$/m.test(saved) && /^method = multi$/m.test(saved) &&
    fs.readdirSync(out).some((f) => f.startsWith('two-pass.ini.bak-')), 'a right value is saved in the profile, the old file kept beside it');
  await page.fill('#settings-as', 'six-views');
  await page.click('#settings-save-as');
  await page.waitForFunction(() => [...document.getElementById('profile').options].some((o) => o.value === 'six-views'));
  check(fs.existsSync(path.join(out, 'six-views.ini')), 'saved as a new profile, it can be picked to scan with');
  await page.close();
  check((await stopServer(s)) === 0, 'the two-pass server shuts down cleanly');
}

// ---- the calibration wizard: scanner calibrate driven from the page, its result put in use ----
async function calibrationTest(browser) {
  // tests/calibrate.ini's short procedure on the simulated demo rig, the simulated person waiting
  // to be told to go on; the profile's calibration file starts as the nominal one
  const root = path.resolve('.');
  const calFile = path.join(out, 'wizard-cal.ini');
  fs.copyFileSync('config/sim-calib.ini', calFile);
  const cfg = fs.readFileSync('tests/calibrate.ini', 'utf8')
    .replace(/^calibration = .*$/m, `calibration = ${calFile}`)
    .replace(/^rig = \.\.\//m, `rig = ${root}/`)
    .replace(/^\[sim\]$/m, '[sim]\nperson = asked');
  fs.writeFileSync(path.join(out, 'wizard.ini'), cfg);
  const s = await serve(['--config', path.join(out, 'wizard.ini'), '--listen', `127.0.0.1:${port + 3}`,
    '--scans', path.join(out, 'wizard-scans')]);
  const page = await browser.newPage({ viewport: { width: 1400, height: 1100 } });
  page.on('pageerror', (e) => check(false, `no error in the page's JavaScript (${e.message})`));
  await page.goto(s.url);
  await page.waitForSelector('#main:not([hidden])');
  await page.waitForFunction(() => /In use: .*wizard-cal\.ini/.test(document.getElementById('calib-in-use').textContent));
  check(true, 'the calibration panel names the file in use');
  const early = await raw(s.url, 'POST', '/api/calibration/use', await keyed(s.url), '{}');
  check(early.status === 409, `Use with no calibration finished is refused (${early.status})`);
  await page.click('#calib-start');
  await page.waitForSelector('#calib-ask:not([hidden])', { timeout: 60000 });
  await page.waitForFunction(() => { const i = document.getElementById('calib-live'); return !i.hidden && i.naturalWidth === 640; },
    null, { timeout: 30000 });
  await page.waitForFunction(() => /sees the board: 48 corners/.test(document.getElementById('calib-seen').textContent), null, { timeout: 30000 });
  check(/Step 1 of 4: .*Placement 1 of 3/.test(await page.textContent('#calib-ask')),
    'the first step says where to put the board; the live picture shows it with its 48 corners found');
  await page.locator('#calib-panel').screenshot({ path: path.join(out, 'page-calibration.png') });
  // hostile answers: another site, no key, an answer the question does not take, a scan meanwhile
  const foreign = await raw(s.url, 'POST', '/api/calibration/answer',
    { ...(await keyed(s.url)), Origin: 'http://evil.example' }, '{"answer":"continue"}');
  check(foreign.status === 403, `an answer from another site is refused (${foreign.status})`);
  const noKey = await raw(s.url, 'POST', '/api/calibration/answer', json, '{"answer":"continue"}');
  check(noKey.status === 403, `an answer without the session key is refused (${noKey.status})`);
  const wrong = await raw(s.url, 'POST', '/api/calibration/answer', await keyed(s.url), '{"answer":"back"}');
  check(wrong.status === 400, `an answer the question does not take ("back" at the first step) is refused (${wrong.status})`);
  const scan = await raw(s.url, 'POST', '/api/scans', await keyed(s.url), '{}');
  check(scan.status === 409, `a scan while the rig calibrates is refused (${scan.status})`);
  const clickAnswer = async (label) => {
    await page.waitForSelector(`#calib-answers button:text-is("${label}"):not([disabled])`, { timeout: 120000 });
    await page.click(`#calib-answers button:text-is("${label}")`);
  };
  await clickAnswer('Continue');
  await page.waitForFunction(() => /Step 2 of 4/.test(document.getElementById('calib-step').textContent), null, { timeout: 120000 });
  await clickAnswer('Take the step before again'); // placement 1 again, over its own views
  await page.waitForFunction(() => /Step 1 of 4/.test(document.getElementById('calib-step').textContent), null, { timeout: 120000 });
  for (let k = 0; k < 5; k++) await clickAnswer('Continue'); // steps 1-4, then compute
  await page.waitForSelector('#calib-choose:not([hidden])', { timeout: 180000 });
  const rows = await page.locator('#calib-captures tbody tr').count();
  check(rows === 8, `the captures listed once each, the step taken again included (${rows} of 8)`);
  const r = JSON.parse((await raw(s.url, 'GET', '/api/calibration')).body).result;
  check(r.written && Math.abs(r.camera.fx_px - 2436) < 12 && Math.abs(r.pose.translation_mm[0] + 250.59) < 2 &&
    r.views.length === 6, `the result is the demo rig's (camera fx ${r.camera.fx_px.toFixed(1)} px, baseline x ${r.pose.translation_mm[0].toFixed(2)} mm, 6 boards)`);
  await page.locator('#calib-panel').screenshot({ path: path.join(out, 'page-calibration-result.png') });
  await page.click('#calib-use');
  await page.waitForFunction(() => /In use now/.test(document.getElementById('calib-choice').textContent));
  const kept = fs.readdirSync(out).filter((f) => /^wizard-cal\.ini\.\d{8}T\d{6}Z$/.test(f));
  const check_config = execFileSync(scanner, ['check-config', '--config', path.join(out, 'wizard.ini')]).toString();
  check(kept.length === 1 && /ok/.test(check_config) && /camera_rms_px/.test(fs.readFileSync(calFile, 'utf8')),
    `Use puts it in the profile's file, which check-config accepts; the old file kept beside it (${kept})`);
  const again = await raw(s.url, 'POST', '/api/calibration/use', await keyed(s.url), '{}');
  check(again.status === 409, `a second Use is refused (${again.status})`);
  // a scan with it from the page: the sphere where the truth is (the nominal file: 6.7 mm off)
  await page.click('#start');
  await page.waitForFunction(() => /1 of 1 views · finished/.test(document.getElementById('progress').textContent), null, { timeout: 120000 });
  const id = fs.readdirSync(path.join(out, 'wizard-scans')).find((f) => /^\d{4}-/.test(f));
  const dir = path.join(out, 'wizard-scans', id);
  const cmp = execFileSync(path.resolve(build, 'mesh-compare'), [path.join(dir, 'mesh.ply'), path.join(dir, 'truth_mesh.ply')]).toString();
  const mean = Number((/result -> truth: mean ([0-9.]+) mm/.exec(cmp) || [])[1]);
  check(mean < 0.1, `a scan with the page's calibration is as good as with the CLI's: ${mean} mm from the truth (the CLI's 0.046 mm)`);
  await page.close();
  check((await stopServer(s)) === 0, 'the calibration server shuts down cleanly');
}

// ---- the page on a phone: one column, nothing wider than the screen, a finger turns the model ----
async function phoneTests(browser, url, id) {
  const ctx = await browser.newContext({ viewport: { width: 375, height: 740 }, hasTouch: true, isMobile: true, deviceScaleFactor: 2 });
  const phone = await ctx.newPage();
  phone.on('pageerror', (e) => check(false, `no error in the page's JavaScript on a phone (${e.message})`));
  await phone.goto(url);
  await phone.waitForSelector('#main:not([hidden])');
  const layout = await phone.evaluate(() => ({
    wide: document.documentElement.scrollWidth, screen: window.innerWidth,
    lefts: [...document.querySelectorAll('main > section')].map((e) => Math.round(e.getBoundingClientRect().left)),
  }));
  check(layout.screen === 375 && layout.wide <= 375 && new Set(layout.lefts).size === 1,
    `on a phone the panels stand in one column, nothing wider than the screen (${layout.wide} px of ${layout.screen}; lefts ${[...new Set(layout.lefts)]})`);
  await phone.click(`#past tbody tr:has(td:text-is("${id}")) button:text-is("Open")`);
  await phone.waitForFunction((sid) => document.getElementById('viewer').dataset.loaded === sid, id, { timeout: 60000 });
  await phone.locator('#viewer').scrollIntoViewIfNeeded();
  await sleep(300);
  const shot = () => phone.evaluate(() => document.getElementById('viewer').toDataURL());
  const before = await shot();
  const box = await phone.locator('#viewer').boundingBox();
  const cdp = await ctx.newCDPSession(phone);
  const at = (dx) => [{ x: box.x + box.width / 2 + dx, y: box.y + box.height / 2 }];
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: at(0) });
  for (let dx = 10; dx <= 120; dx += 10) await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: at(dx) });
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
  await sleep(300);
  check((await shot()) !== before, 'a finger dragged across the model turns it');
  await phone.screenshot({ path: path.join(out, 'page-phone.png'), fullPage: true });
  await ctx.close();
}

// ---- requests that must be refused ----
async function pathTests(url, id) {
  fs.symlinkSync('/etc/passwd', path.join(scans, id, 'planted'));
  const cases = [
    [`/api/scans/${id}/files/../config.ini`, [403, 404]],
    [`/api/scans/${id}/files/%2e%2e/%2e%2e/%2e%2e/etc/passwd`, [403, 404]],
    [`/api/scans/${id}/files/view_000/../../../../etc/passwd`, [403, 404]],
    [`/api/scans/..%2f..%2f..%2fetc/files/passwd`, [403, 404]],
    [`/api/scans/${id}/files/planted`, [403]],
    [`/api/scans/${id}/files/%2fetc%2fpasswd`, [403, 404]],
    [`/../../../etc/passwd`, [403, 404]],
  ];
  for (const [p, want] of cases) {
    const r = await raw(url, 'GET', p);
    check(want.includes(r.status) && !r.body.includes('root:'), `${p} is refused (${r.status})`);
  }
  const ok = await raw(url, 'GET', `/api/scans/${id}/files/view_000/view.ini`);
  check(ok.status === 200, 'a view\'s file is served (200)');
  const long = JSON.stringify({ profile: 'x'.repeat(5000) });
  const key = await keyed(url);
  const big = await raw(url, 'POST', '/api/scans', { ...key, 'Content-Length': long.length }, long);
  check(big.status === 413, `a request body over 4 KiB is refused (${big.status})`);
  const chunked = await raw(url, 'POST', '/api/scans', key, long); // no length: chunked
  check(chunked.status === 413, `so is one sent in chunks, without a length (${chunked.status})`);
  const form = await raw(url, 'POST', '/api/scans', { ...key, 'Content-Type': 'text/plain' }, '{}');
  check(form.status === 415, `a POST that is not application/json is refused (${form.status}): no other site can start the rig`);
  const bad = await raw(url, 'POST', '/api/scans', key, '{"profile": "nope"}');
  check(bad.status === 400, `an unknown profile is refused (${bad.status})`);
}

// ---- a page of another site, open in the same browser, tries the rig (issue 28) ----
async function foreignPageTests(browser, url) {
  const before = JSON.parse((await raw(url, 'GET', '/api/scans')).body).scans.length;
  const target = url.replace(/\/$/, '');
  const evil = `<!doctype html><img id="snap" src="${target}/api/snapshot.png">
<script>
window.results = {};
const post = (path, init) => fetch('${target}' + path, { method: 'POST', ...init })
  .then((r) => r.status, (e) => 'blocked: ' + e.message);
Promise.all([
  post('/api/scans', { headers: { 'Content-Type': 'application/json' }, body: '{}' }),
  post('/api/scans', { mode: 'no-cors', headers: { 'Content-Type': 'text/plain' }, body: '{}' }),
  fetch('${target}/api/session').then((r) => r.text(), (e) => 'blocked: ' + e.message),
]).then((r) => { window.results = { json: r[0], form: r[1], session: r[2] }; window.done = true; });
</script>`;
  const other = http.createServer((req, res) => { res.setHeader('Content-Type', 'text/html'); res.end(evil); });
  await new Promise((r) => other.listen(0, '127.0.0.1', r));
  const page = await browser.newPage();
  try {
    await page.goto(`http://localhost:${other.address().port}/`);
    await page.waitForFunction(() => window.done, null, { timeout: 30000 });
    const r = await page.evaluate(() => window.results);
    await sleep(1000);
    const after = JSON.parse((await raw(url, 'GET', '/api/scans')).body);
    const st = JSON.parse((await raw(url, 'GET', '/api/status')).body);
    check(after.scans.length === before && !st.scanning,
      `a page of another site in the same browser starts no scan (${JSON.stringify(r)})`);
    check(/^blocked/.test(String(r.session)), 'nor reads the session key');
    const img = await page.evaluate(() => document.getElementById('snap').naturalWidth);
    check(img === 0, 'its <img> of /api/snapshot.png gets no picture (the camera is not used)');
  } finally {
    await page.close();
    other.close();
  }
}

// ---- off loopback: a token, or nothing ----
async function tokenTests() {
  try {
    await serve(['--config', 'config/sim.ini', '--listen', `0.0.0.0:${port + 1}`, '--scans', scans]);
    check(false, 'a non-loopback listen without a token is refused');
  } catch (e) {
    check(e.code === 2 && /token-file/.test(e.text), 'a non-loopback listen without a token is refused at start');
  }
  const tokenFile = path.join(out, 'token');
  const token = 'correct-horse-battery-staple';
  fs.writeFileSync(tokenFile, token + '\n', { mode: 0o600 });
  const s = await serve(['--config', 'config/sim.ini', '--listen', `0.0.0.0:${port + 1}`, '--scans', scans,
    '--token-file', tokenFile]);
  const anon = await raw(s.url, 'GET', '/api/status');
  check(anon.status === 401, `without the token GET /api/status is 401 (${anon.status})`);
  const post = await raw(s.url, 'POST', '/api/scans', json, '{}');
  check(post.status === 401, `without the token POST /api/scans is 401 (${post.status})`);
  const file = await raw(s.url, 'GET', '/api/scans/x/files/mesh.ply');
  check(file.status === 401, `without the token a download is 401 (${file.status})`);
  const wrong = await raw(s.url, 'GET', '/api/status', { Authorization: 'Bearer correct-horse-battery-stapl' });
  check(wrong.status === 401, `a wrong token is 401 (${wrong.status})`);
  const bearer = await raw(s.url, 'GET', '/api/status', { Authorization: `Bearer ${token}` });
  check(bearer.status === 200 && JSON.parse(bearer.body).token_required, 'the token as a Bearer header is let in');
  const login = await raw(s.url, 'POST', '/api/login', json, JSON.stringify({ token }));
  const cookie = (login.headers['set-cookie'] || [''])[0].split(';')[0];
  const withCookie = await raw(s.url, 'GET', '/api/scans', { Cookie: cookie });
  check(login.status === 200 && withCookie.status === 200, 'the login\'s cookie lets the page in');
  const page = await raw(s.url, 'GET', '/');
  check(page.status === 200, 'the page itself loads (it asks for the token)');
  check((await stopServer(s)) === 0, 'the token server shuts down cleanly');
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--use-gl=angle', '--use-angle=swiftshader',
    '--enable-unsafe-swiftshader'], // WebGL in software: CI machines have no GPU
});
try {
  await pageTest(browser);
  await twoPassTest(browser);
  await calibrationTest(browser);
  await tokenTests();
} catch (e) {
  check(false, `the test ran to its end (${e.stack})`);
  if (lastServer) console.log(`the server's messages (exit ${lastServer.proc.exitCode}, ${lastServer.proc.signalCode}):\n${lastServer.log()}`);
} finally {
  await browser.close();
  for (const proc of servers) // a check that threw left its server running: end it in order
    if (proc.exitCode === null && proc.signalCode === null)
      await new Promise((resolve) => { proc.on('exit', resolve); proc.kill('SIGTERM'); });
}
console.log(failures === 0 ? 'browser test: every check passed' : `browser test: ${failures} FAILED`);
process.exit(failures === 0 ? 0 : 1);
