// The server's push stream (docs/web.md, "Events"): hello, changes, stats, debug, trace, resync. Each event is
// re-emitted on the bus; `hello` and `resync` both mean "fetch everything again" ('reload'), because a
// late client starts from a snapshot and a client that fell behind lost the dropped batches.

import { emit } from './bus.js';

let source = null;
let lastSeq = 0;

function parse(event) {
  try {
    return JSON.parse(event.data);
  } catch (e) {
    console.error('vsd: an event that is not JSON', event.type, event.data);
    return null;
  }
}

export function connect() {
  if (source) source.close();
  source = new EventSource('/api/events');

  const handlers = {
    hello(hello) {
      lastSeq = hello.seq ?? 0;
      emit('connected', true);
      emit('hello', hello);
      emit('reload', { reason: 'hello' });
    },
    changes(batch) {
      lastSeq = batch.seq ?? lastSeq;
      emit('changes', batch);
    },
    stats(stats) {
      emit('stats', stats);
    },
    debug(d) {
      emit('debug', d);
    },
    trace(t) {
      emit('trace', t);
    },
    resync(why) {
      emit('reload', { reason: why.reason || 'resync' });
    },
  };
  // Events are named (`event: changes`); an unnamed event that says its kind in a "type" member is
  // taken too, so the page does not depend on which of the two the server writes.
  for (const [name, handle] of Object.entries(handlers)) {
    source.addEventListener(name, (event) => {
      const data = parse(event);
      if (data) handle(data);
    });
  }
  source.addEventListener('message', (event) => {
    const data = parse(event);
    const handle = data && handlers[data.type];
    if (handle) handle(data);
  });

  // EventSource reconnects by itself; the server then sends a new hello, which reloads the views.
  source.onerror = () => emit('connected', false);
}

export function sequence() {
  return lastSeq;
}
