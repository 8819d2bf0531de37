// Motion: rotate, stop, move absolute/relative with a speed; the axis's
// position, speed and switches from the live stream (the reference search
// is among the tools, tools.js). Speeds are shown and entered in the
// page's unit, converted as the module's motion units say, with the motor's
// conversion reads (divisors, unit mode, microsteps) as last read.
import { post, el, m, axisOptions, motorSelector } from "./api.js";
import { factor, show as inUnit, toInternal, conversionReads, conversionOf, conversionNames, learn } from "./units.js";

// AP 1 actual, AP 0 target position, AP 3 actual speed, AP 8 position
// reached, AP 11 / 10 / 9 left, right and home switch.
const READOUT = [1, 0, 3, 8, 11, 10, 9];

export class MotionPanel {
  constructor() {
    this.axis = document.getElementById("motion-axis");
    this.log = document.getElementById("motion-log");
    motorSelector(this.axis, () => this.ctx?.resubscribe());
    // A speed typed in the page's unit, as the internal value sent.
    const internal = (x) => {
      const p = this.ctx.profile;
      const v = toInternal(Number(x), "velocity", p?.motion_units, p, this.reads);
      if (v == null) this.log.append(el("div", { class: "err", text: `the motor's ${conversionNames(p)} are not read yet: no conversion` }));
      return v;
    };
    const speed = () => internal(document.getElementById("rot-speed").value);
    const pos = () => Number(document.getElementById("mvp-value").value);
    const a = () => this.axis.value || "0";
    const on = (id, f) => document.getElementById(id).addEventListener("click", f);
    const rotate = (how) => {
      const v = speed();
      if (v != null) this.send(`${how} ${a()}, ${v}`);
    };
    on("rol", () => rotate("ROL"));
    on("ror", () => rotate("ROR"));
    on("mst", () => this.send(`MST ${a()}`));
    const move = async (how) => {
      const typed = document.getElementById("mvp-speed").value;
      const v = typed === "" ? "" : internal(typed);
      if (v === null) return;
      if (v !== "" && !(await this.send(`SAP 4, ${a()}, ${v}`))) return;
      await this.send(`MVP ${how}, ${a()}, ${pos()}`);
    };
    on("mvp-abs", () => move("ABS"));
    on("mvp-rel", () => move("REL"));
  }

  setModule(ctx) {
    this.ctx = ctx;
    this.reads = {};
    const p = ctx.profile;
    axisOptions(this.axis, ctx.profile);
    const has = new Set(p ? p.axis_parameters.map((r) => r.number) : READOUT);
    this.readout = READOUT.filter((n) => has.has(n));
  }

  signals() {
    const index = Number(this.axis.value || 0);
    return [...(this.readout ?? []).map((number) => ({ kind: "ap", number, index })), ...conversionReads(this.ctx?.profile, index)];
  }

  onSample(t, values, msg, signals) {
    const v = {};
    signals.forEach((s, i) => (v[s.number] = values[i]));
    const p = this.ctx.profile;
    this.reads = conversionOf(p, signals, values, signals[0]?.index);
    learn(this.reads);
    const f = factor("velocity", p?.motion_units, p, this.reads);
    const show = (id, x) => (document.getElementById(id).textContent = x ?? "–");
    show("ro-position", v[1]);
    show("ro-target", v[0]);
    show("ro-speed", v[3] == null ? undefined : f == null ? "–" : inUnit(v[3] * f));
    show("ro-reached", v[8] === undefined ? undefined : v[8] ? "yes" : "no");
    const sw = (x) => (x === undefined || x === null ? "–" : x ? "1" : "0");
    show("ro-switches", `${sw(v[11])} / ${sw(v[10])} / ${sw(v[9])}`);
  }

  async send(line) {
    const r = await post(m(this.ctx.id, "command"), { line });
    const ok = !r.error && r.status >= 100;
    this.log.append(el("div", { class: ok ? "ok" : "err", text: `> ${line}   ${r.error ?? `${r.text} [${r.status}]`}` }));
    this.log.scrollTop = this.log.scrollHeight;
    return ok ? r : null;
  }
}
