// The page's start: the header (state, stats, write token), the tabs, and the reloads that `hello` and
// `resync` ask for. Each view is its own module and listens on the bus (bus.js).

import { get, setToken, token } from './api.js';
import { emit, on, select, setWritable, state } from './bus.js';
import { connect } from './events.js';
import * as tree from './tree.js';
import * as table from './table.js';
import * as inspector from './inspector.js';
import * as timeline from './timeline.js';

// The views over the big libraries (three.js 2 MB, uPlot) load in parallel with the first answers, so
// the tree and the inspector do not wait for them.
const scene3dModule = import('./scene3d.js');
const netsModule = import('./nets.js');
const plotsModule = import('./plots.js');
const debugModule = import('./debug.js');
let scene3d = null;
let plots = null;
scene3dModule.then((m) => (scene3d = m));
plotsModule.then((m) => (plots = m));

const stateInfo = document.getElementById('state-info');
const statsLine = document.getElementById('stats');
const tokenInput = document.getElementById('token');
const mode = document.getElementById('mode');

let info = null;
let ready = false;
let reloads = 0;

function paintInfo() {
  if (!info) return;
  const time = Number(info.time ?? 0).toFixed(3);
  stateInfo.textContent = `${info.state ?? ''} · step ${info.step} · t = ${time} s · ${info.instances} instances` +
    (info.paused ? ' · paused' : '');
}

// /api/info answers `writable` for the token this request carried: the page asks again whenever the
// token changes, and enables its editing controls only on a yes.
async function refreshInfo() {
  info = await get('/api/info');
  paintInfo();
  setWritable(info.writable);
  mode.textContent = info.writable ? 'writable' : token() ? 'token refused: read-only' : 'read-only';
  mode.className = info.writable ? 'writable' : 'readonly';
}

async function reloadAll(reason) {
  const mine = ++reloads;
  ready = false;
  const results = await Promise.allSettled([
    refreshInfo(),
    get('/api/classes').then((classes) => {
      state.classes = new Map(classes.map((c) => [c.name, c]));
      table.fillClasses(classes);
    }),
    tree.reload(),
    scene3dModule.then((m) => m.reload()),
    netsModule.then((m) => m.reload()),
    debugModule.then((m) => m.reload()),
    timeline.reload(),
    state.selected !== null ? inspector.show(state.selected) : null,
  ]);
  for (const r of results) if (r.status === 'rejected') console.error(`vsd: reload (${reason})`, r.reason);
  if (mine === reloads) ready = true;
}

// Tabs: one pane of each group is shown; the 3D view and the plots resize when they appear.
for (const nav of document.querySelectorAll('nav.tabs')) {
  nav.addEventListener('click', (e) => {
    const name = e.target.dataset?.tab;
    if (!name) return;
    const section = nav.parentElement;
    for (const b of nav.querySelectorAll('button')) b.classList.toggle('active', b === e.target);
    for (const p of section.querySelectorAll(':scope > .pane')) p.classList.toggle('active', p.dataset.pane === name);
    emit('tab', name);
  });
}

tokenInput.value = token();
tokenInput.addEventListener('change', () => {
  setToken(tokenInput.value.trim());
  refreshInfo().catch((e) => (mode.textContent = e.message));
});

on('reload', ({ reason }) => reloadAll(reason));
on('changes', (batch) => {
  if (!info) return;
  info.step = batch.step ?? info.step;
  info.time = batch.time ?? info.time;
  info.instances += (batch.created?.length || 0) - (batch.deleted?.length || 0);
  paintInfo();
});
on('stats', (s) => {
  if (info && typeof s.step === 'number') {
    // Stats come while the simulation steps even when nothing changed: the header follows them too.
    info.step = s.step;
    info.time = s.time ?? info.time;
    paintInfo();
  }
  const f = (x) => (typeof x === 'number' ? (x >= 100 ? x.toFixed(0) : x.toFixed(1)) : '?');
  statsLine.textContent = `${f(s.steps_per_s)} steps/s · ${f(s.changes_per_s)} changes/s · ` +
    `${f(s.firings_per_s)} firings/s · ${s.clients} client${s.clients === 1 ? '' : 's'}`;
});
on('connected', (up) => document.body.classList.toggle('disconnected', !up));

// The browser tests' hook (tests/web/browser): the view's state, read without pixels.
window.vsdTest = {
  ready: () => ready,
  positions: () => scene3d?.positions() ?? {},
  objects: () => scene3d?.objectIds() ?? [],
  selected: () => state.selected,
  writable: () => state.writable,
  select: (id) => select(id),
  pick: (hullId) => scene3d?.pick(hullId),
  screenPosition: (id) => scene3d?.screenPosition(id) ?? null,
  timeline: () => timeline.current(),
  plots: () => plots?.plotted() ?? [],
  stopped: () => !document.getElementById('debug-banner').hidden,
};

connect();
