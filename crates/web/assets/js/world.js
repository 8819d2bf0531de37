// The world around a virtual module: switches, placement, load, supply,
// temperature, inputs, driver and link faults, reset; each one line of the
// control protocol (docs/world.md).
import { get, post, el, m, axisOptions, motorSelector } from "./api.js";

const POLL_MS = 250;

export class WorldPanel {
  constructor() {
    this.show = document.getElementById("world-show");
    this.axis = document.getElementById("world-axis");
    motorSelector(this.axis, () => this.poll());
    const a = () => this.axis.value || "0";
    for (const which of ["left", "right", "home"]) {
      for (const how of ["press", "release", "auto"]) {
        document.querySelector(`[data-testid=sw-${which}-${how}]`).addEventListener("click", () => this.line(`switch ${a()} ${which} ${how}`));
      }
    }
    const on = (id, f) => document.getElementById(id).addEventListener("click", f);
    const val = (id) => document.getElementById(id).value;
    on("place-go", () => this.line(`place ${a()} ${val("place-which")} ${val("place-at")}`));
    on("world-load-set", () => this.line(`load ${a()} ${val("world-load")}`));
    on("world-supply-set", () => this.line(`supply ${val("world-supply")}`));
    on("world-temp-set", () => this.line(`temperature ${val("world-temp")}`));
    on("world-analog-set", () => this.line(`analog ${val("world-analog")} ${val("world-analog-value")}`));
    on("fault-on", () => this.line(`fault ${a()} ${val("fault-kind")} on`));
    on("fault-off", () => this.line(`fault ${a()} ${val("fault-kind")} off`));
    on("link-fault-go", () => this.line(val("link-fault")));
    on("world-reset", () => this.line("reset"));
    setInterval(() => this.poll(), POLL_MS);
  }

  shown(on) {
    this.visible = on;
    if (on) this.poll();
  }

  setModule(ctx) {
    this.ctx = ctx;
    document.getElementById("world-none").hidden = ctx.virtual;
    document.getElementById("world-controls").hidden = !ctx.virtual;
    axisOptions(this.axis, ctx.profile);
    const inputs = (ctx.profile?.inputs ?? []).filter((x) => x.bank === 0 && !x.analog);
    this.inputLeds = inputs.map((x) => {
      const led = el("span", { class: "led clickable", "data-testid": `world-in-${x.number}`, text: x.name, title: "click: set or clear the input" });
      led.addEventListener("click", () => this.line(`input ${x.number} ${led.classList.contains("on") ? 0 : 1}`));
      return led;
    });
    document.getElementById("world-inputs").replaceChildren(...this.inputLeds);
    // The ADC inputs (GIO N, 1) the world drives, not the supply's reading.
    const adcs = (ctx.profile?.inputs ?? []).filter((x) => x.analog && x.bank === 1 && x.max === 4095);
    document.getElementById("world-analog").replaceChildren(...adcs.map((x) => el("option", { value: String(x.number), text: `${x.name} (0…4095)` })));
    for (const id of ["world-analog", "world-analog-value", "world-analog-set"]) document.getElementById(id).hidden = !adcs.length;
  }

  async line(text) {
    const r = await post(m(this.ctx.id, "world"), { line: text });
    this.show.textContent = `> ${text}\n${r.error ? "error: " + r.error : r.ok || "ok"}`;
    this.show.classList.toggle("err", !!r.error);
    this.poll();
  }

  async poll() {
    if (!this.visible || !this.ctx?.virtual) return;
    const w = await get(m(this.ctx.id, "world"));
    if (w.error) return;
    const ax = w.axes[Number(this.axis.value || 0)];
    for (const which of ["left", "right", "home"]) {
      document.querySelector(`[data-testid=sw-${which}-state]`).textContent = ax[which] ? "pressed" : "open";
    }
    const num = (x, digits) => (typeof x === "number" ? x.toFixed(digits) : "–");
    // The inputs show the world as it is (set here, by a script or over the
    // control socket), except the one being typed into.
    const reflect = (id, x) => {
      const input = document.getElementById(id);
      if (document.activeElement !== input && typeof x === "number") input.value = String(Number(x.toFixed(2)));
    };
    reflect("world-load", ax.load);
    reflect("world-supply", w.supply);
    reflect("world-temp", w.temperature);
    document.getElementById("world-state").textContent =
      `t = ${num(w.time, 2)} s · carriage ${num(ax.carriage, 0)} · load ${num(Math.abs(ax.load), 0)} % · ` +
      `supply ${num(w.supply, 1)} V · ${num(w.temperature, 1)} °C${ax.stopped_by_switch ? " · stopped by a switch" : ""}`;
    this.inputLeds.forEach((l) => l.classList.toggle("on", !!(w.inputs & (1 << Number(l.dataset.testid.split("-").pop())))));
  }
}
