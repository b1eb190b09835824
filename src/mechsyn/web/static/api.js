// Talking to the mechsyn studio server: the per-launch token and JSON requests.
export const token = new URLSearchParams(location.search).get("token") || "";

// How requests travel: HTTP to the studio server, or (notebook widget) messages to the kernel.
export const transport = { events: true, request: null };
export function useTransport(t) { Object.assign(transport, t); }

export async function call(path, body = undefined, { method, raw = false, blob = false } = {}) {
  if (transport.request) return transport.request(path, method || (body === undefined ? "GET" : "POST"), body, raw || blob);
  const opts = { method: method || (body === undefined ? "GET" : "POST"), headers: { "X-Mechsyn-Token": token } };
  if (body !== undefined) {
    opts.headers["Content-Type"] = "application/json";
    opts.body = JSON.stringify(body);
  }
  let resp;
  try {
    resp = await fetch(path, opts);
  } catch (e) {
    throw { error: "the server does not answer (is `mechsyn serve` still running?)" };
  }
  if (blob && resp.ok) return resp.blob();
  if (raw && resp.ok) return resp.text();
  let data;
  try { data = await resp.json(); } catch (e) { data = { error: `HTTP ${resp.status}` }; }
  if (!resp.ok) throw data;
  return data;
}

// A requester that keeps at most one request in flight: while one runs, only the
// latest new argument is kept and sent when it returns (drag events coalesce).
export function coalescing(send, onResult, onError) {
  let busy = false, pending = null, hasPending = false;
  async function run(arg) {
    busy = true;
    try { onResult(await send(arg), arg); } catch (e) { onError(e, arg); }
    busy = false;
    if (hasPending) { const next = pending; pending = null; hasPending = false; run(next); }
  }
  return (arg) => { if (busy) { pending = arg; hasPending = true; } else run(arg); };
}

export function eventsUrl(job) { return `/api/jobs/${job}/events?token=${encodeURIComponent(token)}`; }
