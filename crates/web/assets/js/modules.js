// The module list: filterable, so that one among a thousand is found; only
// the first matches are drawn.
import { el } from "./api.js";

const SHOWN = 200;

/** A long link (a pty's path) by its end, which tells links apart. */
function short(link) {
  return link.length > 26 ? `${link.slice(0, link.indexOf(" ") + 1)}…${link.slice(-18)}` : link;
}

export function moduleList(modules, onPick) {
  const list = document.getElementById("module-list");
  const filter = document.getElementById("module-filter");
  const count = document.getElementById("module-count");
  let selected = 0;
  const text = modules.map((m) => `${m.address} ${m.profile ?? ""} ${m.firmware} ${m.link}`.toLowerCase());
  function draw() {
    const words = filter.value.toLowerCase().split(/\s+/).filter(Boolean);
    // A word that is a module's address puts that module first.
    const exact = [];
    const hits = [];
    for (let i = 0; i < modules.length; i++) {
      if (!words.every((w) => text[i].includes(w))) continue;
      (words.includes(String(modules[i].address)) ? exact : hits).push(i);
    }
    hits.unshift(...exact);
    list.replaceChildren(
      ...hits.slice(0, SHOWN).map((i) => {
        const mod = modules[i];
        const li = el("li", { "data-testid": "module-item", "data-id": String(i), class: i === selected ? "selected" : "" },
          el("b", { text: `${mod.profile ?? "unknown type"} · address ${mod.address}` }),
          el("small", { text: `${mod.firmware} · ${short(mod.link)}`, title: `${mod.firmware} · ${mod.link}` }));
        li.addEventListener("click", () => {
          selected = i;
          draw();
          onPick(i);
        });
        return li;
      }),
    );
    count.textContent = hits.length > SHOWN ? `${hits.length} of ${modules.length} modules (first ${SHOWN} shown)` : `${hits.length} of ${modules.length} modules`;
  }
  filter.addEventListener("input", draw);
  draw();
}
