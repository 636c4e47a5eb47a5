#!/usr/bin/env node
// End-to-end tests of the web inspector in headless Chromium (issue 23, item 7).
//
//   node run.mjs --server PATH_TO_VSD_WEB --file MODEL_FILE [--artifacts DIR] [--modules DIR]
//                [--chromium PATH] [-- EXTRA SERVER ARGS]
//
// Starts `vsd-web MODEL_FILE --port 0 --token T [EXTRA]`, reads the URL from its
// "vsd-web: serving http://..." line, drives the page with playwright-core and asserts on the DOM, on
// the page's test hook (window.vsdTest) and on the server's state (GET /api/...). Screenshots go into
// the artifacts directory; nothing compares pixels. Every check runs even when one before it failed;
// the exit code is 1 when any failed, and each failure says which check and why.
//
// What the checks need of the model, found through the API rather than by name: a Node3D with a hull
// whose frame is Editable, and a SOML++ net with an enabled transition.

import { spawn } from 'node:child_process';
import { randomBytes } from 'node:crypto';
import fs from 'node:fs';
import http from 'node:http';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));

function parseArgs(argv) {
  const opts = { artifacts: null, modules: process.env.VSD_BROWSER_MODULES || here,
                 chromium: process.env.VSD_CHROMIUM || '/usr/bin/chromium', extra: [] };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    const value = () => {
      if (i + 1 >= argv.length) usage(`${a} needs a value`);
      return argv[++i];
    };
    if (a === '--') { opts.extra = argv.slice(i + 1); break; }
    else if (a === '--server') opts.server = value();
    else if (a === '--file') opts.file = value();
    else if (a === '--artifacts') opts.artifacts = value();
    else if (a === '--modules') opts.modules = value();
    else if (a === '--chromium') opts.chromium = value();
    else usage(`unknown argument '${a}'`);
  }
  if (!opts.server || !opts.file) usage('--server and --file are required');
  return opts;
}

function usage(why) {
  console.error(`run.mjs: ${why}\nusage: node run.mjs --server VSD_WEB --file MODEL [--artifacts DIR] ` +
                '[--modules DIR_WITH_NODE_MODULES] [--chromium PATH] [-- SERVER ARGS]');
  process.exit(2);
}

const opts = parseArgs(process.argv.slice(2));
const artifacts = path.resolve(opts.artifacts || path.join(process.cwd(), 'web-browser-artifacts'));
fs.mkdirSync(artifacts, { recursive: true });
const TOKEN = randomBytes(16).toString('hex');

// playwright-core is installed next to the build (run.sh), not next to this file.
let chromium;
try {
  ({ chromium } = createRequire(path.join(path.resolve(opts.modules), 'noop.js'))('playwright-core'));
} catch (e) {
  console.error(`run.mjs: playwright-core not found under ${opts.modules}/node_modules (run.sh installs it): ${e.message}`);
  process.exit(2);
}

// ---- the server -------------------------------------------------------------------------------------

function startServer() {
  return new Promise((resolve, reject) => {
    const args = [opts.file, '--port', '0', '--token', TOKEN, ...opts.extra];
    const child = spawn(opts.server, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    let out = '';
    let err = '';
    const timer = setTimeout(() => fail(new Error('no "vsd-web: serving http://..." line within 20 s')), 20000);
    function fail(e) {
      clearTimeout(timer);
      child.kill('SIGKILL');
      reject(new Error(`${opts.server} ${args.join(' ')}: ${e.message}\nstdout: ${out}\nstderr: ${err}`));
    }
    child.on('error', fail);
    child.on('exit', (code, signal) => fail(new Error(`exited (${code ?? signal}) before serving`)));
    child.stderr.on('data', (d) => (err += d));
    child.stdout.on('data', (d) => {
      out += d;
      const m = /vsd-web: serving (http:\/\/\S+?)\/?(\s|$)/.exec(out);
      if (m) {
        clearTimeout(timer);
        child.removeAllListeners('exit');
        child.stdout.removeAllListeners('data');
        child.stdout.resume(); // keep draining, so the server never blocks on a full pipe
        child.on('exit', (code, signal) => { child.exited = { code, signal }; });
        resolve({ child, url: m[1].replace(/\/$/, ''), stderr: () => err });
      }
    });
  });
}

function stopServer(server) {
  return new Promise((resolve) => {
    if (!server || server.child.exited) return resolve();
    const timer = setTimeout(() => server.child.kill('SIGKILL'), 5000);
    server.child.on('exit', () => { clearTimeout(timer); resolve(); });
    server.child.kill('SIGTERM');
  });
}

// ---- small helpers ----------------------------------------------------------------------------------

let base = '';

async function api(pathAndQuery, { method = 'GET', body, token } = {}) {
  const headers = {};
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  if (token) headers['X-VSD-Token'] = token;
  const r = await fetch(base + pathAndQuery, { method, headers, body: body === undefined ? undefined : JSON.stringify(body) });
  const text = await r.text();
  let json = null;
  try { json = JSON.parse(text); } catch { /* not JSON */ }
  return { status: r.status, json, text };
}

async function apiOk(pathAndQuery, init) {
  const r = await api(pathAndQuery, init);
  if (r.status !== 200) throw new Error(`${init?.method || 'GET'} ${pathAndQuery}: ${r.status} ${r.text}`);
  return r.json;
}

function assert(cond, message) {
  if (!cond) throw new Error(message);
}

// Poll until fn() is truthy (or throw with the last value): the page and the server are asynchronous.
async function until(what, fn, timeout = 10000) {
  const start = Date.now();
  let last;
  for (;;) {
    try {
      last = await fn();
      if (last) return last;
    } catch (e) {
      last = e.message;
    }
    if (Date.now() - start > timeout) throw new Error(`timed out after ${timeout} ms waiting for ${what} (last: ${JSON.stringify(last)})`);
    await new Promise((r) => setTimeout(r, 100));
  }
}

const near = (a, b, eps = 1e-6) => Math.abs(a - b) <= eps;
// One past the newest timeline entry (the server may have dropped the oldest ones).
const timelineEnd = (t) => t.end ?? (t.first ?? 0) + t.entries.length;

async function shot(page, name) {
  try {
    await page.screenshot({ path: path.join(artifacts, `${name}.png`) });
  } catch (e) {
    console.error(`  (screenshot ${name} failed: ${e.message})`);
  }
}

async function openPage(browser, { withToken }) {
  const context = await browser.newContext({ viewport: { width: 1400, height: 850 } });
  const page = await context.newPage();
  const problems = [];
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  // Refused requests (the checks make some on purpose) show as 'Failed to load resource' in the
  // console; the checks assert on those answers themselves.
  page.on('console', (m) => m.type() === 'error' && !m.text().startsWith('Failed to load resource') &&
                             problems.push(`console: ${m.text()}`));
  await page.goto(base + '/');
  if (withToken) {
    // As a user would: paste the token into the header field.
    await page.fill('#token', TOKEN);
    await page.press('#token', 'Enter');
    await page.locator('#token').blur();
  }
  // Generous: a loaded CI machine, and 4 MB of libraries (three.js, elkjs, uPlot) on the first load.
  await until('the page to finish loading (window.vsdTest.ready())', () => page.evaluate(() => window.vsdTest?.ready()), 30000);
  if (withToken) await until('the page to be writable', () => page.evaluate(() => window.vsdTest.writable()));
  return { page, context, problems };
}

// ---- the checks -------------------------------------------------------------------------------------

const results = [];
let mainPage = null; // a failing check leaves a screenshot of it
async function check(name, fn) {
  const started = Date.now();
  try {
    await fn();
    results.push({ name, ok: true });
    console.log(`ok   ${name} (${Date.now() - started} ms)`);
  } catch (e) {
    results.push({ name, ok: false, message: e.message });
    console.log(`FAIL ${name}: ${e.message}`);
    if (mainPage) await shot(mainPage, `FAIL-${results.length}`);
  }
}

async function main() {
  const server = await startServer();
  base = server.url;
  console.log(`server: ${base} (artifacts in ${artifacts})`);
  let browser = null;
  try {
    browser = await chromium.launch({
      executablePath: opts.chromium,
      // --no-sandbox: CI containers run as root; SwiftShader: WebGL without a GPU.
      args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader'],
    });
    await runChecks(browser);
  } finally {
    await browser?.close().catch(() => {});
    await stopServer(server);
  }
  const failed = results.filter((r) => !r.ok);
  console.log(`\n${results.length - failed.length} of ${results.length} checks passed`);
  for (const f of failed) console.log(`  FAILED: ${f.name}: ${f.message}`);
  if (failed.length && server.stderr()) console.log(`server stderr:\n${server.stderr()}`);
  process.exit(failed.length ? 1 : 0);
}

async function runChecks(browser) {
  // A foreign Host header (DNS rebinding): refused before anything else, from node, not the browser
  // (a browser cannot send a Host that differs from the URL).
  await check('a request with a foreign Host header is refused', async () => {
    const url = new URL(base + '/api/info');
    const status = await new Promise((resolve, reject) => {
      const req = http.request({ host: url.hostname, port: url.port, path: url.pathname,
                                 headers: { Host: `evil.example:${url.port}` } }, (res) => {
        res.resume();
        resolve(res.statusCode);
      });
      req.on('error', reject);
      req.end();
    });
    assert(status === 403, `GET /api/info with Host evil.example answered ${status}, expected 403`);
    const own = await api('/api/info');
    assert(own.status === 200, `GET /api/info with the right Host answered ${own.status}`);
  });

  const { page, problems } = await openPage(browser, { withToken: true });
  mainPage = page;
  await shot(page, '01-loaded');

  await check('the page loads without errors', async () => {
    assert(await page.title() === 'vsd inspector', `title is '${await page.title()}'`);
    const info = await apiOk('/api/info');
    await until('the header to show the state', async () =>
      (await page.textContent('#state-info')).includes(`${info.instances} instances`));
    assert(!problems.length, problems.join('; '));
  });

  // The Node3D to move: the node of the first hull, with an Editable frame.
  const scene = await apiOk('/api/scene');
  let target = null;
  for (const hull of scene.hulls || []) {
    const node = await apiOk(`/api/instance?id=${hull.node}`);
    const frame = node.properties.find((p) => p.name === 'frame');
    if (frame?.editable) { target = { id: node.id, hull: hull.id, frame: frame.value }; break; }
  }
  await check('the tree shows the model', async () => {
    const top = await apiOk('/api/children');
    assert(top.children.length > 0, '/api/children lists no top-level node');
    for (const child of top.children.slice(0, 20)) {
      const row = page.locator(`#tree li[data-id="${child.id}"] > .tree-row`);
      await row.waitFor({ timeout: 5000 });
      const text = await row.textContent();
      assert(text.includes(child.class) && text.includes(`#${child.id}`),
             `tree row of #${child.id} reads '${text}', expected its class ${child.class}`);
    }
    // Opening a node fetches its children lazily.
    const parent = top.children.find((c) => c.children > 0);
    if (parent) {
      await page.click(`#tree li[data-id="${parent.id}"] > .tree-row .toggle`);
      const kids = await apiOk(`/api/children?id=${parent.id}&offset=0&limit=5`);
      await page.locator(`#tree li[data-id="${kids.children[0].id}"]`).waitFor({ timeout: 5000 });
    }
    // Selecting an instance elsewhere opens the tree down to it.
    if (target) {
      await page.evaluate((id) => window.vsdTest.select(id), target.id);
      await page.locator(`#tree li[data-id="${target.id}"] > .tree-row.selected`).waitFor({ timeout: 5000 });
    }
    await shot(page, '02-tree');
  });

  const frameOf = async (id) => (await apiOk(`/api/instance?id=${id}`)).properties.find((p) => p.name === 'frame').value;
  const frameRow = 'tr[data-property="frame"]';
  let timelineBefore = null;
  let edited = null;

  await check('editing a frame translation changes the database and moves the object in 3D', async () => {
    assert(target, 'the model has no hull whose node has an Editable frame (see /api/scene)');
    await until('the 3D view to hold the hull', () => page.evaluate((id) => id in window.vsdTest.positions(), target.hull));
    const before = await page.evaluate(() => window.vsdTest.positions());
    timelineBefore = timelineEnd(await apiOk('/api/timeline'));
    await page.evaluate((id) => window.vsdTest.select(id), target.id);
    await page.locator(`#inspector ${frameRow} input.tx`).waitFor({ timeout: 5000 });
    const x0 = target.frame.translation[0];
    const x1 = Math.round((x0 + 0.25) * 1000) / 1000;
    await page.fill(`#inspector ${frameRow} input.tx`, String(x1));
    await page.click(`#inspector ${frameRow} button.set`);
    await until('the database to hold the new translation', async () => near((await frameOf(target.id)).translation[0], x1));
    const dx = x1 - x0;
    await until('the hull to move by the same amount in the 3D view', () => page.evaluate(({ hull, x, dx }) => {
      const p = window.vsdTest.positions()[hull];
      return p && Math.abs(p[0] - (x + dx)) < 1e-6;
    }, { hull: target.hull, x: before[target.hull][0], dx }));
    assert(!(await page.textContent(`#inspector ${frameRow} .msg`)), 'an error is shown after a good edit');
    edited = { x0, x1 };
    await shot(page, '03-edited');
  });

  await check('a click on a hull in the 3D view selects its node', async () => {
    assert(target, 'no hull (see above)');
    await page.click('nav.tabs button[data-tab="scene"]');
    // Select the hull itself first, so that the pick's selection of its node is a change.
    await page.evaluate((id) => window.vsdTest.select(id), target.hull);
    await page.locator(`#inspector[data-id="${target.hull}"]`).waitFor({ timeout: 5000 });
    const at = await until('the hull to be drawn', () => page.evaluate((id) => window.vsdTest.screenPosition(id), target.hull));
    await page.mouse.click(at[0], at[1]);
    await until(`#${target.id} to be selected`, () => page.evaluate((id) => window.vsdTest.selected() === id, target.id));
    await page.locator(`#inspector[data-id="${target.id}"]`).waitFor({ timeout: 5000 });
  });

  await check('a bad value is refused with a message and nothing changes', async () => {
    assert(target, 'no editable Node3D (see above)');
    const before = await frameOf(target.id);
    await page.fill(`#inspector ${frameRow} input.tx`, 'not a number');
    await page.click(`#inspector ${frameRow} button.set`);
    const msg = await until('an error message next to the field',
                            async () => (await page.textContent(`#inspector ${frameRow} .msg`)).trim());
    assert(msg.length > 3, `message '${msg}'`);
    assert(JSON.stringify(await frameOf(target.id)) === JSON.stringify(before),
           'the frame changed in the database after a refused edit');
    // A numeric property too, if the instance has one.
    const info = await apiOk(`/api/instance?id=${target.id}`);
    const numeric = info.properties.find((p) => p.editable && p.kind === 'value' && /^(double|float|u?int\d+)$/.test(p.type));
    if (numeric) {
      const row = `#inspector tr[data-property="${numeric.name}"]`;
      await page.fill(`${row} input.value-input`, '"text"');
      await page.click(`${row} button.set`);
      const m2 = await until(`an error message next to ${numeric.name}`, async () => (await page.textContent(`${row} .msg`)).trim());
      assert(m2.includes(numeric.name) || m2.includes(numeric.type),
             `the message '${m2}' names neither the property '${numeric.name}' nor its type ${numeric.type}`);
      const after = (await apiOk(`/api/instance?id=${target.id}`)).properties.find((p) => p.name === numeric.name);
      assert(JSON.stringify(after.value) === JSON.stringify(numeric.value), `${numeric.name} changed after a refused edit`);
    }
    await shot(page, '04-refused');
  });

  await check('the per-class table lists the instances and filters them', async () => {
    assert(target, 'no editable Node3D (see above)');
    const info = await apiOk(`/api/instance?id=${target.id}`);
    const all = await apiOk(`/api/table?class=${encodeURIComponent(info.class)}&offset=0&limit=1`);
    await page.click('nav.tabs button[data-tab="table"]');
    await page.selectOption('#table-class', info.class);
    await until(`the table to count ${all.total} rows`, async () => (await page.textContent('#table-total')) === `${all.total} rows`);
    await page.locator(`#table-rows tr[data-id="${target.id}"]`).waitFor({ timeout: 5000 });
    const where = `name ~ ${info.name}`;
    const some = await apiOk(`/api/table?class=${encodeURIComponent(info.class)}&offset=0&limit=1&where=${encodeURIComponent(where)}`);
    await page.fill('#table-filter', where);
    await page.press('#table-filter', 'Enter');
    await until(`the filter to leave ${some.total} rows`, async () => (await page.textContent('#table-total')) === `${some.total} rows`);
    await page.fill('#table-filter', 'no_such_property > 1');
    await page.press('#table-filter', 'Enter');
    await until('the server\'s message about the bad filter', async () => (await page.textContent('#table-error')).trim());
    await shot(page, '05-table');
    await page.fill('#table-filter', '');
    await page.press('#table-filter', 'Enter');
    // The Columns chooser: ticking a property not shown adds its column, unticking removes it.
    await page.click('#table-columns summary');
    const unticked = page.locator('#table-columns-list input:not(:checked)').first();
    await unticked.waitFor({ timeout: 5000 });
    const column = await unticked.getAttribute('value');
    const headers = () => page.evaluate(() => [...document.querySelectorAll('#table-header th')].map((th) => th.textContent));
    await unticked.check();
    await until(`the column ${column} in the table`, async () => (await headers()).includes(column));
    await page.locator(`#table-columns-list input[value="${column}"]`).uncheck();
    await until(`the column ${column} to go`, async () => !(await headers()).includes(column));
    await page.click('#table-columns summary');
    await page.click('nav.tabs button[data-tab="tree"]');
  });

  await check('a numeric property picked in the inspector is plotted live', async () => {
    assert(target, 'no editable Node3D (see above)');
    const info = await apiOk(`/api/instance?id=${target.id}`);
    const numeric = info.properties.find((p) => p.editable && p.kind === 'value' && /^(double|float|u?int\d+)$/.test(p.type));
    assert(numeric, `#${target.id} has no editable numeric property`);
    const row = `#inspector tr[data-property="${numeric.name}"]`;
    await page.click(`${row} button.plot`);
    await until('the plot to start', () => page.evaluate(() => window.vsdTest.plots().length === 1));
    await page.fill(`${row} input.value-input`, String(Number(numeric.value) + 1));
    await page.click(`${row} button.set`);
    await until('the change to reach the plot', () => page.evaluate(() => window.vsdTest.plots()[0].points >= 2));
    const plot = await page.evaluate(() => window.vsdTest.plots()[0]);
    const { time } = await apiOk('/api/info');
    assert(plot.axis === 'sim' && plot.x === time, `the plot's x is ${plot.x} (${plot.axis}), the simulated time ${time}`);
    await shot(page, '06-plot');
  });

  // Nets: the DOM's counts must match the server's marking. These run before the timeline's Live
  // (which unpauses the simulation): vsd-web starts paused, so only the checks fire transitions.
  const marking = async () => {
    const nets = (await apiOk('/api/nets')).nets;
    return Object.fromEntries(nets.flatMap((n) => n.places.map((p) => [p.id, p.tokens])));
  };
  const domMarking = () => page.evaluate(() => Object.fromEntries(
    [...document.querySelectorAll('#nets .place[data-id]')].map((g) => [g.dataset.id, Number(g.dataset.tokens)])));
  const sameMarking = async () => {
    const want = await marking();
    const have = await domMarking();
    return Object.entries(want).every(([id, n]) => have[id] === n) ? want : false;
  };
  const enabledTransition = async () => (await apiOk('/api/nets')).nets.flatMap((n) => n.transitions).find((t) => t.enabled);

  await check('the fire button fires an enabled transition', async () => {
    await page.click('nav.tabs button[data-tab="nets"]');
    const t = await until('an enabled transition', enabledTransition, 5000);
    const before = await marking();
    await until('the nets view to show the marking', sameMarking);
    const button = page.locator(`#nets table.transitions tr[data-id="${t.id}"] button.fire`);
    await until('the Fire button to be enabled', () => button.isEnabled());
    await page.locator(`#nets .transition[data-id="${t.id}"].enabled`).waitFor({ timeout: 5000 });
    await shot(page, '07-nets-before');
    await button.click();
    await until('the transition to have fired', async () =>
      (await apiOk('/api/nets')).nets.flatMap((n) => n.transitions).find((x) => x.id === t.id).firings === t.firings + 1);
    const after = await marking();
    assert(JSON.stringify(after) !== JSON.stringify(before), 'the marking did not change');
    await until('the nets view to show the new marking', sameMarking);
    await shot(page, '08-nets-fired');
  });

  await check('the marking updates when a transition fires (fired by another client)', async () => {
    const t = await until('an enabled transition', enabledTransition, 5000);
    const before = await marking();
    await apiOk('/api/fire', { method: 'POST', body: { transition: t.id }, token: TOKEN });
    const after = await marking();
    assert(JSON.stringify(after) !== JSON.stringify(before), 'the marking did not change');
    await until('the page to show the marking after the firing', sameMarking);
    // A click on a place lists its token objects.
    const placeId = Object.keys(after).find((id) => after[id] > 0);
    if (placeId) {
      await page.click(`#nets .place[data-id="${placeId}"]`);
      await until('the place\'s tokens to be listed', async () =>
        (await page.textContent('#place-tokens')).includes(`${after[placeId]} token`));
    }
  });

  await check('a breakpoint set in the Debug tab stops a firing; the page shows where; Continue goes on', async () => {
    await page.click('nav.tabs button[data-tab="debug"]');
    const { programs } = await apiOk('/api/debug');
    assert(programs.length === 1 && programs[0].debuggable, `/api/debug: ${JSON.stringify(programs)}`);
    const source = await apiOk(`/api/debug/source?program=${programs[0].program}`);
    const line = source.text.split('\n').findIndex((l) => l.includes('fired += 1')) + 1;
    assert(line > 0 && source.lines.includes(line), `no breakable line with 'fired += 1' (lines ${source.lines})`);
    const gutter = page.locator(`#debug-source .line[data-line="${line}"] .gutter`);
    await gutter.click();
    await until('the breakpoint in the server', async () =>
      (await apiOk('/api/debug')).programs[0].breakpoints.some((b) => b.line === line));
    await page.locator(`#debug-source .line.bp[data-line="${line}"]`).waitFor({ timeout: 5000 });
    // Another client fires: the firing stops at the line and its request waits for the resume.
    const t = await until('an enabled transition', enabledTransition, 5000);
    const firing = api('/api/fire', { method: 'POST', body: { transition: t.id }, token: TOKEN });
    await until('the stop in the page', () => page.evaluate(() => window.vsdTest.stopped()));
    assert((await page.textContent('#debug-banner')).includes(`:${line}`), `banner: ${await page.textContent('#debug-banner')}`);
    await page.locator(`#debug-source .line.current[data-line="${line}"]`).waitFor({ timeout: 5000 });
    await until('the call stack', async () => (await page.locator('#debug-stack li').count()) >= 1);
    const refused = await api('/api/set', { method: 'POST', body: { id: target?.id ?? 1, property: 'name', value: 'x' }, token: TOKEN });
    assert(refused.status === 409, `an edit while stopped answered ${refused.status}, expected 409`);
    await shot(page, '09a-stopped');
    await page.click('#debug-continue');
    const fired = await firing;
    assert(fired.status === 200, `the stopped firing answered ${fired.status} ${fired.text}`);
    await until('the banner to go', async () => !(await page.evaluate(() => window.vsdTest.stopped())));
    await until('the firing in the token trace', async () => (await page.textContent('#debug-trace')).includes(t.name));
    await gutter.click();
    await until('the breakpoint to be removed', async () => (await apiOk('/api/debug')).programs[0].breakpoints.length === 0);
    // A transition breakpoint from the Nets view's Break button, and off again.
    await page.click('nav.tabs button[data-tab="nets"]');
    const brk = page.locator(`#nets table.transitions tr[data-id="${t.id}"] button.break`);
    await brk.click();
    await until('the transition breakpoint', async () =>
      (await apiOk('/api/debug')).programs[0].breakpoints.some((b) => (b.transitions || []).includes(t.id)));
    await page.locator(`#nets table.transitions tr[data-id="${t.id}"] button.break.on`).waitFor({ timeout: 5000 });
    await brk.click();
    await until('no breakpoint left', async () => (await apiOk('/api/debug')).programs[0].breakpoints.length === 0);
  });

  await check('scrubbing the timeline back restores the earlier value, Live brings the edit back', async () => {
    assert(edited, 'the edit check did not pass');
    const timeline = await apiOk('/api/timeline');
    assert(timelineEnd(timeline) > timelineBefore, `the edit made no timeline entry (${JSON.stringify(timeline).slice(0, 200)})`);
    await page.locator('#timeline-slider').waitFor();
    await until('the slider to know the entries', () =>
      page.evaluate((end) => Number(document.getElementById('timeline-slider').max) >= end, timelineEnd(timeline)));
    // Drag the thumb back to before the edit: what the slider's input and change events do.
    await page.evaluate((k) => {
      const s = document.getElementById('timeline-slider');
      s.value = String(k);
      s.dispatchEvent(new Event('input', { bubbles: true }));
      s.dispatchEvent(new Event('change', { bubbles: true }));
    }, timelineBefore);
    await until('the frame to be back at its earlier translation', async () => near((await frameOf(target.id)).translation[0], edited.x0));
    await until('the hull to be back in the 3D view', () => page.evaluate(({ hull, x }) =>
      Math.abs(window.vsdTest.positions()[hull][0] - x) < 1e-6, { hull: target.hull, x: scene.hulls.find((h) => h.id === target.hull).world[12] }));
    await shot(page, '09-scrubbed');
    await page.click('#timeline-live');
    await until('the edit to be applied again after Live', async () => near((await frameOf(target.id)).translation[0], edited.x1));
    await until('the timeline to be live', async () => (await apiOk('/api/timeline')).live);
  });

  await check('without the token the page is read-only', async () => {
    const { page: ro, context, problems: roProblems } = await openPage(browser, { withToken: false });
    try {
      assert(!(await ro.evaluate(() => window.vsdTest.writable())), 'the page says it is writable without a token');
      assert((await ro.textContent('#mode')).includes('read-only'), `#mode reads '${await ro.textContent('#mode')}'`);
      if (target) {
        await ro.evaluate((id) => window.vsdTest.select(id), target.id);
        await ro.locator(`#inspector ${frameRow} input.tx`).waitFor({ timeout: 5000 });
        assert(await ro.locator(`#inspector ${frameRow} input.tx`).isDisabled(), 'the frame input is enabled');
        assert(await ro.locator(`#inspector ${frameRow} button.set`).isDisabled(), 'the set button is enabled');
      }
      assert(await ro.locator('#timeline-slider').isDisabled(), 'the timeline slider is enabled');
      await ro.click('nav.tabs button[data-tab="nets"]');
      const fires = ro.locator('#nets button.fire');
      await until('the nets view', async () => (await fires.count()) > 0 || !(await enabledTransition()));
      for (let i = 0; i < await fires.count(); ++i) assert(await fires.nth(i).isDisabled(), 'a Fire button is enabled');
      // And the server agrees: a write from this page without the token is refused.
      const status = await ro.evaluate(async (id) => (await fetch('/api/set', {
        method: 'POST', headers: { 'Content-Type': 'application/json' },
        body: JSON.stringify({ id, property: 'name', value: 'x' }) })).status, target?.id ?? 1);
      assert(status === 403, `a POST /api/set without the token answered ${status}`);
      await shot(ro, '10-read-only');
      assert(!roProblems.length, roProblems.join('; '));
    } finally {
      await context.close();
    }
  });

  await check('no errors in the page', async () => {
    assert(!problems.length, problems.join('; '));
  });
  await shot(page, '11-end');
}

main().catch((e) => {
  console.error(`run.mjs: ${e.stack || e.message}`);
  process.exit(1);
});
