// The per-class table (the paper's "table based manner"): the instances of a class and its subclasses
// from /api/table, filtered by a `where` expression. Virtual scrolling: the scroller is as tall as all
// rows, but only the rows in view (plus a margin) are fetched and in the DOM, so 100,000 instances
// cost one request of ~60 rows per scroll stop. The Columns chooser picks the property columns per class
// (the server's default: the class's first twelve plain values).

import { get } from './api.js';
import { on, select, state, formatValue } from './bus.js';

const ROW = 22;      // px; fixed so that a row's position is its index times ROW
const MARGIN = 20;   // rows fetched above and below the visible ones
const MAX_PX = 1.5e7; // browsers cap element heights (~3.3e7 px in Chromium); scale beyond this

const classSelect = document.getElementById('table-class');
const filter = document.getElementById('table-filter');
const totalLabel = document.getElementById('table-total');
const errorLabel = document.getElementById('table-error');
const scroller = document.getElementById('table-scroll');
const sizer = document.getElementById('table-sizer');
const table = document.getElementById('table-rows');
const headBox = document.getElementById('table-head');
const header = document.getElementById('table-header');
const columnsList = document.getElementById('table-columns-list');
let columns = [];
const chosen = new Map();   // class -> the property columns the user picked, in the class's order
let choicesFor = null;      // the class the chooser lists

let total = 0;
let shown = { offset: -1, count: 0 }; // the window of rows in the DOM
let request = 0;                      // only the newest request's answer is drawn
let timer = null;

// Row i sits at i * ROW * scale; the scale is < 1 only for tables too tall for the browser.
function scale() {
  return total * ROW > MAX_PX ? MAX_PX / (total * ROW) : 1;
}

export function fillClasses(classes) {
  const keep = classSelect.value;
  classSelect.replaceChildren();
  for (const c of [...classes].sort((a, b) => a.name.localeCompare(b.name))) {
    const option = document.createElement('option');
    option.value = c.name;
    option.textContent = `${c.name} (${c.count})`;
    classSelect.append(option);
  }
  if (keep && classes.some((c) => c.name === keep)) classSelect.value = keep;
  else if (classes.some((c) => c.name === 'Node')) classSelect.value = 'Node';
  restart();
}

function restart() {
  choicesFor = null;
  total = 0;
  shown = { offset: -1, count: 0 };
  scroller.scrollTop = 0;
  fetchWindow(true);
}

function wanted() {
  const s = scale();
  const first = Math.floor(scroller.scrollTop / (ROW * s));
  const visible = Math.ceil(scroller.clientHeight / ROW) + 1;
  const offset = Math.max(0, first - MARGIN);
  return { offset, count: visible + 2 * MARGIN, first };
}

async function fetchWindow(force = false) {
  if (!classSelect.value) return;
  const w = wanted();
  // Still inside what is drawn: nothing to fetch.
  if (!force && w.first >= shown.offset && w.first + w.count - 2 * MARGIN <= shown.offset + shown.count) return;
  const mine = ++request;
  try {
    const picked = chosen.get(classSelect.value);
    const reply = await get('/api/table', {
      class: classSelect.value, offset: w.offset, limit: w.count, where: filter.value.trim(),
      // `name` alone when none is picked: it is always shown, so no property column appears.
      columns: picked ? (picked.length ? picked.join(',') : 'name') : undefined,
    });
    if (mine !== request) return; // the user scrolled on; a newer request will draw
    errorLabel.textContent = '';
    filter.classList.remove('error');
    total = reply.total;
    totalLabel.textContent = `${total} rows`;
    sizer.style.height = `${total * ROW * scale()}px`;
    draw(reply);
  } catch (e) {
    if (mine !== request) return;
    // A bad filter: the server's message says what and where.
    errorLabel.textContent = e.message;
    filter.classList.add('error');
  }
}

// One checkbox per property of the class (name is always shown), ticked as the answer's columns are.
function fillChoices(reply) {
  if (choicesFor === reply.class) return;
  choicesFor = reply.class;
  const properties = (state.classes.get(reply.class)?.properties || []).filter((p) => p.name !== 'name');
  columnsList.replaceChildren(...properties.map((p) => {
    const label = document.createElement('label');
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.value = p.name;
    box.checked = reply.columns.includes(p.name);
    box.addEventListener('change', () => {
      chosen.set(reply.class, [...columnsList.querySelectorAll('input:checked')].map((b) => b.value));
      fetchWindow(true);
    });
    label.append(box, ` ${p.name}`);
    label.title = p.type;
    return label;
  }));
}

function draw(reply) {
  fillChoices(reply);
  const s = scale();
  shown = { offset: reply.offset, count: reply.rows.length };
  table.style.transform = `translateY(${reply.offset * ROW * s}px)`;
  // The header is a table of its own above the scroller (so it stays in view); both tables have fixed
  // column widths, so their columns line up.
  // id, name and class come with every row; the property columns follow (without name, shown already).
  const values = reply.columns.filter((c) => c !== 'name');
  const withClass = reply.rows.some((r) => r.class !== undefined);
  columns = ['id', 'name', ...(withClass ? ['class'] : []), ...values];
  const widths = columns.map((c, i) => (i === 0 ? 70 : i === 1 ? 140 : 110));
  const colgroup = () => {
    const g = document.createElement('colgroup');
    for (const w of widths) {
      const col = document.createElement('col');
      col.style.width = `${w}px`;
      g.append(col);
    }
    return g;
  };
  const width = `${widths.reduce((a, b) => a + b, 0)}px`;
  const head = document.createElement('tr');
  for (const name of columns) {
    const th = document.createElement('th');
    th.textContent = name;
    th.title = name;
    head.append(th);
  }
  header.replaceChildren(colgroup(), head);
  header.style.width = width;
  table.style.width = width;
  const rows = [colgroup()];
  for (const r of reply.rows) {
    const tr = document.createElement('tr');
    tr.dataset.id = r.id;
    if (state.selected === r.id) tr.classList.add('selected');
    const cells = [`#${r.id}`, r.name, ...(withClass ? [r.class] : []), ...values.map((c) => formatValue(r.values?.[c]))];
    for (const text of cells) {
      const td = document.createElement('td');
      td.textContent = text === undefined ? '' : String(text).slice(0, 80);
      td.title = td.textContent;
      tr.append(td);
    }
    tr.addEventListener('click', () => select(r.id));
    rows.push(tr);
  }
  table.replaceChildren(...rows);
}

scroller.addEventListener('scroll', () => {
  headBox.scrollLeft = scroller.scrollLeft;
  // Fetch when the scrolling pauses, not on every scroll event: a fling across 100,000 rows then
  // costs one request.
  clearTimeout(timer);
  timer = setTimeout(() => fetchWindow(), 60);
});
classSelect.addEventListener('change', restart);
// 'change' fires on Enter and when the box loses the focus with a new text.
filter.addEventListener('change', restart);

on('select', (id) => {
  for (const tr of table.querySelectorAll('tr.selected')) tr.classList.remove('selected');
  table.querySelector(`tr[data-id="${id}"]`)?.classList.add('selected');
});

// Values in view follow the changes; rows come and go only on the next fetch.
on('changes', (batch) => {
  if (batch.created?.length || batch.deleted?.length) {
    fetchWindow(true);
    return;
  }
  for (const s of batch.set || []) {
    const tr = table.querySelector(`tr[data-id="${s.id}"]`);
    if (!tr) continue;
    const i = columns.indexOf(s.property);
    if (i >= 0) tr.children[i].textContent = String(formatValue(s.value)).slice(0, 80);
  }
});

export function refetch() {
  fetchWindow(true);
}
