// The Database spanning tree, fetched lazily: a node's children are asked for (/api/children) only
// when it is opened, a page of PAGE at a time, so a state of 100,000 instances costs what is on screen.

import { get } from './api.js';
import { on, select, state } from './bus.js';

const PAGE = 200;

const container = document.getElementById('tree');
// id -> {id, name, class, children, row, list, open, loaded}
const nodes = new Map();
let rootId = null;

function makeRow(item) {
  const li = document.createElement('li');
  li.dataset.id = item.id;
  const row = document.createElement('div');
  row.className = 'tree-row';
  const toggle = document.createElement('span');
  toggle.className = 'toggle';
  const label = document.createElement('span');
  label.className = 'tree-name';
  const cls = document.createElement('span');
  cls.className = 'tree-class';
  const id = document.createElement('span');
  id.className = 'tree-id';
  row.append(toggle, label, cls, id);
  li.append(row);

  const node = { ...item, li, row, toggle, label, cls, idLabel: id, list: null, open: false, loaded: 0 };
  nodes.set(item.id, node);
  paint(node);

  toggle.addEventListener('click', (e) => {
    e.stopPropagation();
    if (node.open) collapse(node);
    else expand(node);
  });
  row.addEventListener('click', () => select(node.id));
  row.addEventListener('dblclick', () => (node.open ? collapse(node) : expand(node)));
  return li;
}

function paint(node) {
  node.toggle.textContent = node.children > 0 ? (node.open ? '▾' : '▸') : '·';
  node.label.textContent = node.name || '(unnamed)';
  node.cls.textContent = node.class;
  node.idLabel.textContent = `#${node.id}`;
  node.row.classList.toggle('selected', state.selected === node.id);
}

// Fetch the next page of a node's children and append them (a "more" row asks for the page after).
async function loadPage(parentId, list, offset) {
  const reply = await get('/api/children', parentId === null ? { offset, limit: PAGE }
                                                             : { id: parentId, offset, limit: PAGE });
  list.querySelector(':scope > li.more')?.remove();
  for (const child of reply.children) {
    if (nodes.has(child.id)) nodes.get(child.id).li.remove();
    list.append(makeRow(child));
  }
  const loaded = offset + reply.children.length;
  if (loaded < reply.total) {
    const more = document.createElement('li');
    more.className = 'more';
    more.textContent = `… ${reply.total - loaded} more`;
    more.addEventListener('click', () => loadPage(parentId, list, loaded));
    list.append(more);
  }
  return { reply, loaded };
}

async function expand(node) {
  if (node.children === 0) return;
  node.open = true;
  if (!node.list) {
    node.list = document.createElement('ul');
    node.li.append(node.list);
  }
  node.list.hidden = false;
  if (!node.loaded) {
    const { reply, loaded } = await loadPage(node.id, node.list, 0);
    node.loaded = loaded;
    node.children = reply.total;
  }
  paint(node);
}

function collapse(node) {
  node.open = false;
  if (node.list) node.list.hidden = true;
  paint(node);
}

// Forget a node's loaded children after creations, deletions and moves under it: an open node fetches
// its first page again, a closed one only its count (for the toggle).
async function refresh(node) {
  if (node.list) {
    for (const li of node.list.querySelectorAll('li[data-id]')) nodes.delete(Number(li.dataset.id));
    node.list.replaceChildren();
  }
  node.loaded = 0;
  if (node.open) {
    const { reply, loaded } = await loadPage(node.id, node.list, 0);
    node.loaded = loaded;
    node.children = reply.total;
  } else {
    const reply = await get('/api/children', { id: node.id, offset: 0, limit: 1 });
    node.children = reply.total;
  }
  paint(node);
}

export async function reload() {
  nodes.clear();
  container.replaceChildren();
  const list = document.createElement('ul');
  list.className = 'tree-root';
  container.append(list);
  const { reply } = await loadPage(null, list, 0);
  rootId = reply.id ?? null;
  if (state.selected !== null) reveal(state.selected);
}

// Open the path down to an instance selected elsewhere (3D pick, a reference link): its ancestors come
// from /api/instance's `parent`, one request per level.
async function reveal(id) {
  if (!nodes.has(id)) {
    const path = [];
    let at = id;
    // No parent is null (or 0, which no instance has).
    for (let guard = 0; guard < 64 && at && !nodes.has(at); ++guard) {
      if (at === rootId) break;
      path.push(at);
      const info = await get('/api/instance', { id: at }).catch(() => null);
      at = info ? info.parent : null;
    }
    if (!at || !nodes.has(at)) return; // not in the tree (an extension, a floating instance)
    for (let i = path.length - 1; i >= 0; --i) {
      const parent = nodes.get(at);
      await expand(parent);
      // The child may sit on a page not loaded yet: load pages until it appears.
      while (!nodes.has(path[i]) && parent.loaded < parent.children) {
        const { loaded } = await loadPage(parent.id, parent.list, parent.loaded);
        parent.loaded = loaded;
      }
      at = path[i];
      if (!nodes.has(at)) return;
    }
  }
  const node = nodes.get(id);
  if (node) {
    paint(node);
    node.row.scrollIntoView({ block: 'nearest' });
  }
}

on('select', (id) => {
  for (const li of container.querySelectorAll('.tree-row.selected')) li.classList.remove('selected');
  reveal(id);
});

on('changes', (batch) => {
  const stale = new Set();
  for (const c of batch.created || []) stale.add(c.parent);
  for (const m of batch.moved || []) {
    stale.add(m.parent);
    const old = nodes.get(m.id);
    if (old) old.li.remove();
  }
  for (const id of batch.deleted || []) {
    const node = nodes.get(id);
    if (node) {
      node.li.remove();
      nodes.delete(id);
    }
  }
  for (const s of batch.set || []) {
    const node = nodes.get(s.id);
    if (node && s.property === 'name') {
      node.name = s.value;
      paint(node);
    }
  }
  for (const parentId of stale) {
    const parent = nodes.get(parentId);
    if (parent) refresh(parent);
    else if (parentId === rootId || parentId === null) reload();
  }
});

