// The playground: the IDE against virtual modules living in the page (the
// WebAssembly build of tmclsim, tmclsim.js), with no server. The page's
// requests go to the binding's Playground, which answers them as the server
// does; virtual time follows the wall clock. scripts/playground builds the
// page (docs/playground.md).
import init, * as tmclsim from "../tmclsim.js";
import { useTarget } from "./api.js";

// Virtual time moves with the wall clock, at most this much at once: a tab
// in the background (timers slowed down) loses time rather than catching
// up in one leap.
const MAX_STEP_S = 0.25;

// `?speed=N`: virtual time runs N times as fast as the wall clock, as with
// `tmclsim serve --speed N`; a value the binding refuses is said in the
// page, and time keeps the wall clock's pace.
const speedParam = new URLSearchParams(location.search).get("speed");
let speedRefused = null;

// The WebAssembly loads while the app's modules do; requests wait for it.
let page = null;
const loaded = init().then(() => {
  window.tmclsim = tmclsim;
  page = new tmclsim.Playground();
  window.tmclsimPage = page;
  if (speedParam !== null) {
    try {
      page.setSpeed(Number(speedParam));
    } catch (e) {
      speedRefused = `?speed=${speedParam}: ${e.message ?? e}`;
    }
  }
  page.request("POST", "/api/modules", JSON.stringify({ profile: "tmcm-1141" }));
  let last = performance.now();
  setInterval(() => {
    const now = performance.now();
    page.advanceWall(Math.min(MAX_STEP_S, (now - last) / 1000));
    last = now;
  }, 10);
});

async function ask(method, path, body) {
  await loaded;
  return JSON.parse(page.request(method, path, body === undefined ? "" : JSON.stringify(body)));
}

/** The live stream of module `id`: a sample at the subscription's rate. */
class PageLive {
  constructor(id, onSample) {
    this.id = id;
    this.onSample = onSample;
    this.sub = { signals: [], rate: 50, program: false };
    this.restart();
  }
  restart() {
    clearInterval(this.timer);
    const hz = Math.min(100, Math.max(1, this.sub.rate || 20));
    this.timer = setInterval(() => {
      if (page && (this.sub.signals.length || this.sub.program)) this.onSample(JSON.parse(page.sample(this.id, JSON.stringify(this.sub))));
    }, 1000 / hz);
  }
  subscribe(sub) {
    this.sub = { ...this.sub, ...sub };
    this.restart();
  }
  close() {
    clearInterval(this.timer);
  }
}

useTarget({
  call: ask,
  // A download's progress lines come as one array.
  postLines: async (path, body, onLine) => {
    const answer = await ask("POST", path, body);
    const lines = Array.isArray(answer) ? answer : [answer];
    lines.forEach(onLine);
    return lines[lines.length - 1];
  },
  live: (id, onSample) => new PageLive(id, onSample),
});

await import("./app.js");
await loaded;
if (speedRefused) {
  const notice = document.createElement("p");
  notice.className = "notice";
  notice.dataset.testid = "notice";
  notice.textContent = speedRefused;
  document.querySelector("header").append(notice);
}
