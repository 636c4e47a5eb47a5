// The Debug view: the SOML++ debugger the server attaches to every program (docs/web.md, "Debugging").
// The script's source with its breakable lines (a click in the gutter sets or removes a breakpoint), the
// stop (the line, the call stack, the locals of the chosen frame, print), Continue / Step / Next / Finish,
// Break in (stop at the next line run), the breakpoints, and the token trace.
//
// A stop holds the simulation inside the program's run until this page (or another) resumes it: the
// server pushes a `debug` event at the stop and at the resume, and a banner in the header shows the stop
// whatever tab is open. Firings arrive as `trace` events.

import { get, post } from './api.js';
import { emit, on, select, state } from './bus.js';

const $ = (id) => document.getElementById(id);
const programSelect = $('debug-program');
const sourceBox = $('debug-source');
const stackList = $('debug-stack');
const localsTable = $('debug-locals');
const printForm = $('debug-print-form');
const printInput = $('debug-print');
const printOut = $('debug-print-out');
const bpList = $('debug-breakpoints');
const traceList = $('debug-trace');
const status = $('debug-status');
const error = $('debug-error');
const banner = $('debug-banner');
const bannerText = $('debug-banner-text');
const buttons = {
  continue: $('debug-continue'), step: $('debug-step'), next: $('debug-next'), finish: $('debug-finish'),
  pause: $('debug-pause'), bannerContinue: $('debug-banner-continue'),
};

const TRACE_SHOWN = 200;

let available = true;  // false: the server runs with debugging off (404)
let programs = [];     // /api/debug's programs
let current = null;    // the program shown
let source = null;     // {program, file, text, lines: Set}
let stopped = null;    // the stop, or null
let frame = 0;         // the frame whose locals are shown
const trace = [];      // newest last

function text(tag, content, className) {
  const e = document.createElement(tag);
  e.textContent = content;
  if (className) e.className = className;
  return e;
}

function program() {
  return programs.find((p) => p.program === current) || null;
}

function lineBreakpoints() {
  const m = new Map();
  for (const b of program()?.breakpoints || []) if (b.line) m.set(b.line, b.id);
  return m;
}

// Every transition a breakpoint names, by id, for the Nets view's Break buttons.
function transitionBreakpoints() {
  const m = new Map();
  for (const p of programs)
    for (const b of p.breakpoints || [])
      for (const id of b.transitions || []) m.set(id, { program: p.program, id: b.id });
  return m;
}

async function act(fn) {
  try {
    error.textContent = '';
    await fn();
  } catch (e) {
    error.textContent = e.message;
  }
}

function paintControls() {
  const w = state.writable;
  for (const how of ['continue', 'step', 'next', 'finish']) buttons[how].disabled = !w || !stopped;
  buttons.bannerContinue.disabled = !w;
  buttons.pause.disabled = !w || !!stopped || !program()?.debuggable;
  if (!available) status.textContent = 'debugging is off in this server';
  else if (!programs.length) status.textContent = 'this state has no SOML++ program';
  else if (stopped) status.textContent = `stopped (${stopped.reason}) at ${where(stopped)}`;
  else status.textContent = 'running';
  banner.hidden = !stopped;
  if (stopped) bannerText.textContent = `SOML++ stopped at ${where(stopped)}`;
  for (const row of sourceBox.querySelectorAll('.line.code')) row.classList.toggle('editable', w);
}

// A script's name as loaded can be a long path: its last component is enough on screen.
const base = (file) => String(file).split('/').pop();

function where(s) {
  if (s.transition) return `transition ${s.transition.label}`;
  return `${base(s.file)}:${s.line}${s.function ? ` (${s.function})` : ''}`;
}

function paintSource() {
  if (!source || source.program !== current) {
    sourceBox.replaceChildren();
    return;
  }
  const bps = lineBreakpoints();
  const here = stopped && stopped.program === current && !stopped.transition
    ? (stopped.stack[frame]?.line ?? stopped.line) : 0;
  const rows = source.text.split('\n').map((line, k) => {
    const n = k + 1;
    const row = document.createElement('div');
    row.className = 'line';
    row.dataset.line = n;
    const gutter = text('span', String(n), 'gutter');
    row.append(gutter, text('code', line || ' '));
    if (source.lines.has(n)) {
      row.classList.add('code');
      gutter.title = 'set or remove a breakpoint';
      gutter.addEventListener('click', () => state.writable && toggleLine(n));
    }
    if (bps.has(n)) row.classList.add('bp');
    if (n === here) row.classList.add('current');
    return row;
  });
  sourceBox.replaceChildren(...rows);
  sourceBox.querySelector('.line.current')?.scrollIntoView({ block: 'center' });
}

async function paintStop() {
  stackList.replaceChildren();
  localsTable.replaceChildren();
  if (!stopped) return;
  stopped.stack.forEach((f, k) => {
    const li = text('li', `${f.function} — ${base(f.file)}:${f.line}`);
    li.classList.toggle('chosen', k === frame);
    li.addEventListener('click', () => {
      frame = k;
      paintSource();
      paintStop().catch(() => {});
    });
    stackList.append(li);
  });
  if (stopped.transition) {
    const li = text('li', `before transition ${stopped.transition.label}` + (stopped.mark ? ` with mark @${stopped.mark}` : ''));
    stackList.append(li);
  }
  let locals = stopped.locals;
  if (frame > 0) locals = (await get('/api/debug/locals', { frame })).locals;
  for (const v of locals) {
    const tr = document.createElement('tr');
    tr.append(text('th', v.name), text('td', v.type, 'type'), text('td', v.value, 'value'));
    localsTable.append(tr);
  }
}

function paintBreakpoints() {
  bpList.replaceChildren();
  for (const p of programs) {
    for (const b of p.breakpoints || []) {
      const li = text('li', `${b.line ? `${base(p.file)}:${b.line}` : `transition ${b.transition}`} · ${b.hits} hit${b.hits === 1 ? '' : 's'} `);
      const remove = text('button', '×', 'remove');
      remove.title = 'remove this breakpoint';
      remove.disabled = !state.writable;
      remove.addEventListener('click', () => act(async () => {
        await post('/api/debug/remove', { program: p.program, id: b.id });
        await reload();
      }));
      li.append(remove);
      bpList.append(li);
    }
  }
  emit('breakpoints', transitionBreakpoints());
}

function traceLine(e) {
  const move = e.from || e.to ? ` · mark @${e.mark} ${e.from?.label ?? '∅'} → ${e.to?.label ?? '∅'}` : '';
  const tokens = (list, sign) => list.map((m) => `${m.label} ${sign}${m.tokens}`).join(', ');
  const black = [tokens(e.taken, '−'), tokens(e.given, '+')].filter(Boolean).join(' · ');
  const li = text('li', `#${e.firing} ${e.label}${e.kind !== 'plain' ? ` (${e.kind})` : ''}${move}${black ? ` · ${black}` : ''}`);
  li.dataset.seq = e.seq;
  if (e.mark) {
    li.classList.add('link');
    li.addEventListener('click', () => select(e.mark));
  }
  return li;
}

function addTrace(entries) {
  trace.push(...entries);
  if (trace.length > TRACE_SHOWN) trace.splice(0, trace.length - TRACE_SHOWN);
  traceList.replaceChildren(...trace.slice().reverse().map(traceLine));
}

async function toggleLine(n) {
  await act(async () => {
    const id = lineBreakpoints().get(n);
    if (id) await post('/api/debug/remove', { program: current, id });
    else await post('/api/debug/break', { program: current, line: n });
    await reload();
  });
}

/// Sets or removes a breakpoint on transition `id` (the Nets view's Break button).
export async function toggleTransition(id) {
  await act(async () => {
    const bp = transitionBreakpoints().get(id);
    if (bp) await post('/api/debug/remove', bp);
    else await post('/api/debug/break', { transition: id });
    await reload();
  });
}

async function resume(how) {
  await act(() => post('/api/debug/resume', { how }));
}

export async function reload() {
  let answer;
  try {
    answer = await get('/api/debug');
  } catch (e) {
    if (e.status !== 404) throw e;
    available = false;
    paintControls();
    return;
  }
  available = true;
  programs = answer.programs || [];
  stopped = answer.stopped;
  if (stopped) current = stopped.program;
  if (!program()) current = programs.find((p) => p.debuggable)?.program ?? null;
  programSelect.replaceChildren(...programs.map((p) => {
    const o = text('option', p.debuggable ? base(p.file) : `program ${p.program}: ${p.error}`);
    o.value = p.program;
    o.disabled = !p.debuggable;
    return o;
  }));
  programSelect.hidden = programs.length < 2;
  if (current !== null) programSelect.value = String(current);
  if (current !== null && source?.program !== current) {
    const s = await get('/api/debug/source', { program: current });
    source = { program: s.program, file: s.file, text: s.text, lines: new Set(s.lines) };
  }
  if (!trace.length && answer.trace) {
    const t = await get('/api/trace', { after: Math.max(0, answer.trace - TRACE_SHOWN), limit: TRACE_SHOWN });
    addTrace(t.entries);
  }
  paintSource();
  paintBreakpoints();
  await paintStop();
  paintControls();
}

for (const how of ['continue', 'step', 'next', 'finish']) buttons[how].addEventListener('click', () => resume(how));
buttons.bannerContinue.addEventListener('click', () => resume('continue'));
buttons.pause.addEventListener('click', () => act(async () => {
  await post('/api/debug/pause', { program: current });
  status.textContent = 'stops at the next line the program runs';
}));
programSelect.addEventListener('change', () => {
  current = Number(programSelect.value);
  frame = 0;
  reload().catch((e) => (error.textContent = e.message));
});
printForm.addEventListener('submit', (e) => {
  e.preventDefault();
  act(async () => {
    const r = await get('/api/debug/print', { path: printInput.value, frame });
    printOut.textContent = r.text;
  });
});

on('debug', (d) => {
  const wasStopped = !!stopped;
  stopped = d.stopped;
  frame = 0;
  if (stopped && !wasStopped) document.querySelector('nav.tabs button[data-tab="debug"]')?.click();
  reload().catch((e) => (error.textContent = e.message));
});
on('trace', (t) => addTrace(t.entries || []));
on('writable', () => {
  paintControls();
  paintBreakpoints();
});
