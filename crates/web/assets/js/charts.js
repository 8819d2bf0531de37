// Live charts (uPlot): panels with one shared time axis, fed by the live
// stream; pause, zoom (drag; double-click resets), CSV export, any readable
// parameter added. Switches and outputs are step traces.
import { el, axisOptions } from "./api.js";

const COLORS = ["#0b6bcb", "#e67e22", "#1e8e3e", "#8e44ad", "#c0392b", "#16697a", "#7f8c8d"];
const REDRAW_MS = 100;

export class ChartsPanel {
  constructor() {
    this.box = document.getElementById("charts");
    this.paused = false;
    this.visible = false;
    this.windowS = 30;
    this.added = [];
    document.getElementById("chart-pause").addEventListener("click", () => this.pause(!this.paused));
    document.getElementById("chart-clear").addEventListener("click", () => this.clear());
    document.getElementById("chart-csv").addEventListener("click", () => this.csv());
    document.getElementById("chart-window").addEventListener("change", (e) => {
      this.windowS = Number(e.target.value);
      this.redraw();
    });
    document.getElementById("chart-rate").addEventListener("change", () => this.ctx?.resubscribe());
    this.axis = document.getElementById("chart-axis");
    this.axis.addEventListener("change", () => {
      this.build();
      this.ctx.resubscribe();
    });
    document.getElementById("chart-add").addEventListener("change", (e) => {
      const n = e.target.value;
      e.target.value = "";
      if (n === "") return;
      const [kind, bank, number] = n.split(":").map((x, i) => (i === 0 ? x : Number(x)));
      const index = kind === "ap" ? this.motor() : bank;
      const row = (kind === "ap" ? this.ctx.profile.axis_parameters : this.ctx.profile.global_parameters).find((r) => r.number === number && (kind === "ap" || r.bank === bank));
      const where = kind === "ap" ? this.motorSuffix(index) : `, bank ${bank}`;
      this.added.push({ kind, number, index, label: `${row.name} (${kind.toUpperCase()} ${number}${where})`, unit: row.unit });
      this.build();
      this.ctx.resubscribe();
    });
    setInterval(() => this.redraw(), REDRAW_MS);
    window.addEventListener("resize", () => this.resize());
  }

  /** Pausing freezes the view; a drag that zooms pauses too, so that the
   * zoom stays until Resume. */
  pause(on) {
    this.paused = on;
    document.getElementById("chart-pause").textContent = on ? "Resume" : "Pause";
    if (!on) this.redraw();
  }

  motor() {
    return Number(this.axis.value || 0);
  }

  /** ", motor N" on modules with more than one. */
  motorSuffix(index) {
    return (this.ctx.profile?.axes ?? 1) > 1 ? `, motor ${index}` : "";
  }

  rate() {
    return Number(document.getElementById("chart-rate").value);
  }

  shown(on) {
    this.visible = on;
    if (on) {
      this.resize();
      this.redraw();
    }
  }

  setModule(ctx) {
    this.ctx = ctx;
    this.added = [];
    const p = ctx.profile;
    axisOptions(this.axis, p);
    this.axis.closest("label").hidden = (p?.axes ?? 1) < 2;
    const add = document.getElementById("chart-add");
    add.replaceChildren(el("option", { value: "", text: "parameter…" }));
    if (p) {
      for (const r of p.axis_parameters.filter((r) => r.access.includes("R"))) add.append(el("option", { value: `ap:0:${r.number}`, text: `AP ${r.number} ${r.name}` }));
      for (const r of p.global_parameters.filter((r) => r.access.includes("R"))) add.append(el("option", { value: `gp:${r.bank}:${r.number}`, text: `GP ${r.number} (bank ${r.bank}) ${r.name}` }));
    }
    this.build();
  }

  /** The panels and their series from the profile: what the module has. */
  build() {
    const p = this.ctx.profile;
    const has = new Set(p ? p.axis_parameters.map((r) => r.number) : [0, 1, 3]);
    const name = (n) => p?.axis_parameters.find((r) => r.number === n)?.name ?? `AP ${n}`;
    const motor = this.motor();
    const ap = (n, step = false) => ({ kind: "ap", number: n, index: motor, label: `${name(n)} (AP ${n}${this.motorSuffix(motor)})`, step });
    const panels = [
      { title: "Position", unit: "µsteps", series: [ap(1), ap(0)].filter((s) => has.has(s.number)) },
      { title: "Velocity", unit: "internal units", series: [ap(3)].filter((s) => has.has(s.number)) },
      { title: "Load and current", unit: "0…1023 / 0…255", series: [ap(206), ap(180)].filter((s) => has.has(s.number)) },
      { title: "Switches", unit: "0/1", step: true, series: [ap(11, true), ap(10, true), ap(9, true)].filter((s) => has.has(s.number)) },
      { title: "Outputs", unit: "0/1", step: true, series: (p?.outputs ?? []).map((o) => ({ kind: "output", number: o.number, index: 2, label: o.name, step: true })) },
    ];
    if (this.added.length) panels.push({ title: "Added", unit: "", series: this.added });
    this.panels = panels.filter((x) => x.series.length);
    this.flat = this.panels.flatMap((x) => x.series);
    this.clear();
  }

  signals() {
    return (this.flat ?? []).map(({ kind, number, index }) => ({ kind, number, index }));
  }

  clear() {
    this.t = [];
    this.data = this.flat.map(() => []);
    for (const c of this.charts ?? []) c.destroy();
    this.box.replaceChildren();
    const width = this.width();
    const sync = uPlot.sync("tmclsim");
    let i = 0;
    this.charts = this.panels.map((panel, p) => {
      // One time axis label, under the last panel.
      const last = p === this.panels.length - 1;
      const idx = panel.series.map(() => i++);
      const div = el("div", { class: "chart", "data-testid": `chart-${panel.title.toLowerCase().replace(/\W+/g, "-")}` });
      this.box.append(div);
      const opts = {
        title: panel.title,
        width,
        height: panel.step ? 120 : 170,
        cursor: { sync: { key: sync.key }, drag: { x: true, y: false } },
        hooks: { setSelect: [(u) => u.select.width > 0 && this.pause(true)] },
        scales: { x: { time: false } },
        axes: [
          last ? { label: "time (s)", stroke: "#6a7683" } : { stroke: "#6a7683", labelSize: 0, size: 30 },
          { label: panel.unit, stroke: "#6a7683", size: 70 },
        ],
        series: [
          { label: "t (s)", value: (u, v) => (v == null ? "–" : v.toFixed(3)) },
          ...panel.series.map((s, k) => ({
            label: s.label,
            stroke: COLORS[(idx[k]) % COLORS.length],
            width: 1.5,
            paths: s.step ? uPlot.paths.stepped({ align: 1 }) : undefined,
          })),
        ],
      };
      const chart = new uPlot(opts, [[], ...panel.series.map(() => [])], div);
      chart.idx = idx;
      return chart;
    });
    document.getElementById("chart-info").textContent = "";
  }

  width() {
    return Math.max(400, (this.box.clientWidth || document.querySelector("main").clientWidth - 40) - 10);
  }

  resize() {
    const w = this.width();
    for (const c of this.charts ?? []) c.setSize({ width: w, height: c.height });
  }

  onSample(t, values) {
    if (this.paused || !this.data) return;
    this.t.push(t);
    values.forEach((v, i) => this.data[i].push(v));
    // Keep ten windows of history at most.
    const keep = this.windowS * 10 * this.rate();
    if (this.t.length > keep) {
      const cut = this.t.length - keep;
      this.t.splice(0, cut);
      for (const d of this.data) d.splice(0, cut);
    }
    this.lastValues = values;
  }

  redraw() {
    if (!this.visible || this.paused || !this.charts || !this.t.length) return;
    const end = this.t[this.t.length - 1];
    let start = this.t.findIndex((x) => x >= end - this.windowS);
    if (start < 0) start = 0;
    const t = this.t.slice(start);
    for (const c of this.charts) c.setData([t, ...c.idx.map((i) => this.data[i].slice(start))]);
    document.getElementById("chart-info").textContent = `${this.t.length} samples · t = ${end.toFixed(2)} s`;
  }

  csv() {
    const head = ["t_s", ...this.flat.map((s) => s.label.replace(/,/g, ";"))].join(",");
    const lines = this.t.map((t, i) => [t.toFixed(6), ...this.data.map((d) => d[i] ?? "")].join(","));
    const blob = new Blob([head + "\n" + lines.join("\n") + "\n"], { type: "text/csv" });
    const a = el("a", { href: URL.createObjectURL(blob), download: `tmclsim-module-${this.ctx.id}.csv` });
    document.body.append(a);
    a.click();
    a.remove();
  }
}
