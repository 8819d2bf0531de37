// The browser IDE: the module list on the left, one panel per tab. Every
// command is a TMCL request through the target (api.js: the server, or the
// playground's modules in the page).
import { get, openLive } from "./api.js";
import { moduleList, scanButton, addButton } from "./modules.js";
import { DirectPanel } from "./direct.js";
import { ParamsPanel } from "./params.js";
import { MotionPanel } from "./motion.js";
import { ChartsPanel } from "./charts.js";
import { IoPanel } from "./io.js";
import { ProgramPanel } from "./program.js";
import { WorldPanel } from "./world.js";
import { ToolsPanel } from "./tools.js";
import { unitControls, showModule } from "./units.js";

const panels = {
  direct: new DirectPanel(),
  params: new ParamsPanel(),
  motion: new MotionPanel(),
  charts: new ChartsPanel(),
  io: new IoPanel(),
  program: new ProgramPanel(),
  tools: new ToolsPanel(),
  world: new WorldPanel(),
};
// Read by the tests.
window.tmclsimCharts = panels.charts;
window.tmclsimTools = panels.tools;
window.tmclsimProgram = panels.program;
let active = "direct";
let live = null;
// Per subscription id: which panel's signals are where in a sample.
const layouts = new Map();
let subscription = 0;

function resubscribe(ctx) {
  // Every panel's signals in one subscription, each signal read once; each
  // panel gets its own back, with the signals it asked for then.
  const parts = [];
  const signals = [];
  const at = new Map();
  for (const [name, p] of Object.entries(panels)) {
    const asked = p.signals ? p.signals() : [];
    const indices = asked.map((x) => {
      const key = `${x.kind}:${x.index}:${x.number}`;
      if (!at.has(key)) {
        at.set(key, signals.length);
        signals.push(x);
      }
      return at.get(key);
    });
    parts.push({ name, indices, signals: asked });
  }
  subscription += 1;
  layouts.set(subscription, parts);
  live.subscribe({ signals, rate: panels.charts.rate(), program: active === "program", id: subscription });
}

function onSample(msg) {
  const parts = layouts.get(msg.sub);
  if (msg.error || !parts) return;
  // Samples of older subscriptions will not come any more.
  for (const id of layouts.keys()) if (id < msg.sub) layouts.delete(id);
  for (const { name, indices, signals } of parts) {
    const p = panels[name];
    if (p.onSample) p.onSample(msg.t, indices.map((i) => msg.values[i]), msg, signals);
  }
}

let picks = 0;
async function pick(modules, info, id) {
  const mod = modules[id];
  const mine = ++picks;
  const profile = mod.profile ? await get(`/api/modules/${id}/profile`) : null;
  // A later pick wins, whichever profile arrives first.
  if (mine !== picks) return;
  if (live) live.close();
  const ctx = { id, module: mod, profile, info, virtual: mod.virtual, resubscribe: () => resubscribe(ctx) };
  showModule(profile);
  for (const p of Object.values(panels)) p.setModule(ctx);
  // The title names the module the panels now act on: a command typed as
  // soon as it shows goes to that module.
  document.getElementById("module-title").textContent = mod.bootloader
    ? `${mod.profile ?? "unknown type"} · in its bootloader (${mod.bootloader}): a firmware update did not complete; the tools are off until one does`
    : `${mod.profile ?? "unknown type"} · address ${mod.address} · ${mod.firmware}`;
  live = openLive(id, onSample);
  resubscribe(ctx);
  window.tmclsimReady = true;
}

async function main() {
  unitControls(document.getElementById("units"), document.getElementById("fullsteps"));
  const info = await get("/api/info");
  // Virtual time that fell behind its speed runs as fast as the modules
  // can compute it (docs/behaviour.md rule 119).
  const behind = info.behind ? " (behind: the modules cannot keep up)" : "";
  const speed = info.speed && info.speed !== 1 ? ` · time ×${info.speed}${behind}` : "";
  document.getElementById("target").textContent = `${info.target === "virtual" ? "virtual modules" : "TMCL link"} · ${info.link}${speed}`;
  let modules = await get("/api/modules");
  let ctxRef = null;
  for (const b of document.querySelectorAll("#tabs button")) {
    b.addEventListener("click", () => {
      active = b.dataset.tab;
      for (const x of document.querySelectorAll("#tabs button")) x.classList.toggle("active", x === b);
      for (const s of document.querySelectorAll(".panel")) s.classList.toggle("active", s.id === `panel-${active}`);
      for (const [name, p] of Object.entries(panels)) if (p.shown) p.shown(name === active);
      if (live) resubscribe(ctxRef);
    });
  }
  const list = moduleList(modules, (id) => pick(modules, info, id));
  scanButton(info);
  addButton(info, async (id) => {
    modules = await get("/api/modules");
    list.update(modules, id);
    await pick(modules, info, id);
  });
  if (modules.length) await pick(modules, info, 0);
}

main();
