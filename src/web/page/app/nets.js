// The Nets view: every SOML++ net of /api/nets laid out by elkjs (layered, left to right) and drawn as
// SVG: places as circles with their token counts, transitions as boxes (highlighted when enabled),
// arrows with their weights. A click on a place lists its token objects (links that select them); an
// enabled transition has a Fire button (POST /api/fire) when the page holds the write token.
//
// The marking and the enabled flags can change with any change of the state (conditions read any
// property), so each `changes` batch schedules a refetch of /api/nets, at most a few per second; the
// layout is redone only when the structure (places, transitions, arrows) changed.

import { post, get } from './api.js';
import { on, select, state } from './bus.js';

// The Debug view sets and removes transition breakpoints (loaded on first use, like this view).
const debugView = import('./debug.js');

const SVG = 'http://www.w3.org/2000/svg';
const PLACE = 34;      // circle diameter (px)
const LABEL = 14;      // room for the name under a place
const REFETCH_MS = 250;

const list = document.getElementById('nets-list');
const tokensPanel = document.getElementById('place-tokens');

let nets = [];
let shapeKey = '';             // the structure last laid out
const views = new Map();       // place or transition id -> {kind, group, count?, button?}
let openPlace = null;          // the place whose tokens are listed
let breaks = new Map();        // transition id -> its breakpoint (from the Debug view)
let stoppedAt = null;          // the transition a stop waits before
let elk = null;

function svg(tag, attrs = {}) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  return e;
}

function structure(answer) {
  return JSON.stringify(answer.nets.map((n) => [n.id, n.places.map((p) => p.id),
    n.transitions.map((t) => t.id), n.arrows.map((a) => [a.id, a.from, a.to])]));
}

// elkjs ships no ES module: its bundled UMD build is a classic script that defines window.ELK. It is
// 1.6 MB, so it is loaded when the first net is drawn, not with the page.
let elkLoading = null;
function loadElk() {
  elkLoading ??= new Promise((resolve, reject) => {
    const script = document.createElement('script');
    script.src = '/lib/elkjs/lib/elk.bundled.js';
    script.onload = () => (window.ELK ? resolve() : reject(new Error('elk.bundled.js defined no ELK')));
    script.onerror = () => {
      elkLoading = null;
      reject(new Error('elkjs did not load (/lib/elkjs/lib/elk.bundled.js)'));
    };
    document.head.append(script);
  });
  return elkLoading;
}

async function layout(net) {
  if (!elk) {
    await loadElk();
    elk = new window.ELK();
  }
  const width = (name) => Math.max(48, 8 * String(name).length + 16);
  const graph = {
    id: `net${net.id}`,
    layoutOptions: {
      'elk.algorithm': 'layered',
      'elk.direction': 'RIGHT',
      'elk.spacing.nodeNode': '24',
      'elk.layered.spacing.nodeNodeBetweenLayers': '36',
      'elk.edgeRouting': 'POLYLINE',
    },
    children: [
      ...net.places.map((p) => ({ id: `n${p.id}`, width: Math.max(PLACE, 7 * p.name.length), height: PLACE + LABEL })),
      ...net.transitions.map((t) => ({ id: `n${t.id}`, width: width(t.name), height: 24 })),
    ],
    edges: net.arrows.map((a) => ({ id: `a${a.id}`, sources: [`n${a.from}`], targets: [`n${a.to}`] })),
  };
  return elk.layout(graph);
}

function drawNet(net, laid) {
  const byId = new Map(laid.children.map((c) => [c.id, c]));
  const root = svg('svg', { width: laid.width + 20, height: laid.height + 20, class: 'net-graph' });
  const defs = svg('defs');
  const marker = svg('marker', { id: `arrowhead${net.id}`, viewBox: '0 0 10 10', refX: 10, refY: 5,
                                 markerWidth: 7, markerHeight: 7, orient: 'auto-start-reverse' });
  marker.append(svg('path', { d: 'M0,0 L10,5 L0,10 z', class: 'arrowhead' }));
  defs.append(marker);
  root.append(defs);
  const g = svg('g', { transform: 'translate(10,10)' });
  root.append(g);

  for (const edge of laid.edges || []) {
    const arrow = net.arrows.find((a) => `a${a.id}` === edge.id);
    for (const s of edge.sections || []) {
      const points = [s.startPoint, ...(s.bendPoints || []), s.endPoint];
      g.append(svg('polyline', {
        points: points.map((p) => `${p.x},${p.y}`).join(' '),
        class: `arrow ${arrow?.type || ''}`,
        'marker-end': `url(#arrowhead${net.id})`,
      }));
      if (arrow && arrow.weight > 1) {
        const mid = points[Math.floor(points.length / 2)];
        const label = svg('text', { x: mid.x + 3, y: mid.y - 3, class: 'weight' });
        label.textContent = arrow.weight;
        g.append(label);
      }
    }
  }

  for (const p of net.places) {
    const box = byId.get(`n${p.id}`);
    const group = svg('g', { class: 'place', 'data-id': p.id,
                             transform: `translate(${box.x + box.width / 2},${box.y + PLACE / 2})` });
    group.append(svg('circle', { r: PLACE / 2 }));
    const count = svg('text', { class: 'tokens', 'text-anchor': 'middle', 'dominant-baseline': 'central' });
    const name = svg('text', { class: 'name', 'text-anchor': 'middle', y: PLACE / 2 + 11 });
    name.textContent = p.name;
    group.append(count, name);
    group.addEventListener('click', () => showTokens(p.id));
    g.append(group);
    views.set(p.id, { kind: 'place', group, count });
  }

  for (const t of net.transitions) {
    const box = byId.get(`n${t.id}`);
    const group = svg('g', { class: 'transition', 'data-id': t.id, transform: `translate(${box.x},${box.y})` });
    group.append(svg('rect', { width: box.width, height: box.height, rx: 3 }));
    const name = svg('text', { x: box.width / 2, y: box.height / 2, 'text-anchor': 'middle',
                               'dominant-baseline': 'central' });
    name.textContent = t.name;
    group.append(name);
    group.addEventListener('click', () => select(t.id));
    g.append(group);
    views.set(t.id, { kind: 'transition', group });
  }
  return root;
}

// The list under each graph: one row per transition with its firings and a Fire button.
function transitionRows(net) {
  const table = document.createElement('table');
  table.className = 'transitions';
  for (const t of net.transitions) {
    const tr = document.createElement('tr');
    tr.dataset.id = t.id;
    const name = document.createElement('td');
    name.textContent = t.name;
    const firings = document.createElement('td');
    firings.className = 'firings';
    const cell = document.createElement('td');
    const button = document.createElement('button');
    button.className = 'fire';
    button.textContent = 'Fire';
    const msg = document.createElement('span');
    msg.className = 'msg';
    button.addEventListener('click', async () => {
      try {
        await post('/api/fire', { transition: t.id });
        msg.textContent = '';
      } catch (e) {
        msg.textContent = e.message;
      }
      refetchSoon(0);
    });
    const brk = document.createElement('button');
    brk.className = 'break';
    brk.textContent = 'Break';
    brk.title = 'stop the program before this transition fires (Debug tab)';
    brk.addEventListener('click', async () => (await debugView).toggleTransition(t.id));
    cell.append(button, brk, msg);
    tr.append(name, firings, cell);
    table.append(tr);
    Object.assign(views.get(t.id), { button, brk, firings, row: tr });
  }
  return table;
}

// Counts, enabled flags and Fire buttons from an answer whose structure is already drawn.
function update() {
  for (const net of nets) {
    for (const p of net.places) {
      const v = views.get(p.id);
      if (!v) continue;
      v.count.textContent = p.tokens;
      v.group.classList.toggle('marked', p.tokens > 0);
      v.group.dataset.tokens = p.tokens;
    }
    for (const t of net.transitions) {
      const v = views.get(t.id);
      if (!v) continue;
      v.group.classList.toggle('enabled', !!t.enabled);
      v.row.classList.toggle('enabled', !!t.enabled);
      v.firings.textContent = `${t.firings ?? 0} firings`;
      v.button.disabled = !(t.enabled && state.writable);
      v.brk.disabled = !state.writable;
      v.brk.classList.toggle('on', breaks.has(t.id));
      v.group.classList.toggle('break', breaks.has(t.id));
      v.group.classList.toggle('stopped', stoppedAt === t.id);
    }
  }
  if (openPlace !== null) showTokens(openPlace);
}

function showTokens(placeId) {
  openPlace = placeId;
  const place = nets.flatMap((n) => n.places).find((p) => p.id === placeId);
  tokensPanel.replaceChildren();
  if (!place) return;
  const title = document.createElement('div');
  title.textContent = `${place.name}: ${place.tokens} token${place.tokens === 1 ? '' : 's'}`;
  tokensPanel.append(title);
  const ul = document.createElement('ul');
  for (const id of place.objects || []) {
    const li = document.createElement('li');
    const a = document.createElement('a');
    a.href = `#${id}`;
    a.className = 'ref';
    a.textContent = `@${id}`;
    a.addEventListener('click', (e) => {
      e.preventDefault();
      select(id);
    });
    li.append(a);
    ul.append(li);
  }
  tokensPanel.append(ul);
  for (const g of list.querySelectorAll('.place.open')) g.classList.remove('open');
  views.get(placeId)?.group.classList.add('open');
}

let fetching = null;
let again = false;
export async function reload() {
  // One request at a time; a reload asked for meanwhile runs once it is done.
  if (fetching) {
    again = true;
    return fetching;
  }
  fetching = (async () => {
    const answer = await get('/api/nets');
    nets = answer.nets || [];
    const key = structure(answer);
    if (key !== shapeKey) {
      shapeKey = key;
      views.clear();
      const sections = [];
      for (const net of nets) {
        const section = document.createElement('section');
        section.className = 'net';
        section.dataset.id = net.id;
        const h = document.createElement('h3');
        h.textContent = net.name;
        section.append(h);
        try {
          section.append(drawNet(net, await layout(net)));
        } catch (e) {
          const p = document.createElement('p');
          p.className = 'error-text';
          p.textContent = `layout: ${e.message}`;
          section.append(p);
          // Still give every place and transition a view, so the counts and the buttons work.
          for (const p2 of net.places) views.set(p2.id, { kind: 'place', group: svg('g'), count: svg('text') });
          for (const t of net.transitions) views.set(t.id, { kind: 'transition', group: svg('g') });
        }
        section.append(transitionRows(net));
        sections.push(section);
      }
      if (!nets.length) {
        const p = document.createElement('p');
        p.className = 'hint';
        p.textContent = 'This state has no SOML++ nets.';
        sections.push(p);
      }
      list.replaceChildren(...sections);
    }
    update();
  })();
  try {
    await fetching;
  } finally {
    fetching = null;
    if (again) {
      again = false;
      refetchSoon(0);
    }
  }
}

let timer = null;
function refetchSoon(delay = REFETCH_MS) {
  if (timer && delay) return;
  clearTimeout(timer);
  timer = setTimeout(() => {
    timer = null;
    reload().catch((e) => console.error('vsd: nets', e));
  }, delay);
}

on('changes', () => nets.length && refetchSoon());
on('writable', () => update());
on('breakpoints', (map) => {
  breaks = map;
  update();
});
on('debug', (d) => {
  stoppedAt = d.stopped?.transition?.id ?? null;
  update();
});
