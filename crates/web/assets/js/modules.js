// The module list: filterable, so that one among a thousand is found; only
// the first matches are drawn.
import { el, post } from "./api.js";

const SHOWN = 200;

/** A long link (a pty's path) by its end, which tells links apart. */
function short(link) {
  return link.length > 26 ? `${link.slice(0, link.indexOf(" ") + 1)}…${link.slice(-18)}` : link;
}

/** The list; `update(modules, selected)` draws another list. */
export function moduleList(modules, onPick) {
  const list = document.getElementById("module-list");
  const filter = document.getElementById("module-filter");
  const count = document.getElementById("module-count");
  let selected = 0;
  let text;
  const describe = () => (text = modules.map((m) => `${m.address} ${m.profile ?? ""} ${m.firmware} ${m.link}`.toLowerCase()));
  describe();
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
          el("small", mod.bootloader
            ? { text: `in its bootloader (${mod.bootloader}) · ${short(mod.link)}`, title: `a firmware update did not complete · ${mod.link}`, class: "bootloader" }
            : { text: `${mod.firmware} · ${short(mod.link)}`, title: `${mod.firmware} · ${mod.link}` }));
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
  return {
    update(all, id) {
      modules = all;
      selected = id;
      describe();
      draw();
    },
  };
}

/** Adding a module of any built-in profile, where the target can (the
 * playground's modules in the page). */
export function addButton(info, onAdded) {
  const box = document.getElementById("add-module");
  box.hidden = !info.playground;
  if (!info.playground) return;
  const select = document.getElementById("add-profile");
  select.replaceChildren(...info.profiles.map((p) => el("option", { value: p, text: p.toUpperCase() })));
  select.value = "tmcm-1141";
  const message = document.getElementById("add-message");
  document.getElementById("add-go").addEventListener("click", async () => {
    const r = await post("/api/modules", { profile: select.value });
    message.textContent = r.error ?? "";
    if (!r.error) await onAdded(r.id);
  });
}

/** The scan of a link target: every module that answers 136, with the
 * ones the app does not list marked. */
export function scanButton(info) {
  document.getElementById("scan").hidden = info.target !== "link";
  const list = document.getElementById("scan-list");
  const button = document.getElementById("scan-go");
  button.addEventListener("click", async () => {
    button.disabled = true;
    list.replaceChildren(el("li", { text: "scanning addresses 1…255…" }));
    const r = await post("/api/scan").finally(() => (button.disabled = false));
    if (r.error) return list.replaceChildren(el("li", { class: "error", text: r.error }));
    list.replaceChildren(
      el("li", { "data-testid": "scan-count", text: `${r.modules.length} module(s) answered` }),
      ...r.modules.map((x) =>
        el("li", { "data-testid": "scan-item" },
          el("b", { text: `${x.profile ?? "unknown type"} · address ${x.address}` }),
          el("small", { text: `${x.firmware}${x.listed ? "" : " · not listed: restart with --bus-addresses or --scan"}` }))),
    );
  });
}
