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

const panels = {
  direct: new DirectPanel(),
  params: new ParamsPanel(),
  motion: new MotionPanel(),
  charts: new ChartsPanel(),
  io: new IoPanel(),
  program: new ProgramPanel(),
  world: new WorldPanel(),
};
let active = "direct";
let live = null;
let parts = [];

function resubscribe(ctx) {
  // Every panel's signals in one subscription; each gets its slice back.
  parts = [];
  const signals = [];
  for (const [name, p] of Object.entries(panels)) {
    const s = p.signals ? p.signals() : [];
    parts.push([name, signals.length, s.length]);
    signals.push(...s);
  }
  live.subscribe({ signals, rate: panels.charts.rate(), program: active === "program" });
}

function onSample(msg) {
  if (msg.error) return;
  for (const [name, start, n] of parts) {
    const p = panels[name];
    if (p.onSample) p.onSample(msg.t, msg.values.slice(start, start + n), msg);
  }
}

async function pick(modules, info, id) {
  const mod = modules[id];
  document.getElementById("module-title").textContent = `${mod.profile ?? "unknown type"} · address ${mod.address} · ${mod.firmware}`;
  const profile = mod.profile ? await get(`/api/modules/${id}/profile`) : null;
  if (live) live.close();
  const ctx = { id, module: mod, profile, info, virtual: mod.virtual, resubscribe: () => resubscribe(ctx) };
  for (const p of Object.values(panels)) p.setModule(ctx);
  live = openLive(id, onSample);
  resubscribe(ctx);
  window.tmclsimReady = true;
}

async function main() {
  const info = await get("/api/info");
  document.getElementById("target").textContent = `${info.target === "virtual" ? "virtual modules" : "TMCL link"} · ${info.link}`;
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
