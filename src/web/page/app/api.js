// The HTTP side of the protocol (docs/web.md): reads are plain GETs, writes are POSTs that carry the
// write token in the X-VSD-Token header (never in a URL). The token lives in sessionStorage so that it
// survives a reload of the tab but not the browser session.

const TOKEN_KEY = 'vsd-token';

export function token() {
  return sessionStorage.getItem(TOKEN_KEY) || '';
}

export function setToken(value) {
  if (value) sessionStorage.setItem(TOKEN_KEY, value);
  else sessionStorage.removeItem(TOKEN_KEY);
}

// An error answer of the server: `message` is the server's own text ({"error": ...}), shown to the user
// as it is, because it names the property and the expected type.
export class ApiError extends Error {
  constructor(status, message) {
    super(message);
    this.status = status;
  }
}

async function answer(response) {
  let body = null;
  const text = await response.text();
  try {
    body = text ? JSON.parse(text) : null;
  } catch {
    body = null;
  }
  if (!response.ok) {
    const message = body && typeof body.error === 'string' ? body.error : `${response.status} ${text}`;
    throw new ApiError(response.status, message);
  }
  return body;
}

// The token is sent on reads too: /api/info answers `writable` for the request that asked.
function headers(extra = {}) {
  const h = { ...extra };
  const t = token();
  if (t) h['X-VSD-Token'] = t;
  return h;
}

export async function get(path, params = {}) {
  const query = new URLSearchParams();
  for (const [k, v] of Object.entries(params)) {
    if (v !== undefined && v !== null && v !== '') query.set(k, String(v));
  }
  const qs = query.toString();
  const response = await fetch(qs ? `${path}?${qs}` : path, { headers: headers() });
  return answer(response);
}

export async function post(path, body) {
  const response = await fetch(path, {
    method: 'POST',
    headers: headers({ 'Content-Type': 'application/json' }),
    body: JSON.stringify(body),
  });
  return answer(response);
}
