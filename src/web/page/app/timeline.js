// The timeline: the state's recorded bundles (/api/timeline) as a slider whose value is the number of
// entries kept applied. Dragging it seeks (POST /api/timeline/seek, which pauses the simulation and
// applies inverted bundles back, or the bundles again forward); Live returns to the newest entry and
// unpauses. Pause/Run stops and starts the simulation (POST /api/pause). Seeking is a write, so without
// the token the slider only shows where the state is.

import { get, post } from './api.js';
import { on, state } from './bus.js';

const slider = document.getElementById('timeline-slider');
const live = document.getElementById('timeline-live');
const pause = document.getElementById('timeline-pause');
const label = document.getElementById('timeline-label');
const error = document.getElementById('timeline-error');

let entries = [];
let first = 0;       // the oldest entry still kept (older ones may have been dropped)
let end = 0;         // one past the newest entry
let position = 0;
let isLive = true;
let paused = false;
let dragging = false;

function describe(k) {
  const last = entries.find((e) => e.index === k - 1);
  const at = last ? ` · step ${last.step} · t = ${Number(last.time).toFixed(3)} s` : k === first ? ' · the start' : '';
  return `${k} / ${end} entries${at}${isLive ? ' · live' : ' · scrubbed'}${paused ? ' · paused' : ''}`;
}

function paint() {
  slider.min = String(first);
  slider.max = String(end);
  if (!dragging) slider.value = String(position);
  slider.disabled = !state.writable;
  live.disabled = !state.writable || isLive;
  pause.disabled = !state.writable;
  pause.textContent = paused ? 'Run' : 'Pause';
  label.textContent = describe(dragging ? Number(slider.value) : position);
  document.getElementById('timeline').classList.toggle('paused', !isLive);
}

export async function reload() {
  const [answer, info] = await Promise.all([get('/api/timeline'), get('/api/info')]);
  entries = answer.entries || [];
  first = answer.first ?? (entries.length ? entries[0].index : 0);
  end = answer.end ?? first + entries.length;
  position = answer.position ?? end;
  isLive = !!answer.live;
  paused = !!info.paused;
  paint();
}

// While dragging, one seek is in flight at a time and the newest slider value is sent after it: the
// state follows the thumb without a queue of stale requests.
let inFlight = false;
let wanted = null;
async function seek(k) {
  wanted = k;
  if (inFlight) return;
  inFlight = true;
  try {
    while (wanted !== null) {
      const index = wanted;
      wanted = null;
      try {
        const reply = await post('/api/timeline/seek', { index });
        position = reply.position ?? index;
        isLive = false;
        paused = true; // a seek pauses the simulation
        error.textContent = '';
      } catch (e) {
        error.textContent = e.message;
      }
    }
  } finally {
    inFlight = false;
    paint();
  }
}

slider.addEventListener('input', () => {
  dragging = true;
  label.textContent = describe(Number(slider.value));
  seek(Number(slider.value));
});
slider.addEventListener('change', () => {
  dragging = false;
  seek(Number(slider.value));
});

live.addEventListener('click', async () => {
  try {
    await post('/api/timeline/live', {});
    error.textContent = '';
  } catch (e) {
    error.textContent = e.message;
  }
  reload().catch(() => {});
});

pause.addEventListener('click', async () => {
  try {
    const reply = await post('/api/pause', { paused: !paused });
    paused = !!reply.paused;
    error.textContent = '';
  } catch (e) {
    error.textContent = e.message;
  }
  paint();
});

let timer = null;
on('changes', () => {
  // New entries arrive with the changes; follow them at most twice a second.
  if (timer) return;
  timer = setTimeout(() => {
    timer = null;
    reload().catch((e) => console.error('vsd: timeline', e));
  }, 500);
});
on('writable', paint);

export function current() {
  return { position, first, end, live: isLive, paused };
}
