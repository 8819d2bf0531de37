// Motion: rotate, stop, move absolute/relative with a speed, reference
// search with the mode chosen by name; the axis's position, speed and
// switches from the live stream.
import { post, el, m, axisOptions } from "./api.js";

// AP 1 actual, AP 0 target position, AP 3 actual speed, AP 8 position
// reached, AP 11 / 10 / 9 left, right and home switch.
const READOUT = [1, 0, 3, 8, 11, 10, 9];

export class MotionPanel {
  constructor() {
    this.axis = document.getElementById("motion-axis");
    this.log = document.getElementById("motion-log");
    this.axis.addEventListener("change", () => this.ctx.resubscribe());
    const speed = () => Number(document.getElementById("rot-speed").value);
    const pos = () => Number(document.getElementById("mvp-value").value);
    const a = () => this.axis.value || "0";
    const on = (id, f) => document.getElementById(id).addEventListener("click", f);
    on("rol", () => this.send(`ROL ${a()}, ${speed()}`));
    on("ror", () => this.send(`ROR ${a()}, ${speed()}`));
    on("mst", () => this.send(`MST ${a()}`));
    const move = async (how) => {
      const v = document.getElementById("mvp-speed").value;
      if (v !== "" && !(await this.send(`SAP 4, ${a()}, ${Number(v)}`))) return;
      await this.send(`MVP ${how}, ${a()}, ${pos()}`);
    };
    on("mvp-abs", () => move("ABS"));
    on("mvp-rel", () => move("REL"));
    on("rfs-start", async () => {
      const mode = document.getElementById("rfs-mode").value;
      if (mode && !(await this.send(`SAP 193, ${a()}, ${mode}`))) return;
      await this.send(`RFS START, ${a()}`);
    });
    on("rfs-stop", () => this.send(`RFS STOP, ${a()}`));
    on("rfs-status", async () => {
      const r = await this.send(`RFS STATUS, ${a()}`);
      if (r) document.getElementById("rfs-result").textContent = r.value === 0 ? "not searching (done or never started)" : "searching";
    });
  }

  setModule(ctx) {
    this.ctx = ctx;
    const p = ctx.profile;
    axisOptions(this.axis, ctx.profile);
    const modes = p ? p.reference_modes : [];
    document.getElementById("rfs-mode").replaceChildren(
      el("option", { value: "", text: "as set (AP 193)" }),
      ...modes.map((x) => el("option", { value: String(x.value), text: x.name })),
    );
    const has = new Set(p ? p.axis_parameters.map((r) => r.number) : READOUT);
    this.readout = READOUT.filter((n) => has.has(n));
  }

  signals() {
    const index = Number(this.axis.value || 0);
    return (this.readout ?? []).map((number) => ({ kind: "ap", number, index }));
  }

  onSample(t, values) {
    const v = Object.fromEntries(this.readout.map((n, i) => [n, values[i]]));
    const show = (id, x) => (document.getElementById(id).textContent = x ?? "–");
    show("ro-position", v[1]);
    show("ro-target", v[0]);
    show("ro-speed", v[3]);
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
