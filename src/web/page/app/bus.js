// What the views share: the selected instance, whether this page may write, and the server's events.
// Views subscribe by name instead of calling each other, so each view stays one small module.

const listeners = new Map();

export function on(name, fn) {
  if (!listeners.has(name)) listeners.set(name, []);
  listeners.get(name).push(fn);
}

export function emit(name, payload) {
  for (const fn of listeners.get(name) || []) {
    try {
      fn(payload);
    } catch (e) {
      // One broken view must not stop the others from hearing the event.
      console.error(`vsd: a '${name}' listener failed`, e);
    }
  }
}

export const state = {
  selected: null,     // id of the selected instance, or null
  writable: false,    // /api/info said the token is right
  classes: new Map(), // name -> class from /api/classes
};

// Selecting is idempotent: the tree, the table, the 3D view and reference links all call it.
export function select(id) {
  if (id === null || id === undefined) return;
  id = Number(id);
  if (state.selected === id) return;
  state.selected = id;
  emit('select', id);
}

export function setWritable(writable) {
  if (state.writable === !!writable) return; // the views re-render their controls only on a change
  state.writable = !!writable;
  document.body.classList.toggle('writable', state.writable);
  emit('writable', state.writable);
}

// Whether class `name` is `base` or derives from it, by the bases of /api/classes (a script class that
// derives from scene::Node3D is drawn like a Node3D).
export function isA(name, base) {
  for (let c = name, guard = 0; c && guard < 64; ++guard) {
    if (c === base) return true;
    c = state.classes.get(c)?.base;
  }
  return false;
}

// Parse what the user typed into a value field: JSON where it is JSON (numbers, vectors, frames,
// booleans, null), else the text itself as a string (enum names, "@42" references, free text). The
// server checks the type and answers with a message that names the property and the expected type, so
// the page does not second-guess it.
export function parseInput(text, type) {
  if (type === 'string') return text;
  const trimmed = text.trim();
  try {
    return JSON.parse(trimmed);
  } catch {
    return trimmed;
  }
}

// The text a value is shown and edited as: the inverse of parseInput.
export function formatValue(value, type) {
  if (type === 'string' && typeof value === 'string') return value;
  if (typeof value === 'string') return value;
  return JSON.stringify(value);
}

const NUMERIC = /^(u?int(8|16|32|64)|float|double|bool)$/;
export function isNumericType(type) {
  return NUMERIC.test(type);
}
