// Live charts (uPlot): panels with one shared time axis, fed by the live
// stream. A series holds what was read, sample by sample, with null where
// a signal was not read (a gap, never a 0); adding a signal or choosing
// another motor starts new series beside the kept ones. Pause and zoom
// only change the view: samples keep coming in. Each scale group of a
// panel (µsteps, a speed, a 0…1023 load, a 0…31 current, switches 0/1)
// has its own axis. Every panel exports PNG and CSV.
import { el, axisOptions, download, motorSelector } from "./api.js";
import { factor, unitName, onUnits, conversionReads, conversionNumbers, unit as chosenUnit } from "./units.js";

const COLORS = ["#0b6bcb", "#e67e22", "#1e8e3e", "#8e44ad", "#c0392b", "#16697a", "#7f8c8d"];
const REDRAW_MS = 100;
/** Samples kept: an hour at 50 Hz. The oldest go first, whatever the view. */
const MAX_SAMPLES = 180000;

const keyOf = (s) => `${s.kind}:${s.index}:${s.number}`;

export class ChartsPanel {
  constructor() {
    this.box = document.getElementById("charts");
    this.paused = false;
    this.visible = false;
    this.windowS = 30;
    this.added = [];
    this.reset();
    document.getElementById("chart-pause").addEventListener("click", () => this.pause(!this.paused));
    document.getElementById("chart-clear").addEventListener("click", () => {
      this.reset();
      this.build();
    });
    document.getElementById("chart-csv").addEventListener("click", () => this.csv(this.panels, "all"));
    document.getElementById("chart-window").addEventListener("change", (e) => {
      this.windowS = Number(e.target.value);
      this.redraw(true);
    });
    document.getElementById("chart-rate").addEventListener("change", () => this.ctx?.resubscribe());
    this.axis = document.getElementById("chart-axis");
    motorSelector(this.axis, () => {
      this.build();
      this.ctx?.resubscribe();
    });
    document.getElementById("chart-add").addEventListener("change", (e) => {
      const n = e.target.value;
      e.target.value = "";
      if (n === "") return;
      const [kind, bank, number] = n.split(":").map((x, i) => (i === 0 ? x : Number(x)));
      const index = kind === "ap" ? this.motor() : bank;
      const row = (kind === "ap" ? this.ctx.profile.axis_parameters : this.ctx.profile.global_parameters).find((r) => r.number === number && (kind === "ap" || r.bank === bank));
      const where = kind === "ap" ? this.motorSuffix(index) : `, bank ${bank}`;
      this.added.push({ kind, number, index, row, label: `${row.name} (${kind.toUpperCase()} ${number}${where})` });
      this.build();
      this.ctx.resubscribe();
    });
    onUnits(() => this.build());
    setInterval(() => this.redraw(), REDRAW_MS);
    window.addEventListener("resize", () => this.resize());
  }

  /** No samples: the time axis and every series empty. */
  reset() {
    this.t = [];
    this.store = new Map();
  }

  /** Pausing freezes the view, not the recording; a drag that zooms
   * pauses too, so that the zoom stays until Resume. */
  pause(on) {
    this.paused = on;
    document.getElementById("chart-pause").textContent = on ? "Resume" : "Pause";
    if (!on) this.redraw(true);
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
      this.redraw(true);
    }
  }

  setModule(ctx) {
    this.ctx = ctx;
    this.added = [];
    this.reset();
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

  /** The scale group of a series: one axis per group in a panel. */
  group(s) {
    const r = s.row;
    if (r?.quantity) {
      // In internal units a sixPoint module's speeds and its measured speed
      // (pps either way) may differ: each on its own axis then.
      const key = chosenUnit() === "internal" ? `${r.quantity}:${r.quantity_units}` : r.quantity;
      return { key, label: unitName(r.quantity, r.quantity_units) };
    }
    if (r && r.min === 0 && r.max === 1) return { key: "0/1", label: "0/1", bool: true };
    if (!r) return { key: "0/1", label: "0/1", bool: true };
    const range = r.min <= -(2 ** 31) && r.max >= 2 ** 31 - 1 ? "" : ` ${r.min}…${r.max}`;
    return { key: `${r.unit ?? ""}${range}`, label: `${r.unit ?? ""}${range}`.trim() };
  }

  /** The panels and their series from the profile: what the module has. */
  build() {
    const p = this.ctx.profile;
    const rows = new Map((p?.axis_parameters ?? []).map((r) => [r.number, r]));
    const motor = this.motor();
    const ap = (n) => ({ kind: "ap", number: n, index: motor, row: rows.get(n), label: `${rows.get(n)?.name ?? `AP ${n}`} (AP ${n}${this.motorSuffix(motor)})` });
    const has = (s) => !p || rows.has(s.number);
    const panels = [
      { title: "Position", series: [ap(1), ap(0)].filter(has) },
      { title: "Velocity", series: [ap(3)].filter(has) },
      { title: "Load and current", series: [ap(206), ap(180)].filter(has) },
      { title: "Switches", series: [ap(11), ap(10), ap(9)].filter(has) },
      { title: "Outputs", series: (p?.outputs ?? []).map((o) => ({ kind: "output", number: o.number, index: 2, label: o.name, row: { min: 0, max: 1 } })) },
    ];
    if (this.added.length) panels.push({ title: "Added", series: this.added });
    this.panels = panels.filter((x) => x.series.length);
    for (const panel of this.panels) {
      for (const s of panel.series) {
        s.key = keyOf(s);
        s.group = this.group(s);
      }
    }
    // The conversion reads (divisors, unit mode, microsteps) of every motor
    // whose speeds are drawn come along with each sample, so that each
    // sample converts with its own.
    const series = this.panels.flatMap((x) => x.series);
    const motors = [...new Set(series.filter((s) => s.row?.quantity).map((s) => s.index))];
    this.subscribed = [...series, ...motors.flatMap((m) => conversionReads(p, m))].filter((s, i, all) => all.findIndex((x) => keyOf(x) === keyOf(s)) === i);
    for (const s of this.subscribed) if (!this.store.has(keyOf(s))) this.store.set(keyOf(s), new Array(this.t.length).fill(null));
    this.draw();
  }

  signals() {
    return (this.subscribed ?? []).map(({ kind, number, index }) => ({ kind, number, index }));
  }

  /** The uPlot charts of the panels. */
  draw() {
    for (const c of this.charts ?? []) c.destroy();
    this.box.replaceChildren();
    const width = this.width();
    const sync = uPlot.sync("tmclsim");
    let color = 0;
    this.charts = this.panels.map((panel, p) => {
      // One time axis label, under the last panel.
      const last = p === this.panels.length - 1;
      const slug = panel.title.toLowerCase().replace(/\W+/g, "-");
      const groups = [...new Map(panel.series.map((s) => [s.group.key, s.group])).values()];
      const step = groups.every((g) => g.bool);
      const div = el("div", { class: "chart", "data-testid": `chart-${slug}` });
      const bar = el("div", { class: "chart-export" },
        el("button", { "data-testid": `chart-${slug}-png`, text: "PNG", title: `${panel.title} as an image`, onclick: () => this.png(chart, slug) }),
        el("button", { "data-testid": `chart-${slug}-csv`, text: "CSV", title: `${panel.title}: every sample kept, time in seconds`, onclick: () => this.csv([panel], slug) }));
      this.box.append(el("div", { class: "chart-box" }, bar, div));
      const colors = panel.series.map(() => COLORS[color++ % COLORS.length]);
      const scales = { x: { time: false } };
      const axes = [last ? { label: "time (s)", stroke: "#6a7683" } : { stroke: "#6a7683", labelSize: 0, size: 30 }];
      const scaleOf = new Map(groups.map((g, k) => [g.key, `y${k}`]));
      groups.forEach((g, k) => {
        const scale = scaleOf.get(g.key);
        scales[scale] = g.bool ? { range: [-0.15, 1.15] } : {};
        const only = panel.series.filter((s) => s.group.key === g.key);
        axes.push({
          scale,
          label: g.label,
          side: k % 2 ? 1 : 3,
          size: 70,
          stroke: only.length === 1 && groups.length > 1 ? colors[panel.series.indexOf(only[0])] : "#6a7683",
          grid: { show: k === 0 },
          ...(g.bool ? { splits: () => [0, 1] } : {}),
        });
      });
      const opts = {
        title: panel.title,
        width,
        // The last panel carries the time axis's label too.
        height: (step ? 120 : 170) + (last ? 20 : 0),
        cursor: { sync: { key: sync.key }, drag: { x: true, y: false } },
        hooks: { setSelect: [(u) => u.select.width > 0 && this.pause(true)] },
        scales,
        axes,
        series: [
          { label: "t (s)", value: (u, v) => (v == null ? "–" : v.toFixed(3)) },
          ...panel.series.map((s, k) => ({
            label: s.label,
            scale: scaleOf.get(s.group.key),
            stroke: colors[k],
            width: 1.5,
            paths: s.group.bool ? uPlot.paths.stepped({ align: 1 }) : undefined,
          })),
        ],
      };
      const chart = new uPlot(opts, [[], ...panel.series.map(() => [])], div);
      chart.panel = panel;
      return chart;
    });
    this.redraw(true);
  }

  width() {
    return Math.max(400, (this.box.clientWidth || document.querySelector("main").clientWidth - 40) - 10);
  }

  resize() {
    const w = this.width();
    for (const c of this.charts ?? []) c.setSize({ width: w, height: c.height });
  }

  /** One sample of the subscription whose signals were `signals`. */
  onSample(t, values, msg, signals) {
    this.t.push(t);
    for (const d of this.store.values()) d.push(null);
    const n = this.t.length - 1;
    signals.forEach((s, i) => {
      const d = this.store.get(keyOf(s));
      if (d) d[n] = values[i] ?? null;
    });
    if (this.t.length > MAX_SAMPLES * 1.1) {
      const cut = this.t.length - MAX_SAMPLES;
      this.t.splice(0, cut);
      for (const d of this.store.values()) d.splice(0, cut);
    }
  }

  /** Series `s` from sample `from` on, in the chosen unit. */
  values(s, from = 0) {
    const raw = this.store.get(s.key).slice(from);
    const q = s.row?.quantity;
    if (!q) return raw;
    const p = this.ctx.profile;
    const numbers = conversionNumbers(p);
    const d = Object.fromEntries(numbers.map((n) => [n, this.store.get(`ap:${s.index}:${n}`)]));
    return raw.map((v, i) => {
      if (v == null) return null;
      const f = factor(q, s.row.quantity_units, p, Object.fromEntries(numbers.map((n) => [n, d[n]?.[from + i]])));
      return f == null ? null : v * f;
    });
  }

  redraw(force = false) {
    if (!this.visible || !this.charts) return;
    const end = this.t[this.t.length - 1];
    document.getElementById("chart-info").textContent = this.t.length ? `${this.t.length} samples · t = ${end.toFixed(2)} s` : "";
    if ((this.paused && !force) || !this.t.length) return;
    let start = this.t.findIndex((x) => x >= end - this.windowS);
    if (start < 0) start = 0;
    const t = this.t.slice(start);
    for (const c of this.charts) c.setData([t, ...c.panel.series.map((s) => this.values(s, start))]);
  }

  /** The panels' series, every sample kept: the time in seconds, then one
   * column per signal (in the chosen unit); a gap is an empty cell. */
  csv(panels, name) {
    const series = panels.flatMap((x) => x.series);
    const unit = (s) => (s.row?.quantity ? ` [${unitName(s.row.quantity, s.row.quantity_units)}]` : "");
    const head = ["t_s", ...series.map((s) => (s.label + unit(s)).replace(/,/g, ";"))].join(",");
    const columns = series.map((s) => this.values(s));
    const lines = this.t.map((t, i) => [t.toFixed(6), ...columns.map((d) => d[i] ?? "")].join(","));
    download(new Blob([head + "\n" + lines.join("\n") + "\n"], { type: "text/csv" }), `tmclsim-module-${this.ctx.id}-${name}.csv`);
  }

  /** The chart as drawn (title, plot with its axes, legend) as a PNG. */
  png(chart, name) {
    const plot = chart.ctx.canvas;
    const r = plot.width / chart.width;
    const series = chart.series.slice(1);
    const titleH = 28 * r;
    const legendH = (series.length * 18 + 8) * r;
    const c = el("canvas", { width: plot.width, height: plot.height + titleH + legendH });
    const g = c.getContext("2d");
    g.fillStyle = "#fff";
    g.fillRect(0, 0, c.width, c.height);
    g.fillStyle = "#1d2733";
    g.font = `600 ${14 * r}px sans-serif`;
    g.textAlign = "center";
    g.fillText(chart.panel.title, c.width / 2, 19 * r);
    g.drawImage(plot, 0, titleH);
    g.textAlign = "left";
    g.font = `${12 * r}px sans-serif`;
    series.forEach((s, i) => {
      const y = plot.height + titleH + (i * 18 + 14) * r;
      g.fillStyle = typeof s.stroke === "function" ? s.stroke(chart, i + 1) : s.stroke;
      g.fillRect(12 * r, y - 6 * r, 18 * r, 3 * r);
      g.fillStyle = "#1d2733";
      g.fillText(s.label, 38 * r, y);
    });
    c.toBlob((b) => download(b, `tmclsim-module-${this.ctx.id}-${name}.png`), "image/png");
  }
}
