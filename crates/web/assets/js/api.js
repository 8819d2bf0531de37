// The IDE's API (crates/web/README.md): requests and their JSON answers, and
// the live stream of one module. They go to a target: the server over HTTP
// and a WebSocket (the default), or the playground's modules in the page,
// which answer the same requests with the same JSON (playground.js).

const http = {
  call: httpCall,
  postLines: httpPostLines,
  live: (id, onSample) => new Live(id, onSample),
};
let target = http;

/** Sends every request to `t` from now on: `{call, postLines, live}`. */
export function useTarget(t) {
  target = t;
}

export const call = (method, path, body) => target.call(method, path, body);
export const get = (path) => call("GET", path);
export const post = (path, body) => call("POST", path, body ?? {});
/** POST that answers newline-delimited JSON; `onLine` gets each object. */
export const postLines = (path, body, onLine) => target.postLines(path, body, onLine);
/** The live stream of module `id`: `{subscribe(sub), close()}`. */
export const openLive = (id, onSample) => target.live(id, onSample);

async function httpCall(method, path, body) {
  const init = { method, headers: {} };
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  let r;
  try {
    r = await fetch(path, init);
  } catch (e) {
    return { error: unreachable(e) };
  }
  let data;
  try {
    data = await r.json();
  } catch {
    data = { error: `HTTP ${r.status}` };
  }
  if (!r.ok && !data.error) data.error = `HTTP ${r.status}`;
  return data;
}

/** What a request that got no answer at all says (the server stopped, or
 * the network failed): an answer like any other error. */
function unreachable(e) {
  return `no answer from the server (${e.message})`;
}

async function httpPostLines(path, body, onLine) {
  const failed = (e) => {
    const last = { error: unreachable(e) };
    onLine(last);
    return last;
  };
  let r;
  try {
    r = await fetch(path, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
  } catch (e) {
    return failed(e);
  }
  const reader = r.body.getReader();
  const decoder = new TextDecoder();
  let buffer = "";
  let last = null;
  for (;;) {
    let chunk;
    try {
      chunk = await reader.read();
    } catch (e) {
      return failed(e);
    }
    const { value, done } = chunk;
    if (done) break;
    buffer += decoder.decode(value, { stream: true });
    let nl;
    while ((nl = buffer.indexOf("\n")) >= 0) {
      const line = buffer.slice(0, nl).trim();
      buffer = buffer.slice(nl + 1);
      if (line) {
        last = JSON.parse(line);
        onLine(last);
      }
    }
  }
  if (buffer.trim()) {
    last = JSON.parse(buffer);
    onLine(last);
  }
  return last;
}

/** The live stream of module `id`: `subscribe(sub)` (re)sends the
 * subscription, `onSample` gets every message. */
class Live {
  constructor(id, onSample) {
    this.id = id;
    this.onSample = onSample;
    this.sub = { signals: [], rate: 50, program: false };
    this.closed = false;
    this.open();
  }
  open() {
    const proto = location.protocol === "https:" ? "wss" : "ws";
    this.ws = new WebSocket(`${proto}://${location.host}/api/modules/${this.id}/live`);
    this.ws.onopen = () => this.ws.send(JSON.stringify(this.sub));
    this.ws.onmessage = (e) => this.onSample(JSON.parse(e.data));
    this.ws.onclose = () => {
      if (!this.closed) setTimeout(() => this.open(), 1000);
    };
  }
  subscribe(sub) {
    this.sub = { ...this.sub, ...sub };
    if (this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(this.sub));
  }
  close() {
    this.closed = true;
    this.ws.close();
  }
}

export const m = (id, rest) => `/api/modules/${id}/${rest}`;

export function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "class") e.className = v;
    else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else if (k === "text") e.textContent = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

/** Fills a motor selector with the module's axes (one without a profile). */
export function axisOptions(select, profile) {
  const axes = profile ? profile.axes : 1;
  select.replaceChildren(...Array.from({ length: axes }, (_, i) => el("option", { value: String(i), text: String(i) })));
}

// The module has one selected motor: every panel's motor selector shows
// it, and choosing another in one panel chooses it in all.
const motorSelectors = new Map();

/** Links `select` to the selected motor; `onChange` runs when it changes. */
export function motorSelector(select, onChange) {
  motorSelectors.set(select, onChange);
  select.addEventListener("change", () => chooseMotor(select.value));
}

/** Chooses motor `value` in every panel. */
export function chooseMotor(value) {
  for (const [select, onChange] of motorSelectors) {
    select.value = value;
    onChange();
  }
}

/** Saves `blob` as the file `name` (a download). */
export function download(blob, name) {
  const a = el("a", { href: URL.createObjectURL(blob), download: name });
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}
