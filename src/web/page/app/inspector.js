// The inspector: every property of the selected instance with its type and flags (/api/instance),
// generated from the meta-information. Editable properties get an input when the page holds the write
// token; a value goes to POST /api/set as typed and the server checks it: on an error its message is
// shown next to the field and the shown value stays what the database holds. References are links that
// select their target. Methods get a call button with one input per parameter (/api/call).

import { get, post } from './api.js';
import { emit, formatValue, isNumericType, on, parseInput, select, state } from './bus.js';

const root = document.getElementById('inspector');
let current = null; // the /api/instance answer shown
let loading = 0;

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v;
    else if (k in e) e[k] = v;
    else e.setAttribute(k, v);
  }
  e.append(...children.filter((c) => c !== null && c !== undefined));
  return e;
}

// A read-only value of up to 64 KiB of text would fill the panel: the first 2,000 characters show.
function shorten(text) {
  return text.length > 2000 ? `${text.slice(0, 2000)} … (${text.length} characters)` : text;
}

function refLink(ref) {
  if (ref === null || ref === undefined) return el('span', { class: 'null' }, 'null');
  const id = Number(String(ref).replace(/^@/, ''));
  const a = el('a', { href: `#${id}`, class: 'ref' }, `@${id}`);
  a.addEventListener('click', (e) => {
    e.preventDefault();
    select(id);
  });
  return a;
}

function refLinks(value) {
  if (Array.isArray(value)) {
    const span = el('span', { class: 'refs' });
    value.forEach((r, i) => span.append(...(i ? [' ', refLink(r)] : [refLink(r)])));
    if (!value.length) span.append('[]');
    return span;
  }
  return refLink(value);
}

// The editor of one property: a checkbox for bool, x/y/z inputs for a frame's translation (with its
// rotation as JSON), a text input for everything else. `read()` gives the value to send, `show(v)`
// puts a value from the server into the inputs.
function editor(p, commit) {
  const enabled = p.editable && state.writable;
  if (p.type === 'bool') {
    const box = el('input', { type: 'checkbox', checked: !!p.value, disabled: !enabled, class: 'value-input' });
    box.addEventListener('change', commit);
    return { node: box, read: () => box.checked, show: (v) => (box.checked = !!v), inputs: [box] };
  }
  if (Array.isArray(p.enum) && p.enum.length && typeof p.value === 'string') {
    // An enum whose names the server listed: a choice among them.
    const choice = el('select', { class: 'value-input', disabled: !enabled });
    for (const name of p.enum) choice.append(el('option', { value: name }, name));
    choice.value = p.value;
    choice.addEventListener('change', commit);
    return { node: choice, read: () => choice.value, show: (v) => (choice.value = v), inputs: [choice] };
  }
  if (p.type === 'Isometry3d' && p.value && Array.isArray(p.value.translation)) {
    const axes = ['x', 'y', 'z'].map((a) =>
      el('input', { class: `value-input t${a}`, size: 7, disabled: !enabled, title: `translation ${a}` }));
    const rotation = el('input', { class: 'value-input rotation', size: 14, disabled: !enabled,
                                   title: 'rotation: a 3×3 matrix as rows, or a quaternion [w, x, y, z]' });
    const show = (v) => {
      axes.forEach((input, i) => (input.value = formatValue(v.translation[i])));
      rotation.value = JSON.stringify(v.rotation);
    };
    show(p.value);
    for (const input of [...axes, rotation]) {
      input.addEventListener('keydown', (e) => e.key === 'Enter' && commit());
    }
    return {
      node: el('span', { class: 'frame-editor' }, 't ', ...axes, ' R ', rotation),
      read: () => ({ translation: axes.map((a) => parseInput(a.value, 'double')),
                     rotation: parseInput(rotation.value, 'json') }),
      show,
      inputs: [...axes, rotation],
    };
  }
  const input = el('input', { class: 'value-input', disabled: !enabled, size: 12 });
  input.value = formatValue(p.value, p.type);
  input.addEventListener('keydown', (e) => e.key === 'Enter' && commit());
  return { node: input, read: () => parseInput(input.value, p.type),
           show: (v) => (input.value = formatValue(v, p.type)), inputs: [input] };
}

function propertyRow(p) {
  const msg = el('span', { class: 'msg' });
  const tr = el('tr', { 'data-property': p.name });
  const head = el('th', {}, p.name, el('small', {}, ` ${p.type}`),
                  p.flags?.length ? el('small', { class: 'flags' }, ` ${p.flags.join(' ')}`) : null);
  const cell = el('td', { class: 'value' });
  let ed = null;

  async function commit() {
    const value = ed.read();
    tr.classList.add('pending');
    try {
      const reply = await post('/api/set', { id: current.id, property: p.name, value });
      msg.textContent = '';
      tr.classList.remove('error');
      p.value = reply.value;
      ed.show(reply.value);
      emit('edited', { id: current.id, property: p.name, value: reply.value });
    } catch (e) {
      // Nothing changed in the database: show why, keep what the user typed so it can be fixed.
      msg.textContent = e.message;
      tr.classList.add('error');
    } finally {
      tr.classList.remove('pending');
    }
  }

  if (p.truncated) {
    // Over 64 KiB of text (a mesh's vertices): the server sends null, and an edit would overwrite it.
    cell.append(el('span', { class: 'null' }, 'too long to show (over 64 KiB)'));
  } else if (p.kind === 'ref' || p.kind === 'list') {
    cell.append(refLinks(p.value));
    if (p.editable && p.kind === 'ref') {
      ed = editor({ ...p, value: p.value === null ? 'null' : p.value }, commit);
      cell.append(' ', ed.node);
    }
  } else if (p.editable) {
    ed = editor(p, commit);
    cell.append(ed.node);
  } else {
    cell.append(el('span', { class: 'readonly-value' }, shorten(formatValue(p.value, p.type))));
  }
  if (ed) {
    const set = el('button', { class: 'set', disabled: !state.writable, title: 'POST /api/set' }, 'set');
    set.addEventListener('click', commit);
    if (p.type !== 'bool' && !(ed.node.tagName === 'SELECT')) cell.append(set);
    ed.inputs.push(set);
  }
  if (isNumericType(p.type) && p.kind === 'value') {
    const plot = el('button', { class: 'plot', title: 'plot this property live' }, '∿');
    plot.addEventListener('click', () =>
      emit('plot', { id: current.id, property: p.name, label: `${current.name || '#' + current.id}.${p.name}` }));
    cell.append(plot);
  }
  cell.append(msg);
  tr.append(head, cell);
  tr.vsd = { p, ed, cell, msg };
  return tr;
}

function methodRow(m) {
  const args = (m.params || []).map((param) =>
    el('input', { class: 'arg', placeholder: `${param.name}: ${param.type}`, size: 10, 'data-type': param.type }));
  const call = el('button', { class: 'call', disabled: !state.writable }, 'call');
  const out = el('span', { class: 'msg' });
  call.addEventListener('click', async () => {
    try {
      const reply = await post('/api/call', {
        id: current.id, method: m.name,
        args: args.map((a) => parseInput(a.value, a.dataset.type)),
      });
      out.textContent = m.result && m.result !== 'void' ? `→ ${formatValue(reply.result)}` : '✓';
      out.classList.remove('error-text');
    } catch (e) {
      out.textContent = e.message;
      out.classList.add('error-text');
    }
  });
  const sig = `${m.result || 'void'} ${m.name}(${(m.params || []).map((a) => `${a.type} ${a.name}`).join(', ')})`;
  return el('tr', { 'data-method': m.name }, el('th', {}, el('code', {}, sig)), el('td', {}, ...args, call, out));
}

function render(info) {
  current = info;
  const props = el('table', { class: 'props' }, ...info.properties.map(propertyRow));
  const parent = info.parent !== null && info.parent !== undefined
    ? el('div', { class: 'parent' }, 'parent ', refLink(info.parent)) : null;
  const methods = info.methods?.length
    ? [el('h3', {}, 'Methods'), el('table', { class: 'methods' }, ...info.methods.map(methodRow))] : [];
  root.replaceChildren(
    el('h2', {}, info.name || '(unnamed)', el('small', {}, ` ${info.class} #${info.id}`)),
    parent, props, ...methods);
  root.dataset.id = info.id;
}

export async function show(id) {
  const mine = ++loading;
  try {
    const info = await get('/api/instance', { id });
    if (mine === loading) render(info);
  } catch (e) {
    if (mine === loading) {
      current = null;
      root.replaceChildren(el('p', { class: 'error-text' }, `#${id}: ${e.message}`));
    }
  }
}

on('select', (id) => show(id));
on('writable', () => current && show(current.id));

// Follow the changes of the instance shown; a field the user is typing in is left alone.
on('changes', (batch) => {
  if (!current) return;
  if ((batch.deleted || []).includes(current.id)) {
    root.prepend(el('p', { class: 'error-text' }, 'deleted'));
    return;
  }
  for (const s of batch.set || []) {
    if (s.id !== current.id) continue;
    const tr = root.querySelector(`tr[data-property="${CSS.escape(s.property)}"]`);
    if (!tr || !tr.vsd) continue;
    const { p, ed, cell, msg } = tr.vsd;
    if (p.truncated || s.truncated) continue; // shown as too long; nothing to update
    p.value = s.value;
    // The field now shows what the database holds: an earlier refusal no longer applies to it.
    if (ed && !ed.inputs.includes(document.activeElement)) {
      msg.textContent = '';
      tr.classList.remove('error');
    }
    if (p.kind === 'ref' || p.kind === 'list') {
      cell.firstChild.replaceWith(refLinks(s.value));
      if (ed && !ed.inputs.includes(document.activeElement)) ed.show(s.value === null ? 'null' : s.value);
    } else if (ed) {
      if (!ed.inputs.includes(document.activeElement)) ed.show(s.value);
    } else {
      cell.firstChild.textContent = shorten(formatValue(s.value, p.type));
    }
  }
});
