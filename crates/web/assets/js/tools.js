// Tuning tools: stallGuard2 (the load value against speed and threshold,
// and the threshold at which the load is detected as a stall), coolStep
// (the current scale against the load, within the band its settings
// make), reference search (mode and speeds, the switch events, the final
// position). Each is a sequence of TMCL requests through the target; which
// axis parameters play which role comes from the profile ("tuning"). On a
// virtual module the coolStep tool steps the world's load; on a module
// reached over a link it records what the module reports.
import { get, post, el, m, axisOptions, motorSelector } from "./api.js";
import { factor, show, toInternal, conversionReads, conversionOf, conversionNames, unitName } from "./units.js";

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const STATUS_MS = 500;
const COLORS = ["#0b6bcb", "#e67e22", "#1e8e3e", "#c0392b", "#8e44ad"];

/** A uPlot chart of y against x (not time); `series`: [{label, scale, points}]. */
function xyChart(box, title, xLabel, series) {
  const scales = { x: { time: false } };
  const axes = [{ label: xLabel }];
  for (const s of series) {
    if (scales[s.scale]) continue;
    scales[s.scale] = { auto: true };
    axes.push({ scale: s.scale, label: s.scale, side: axes.length === 1 ? 3 : 1, grid: { show: axes.length === 1 } });
  }
  const opts = {
    title,
    legend: { live: false },
    width: Math.max(260, box.clientWidth || 300),
    height: 200,
    scales,
    axes,
    series: [{ label: xLabel }, ...series.map((s, i) => ({ label: s.label, scale: s.scale, stroke: COLORS[i], width: 1.5, points: { show: !!s.points } }))],
  };
  box.replaceChildren();
  const chart = new uPlot(opts, [[], ...series.map(() => [])], box);
  return (rows) => {
    const sorted = [...rows].sort((a, b) => a[0] - b[0]);
    chart.setData([sorted.map((r) => r[0]), ...series.map((_, i) => sorted.map((r) => r[i + 1]))]);
  };
}

export class ToolsPanel {
  constructor() {
    this.axis = document.getElementById("tools-axis");
    motorSelector(this.axis, () => {});
    this.message = document.getElementById("tools-message");
    const on = (id, f) => document.getElementById(id).addEventListener("click", f);
    on("sg-run", () => this.exclusive(() => this.stallguard()));
    on("sg-apply", () => this.applyStall());
    on("cs-run", () => this.exclusive(() => this.coolstep()));
    on("rfs-start", () => this.exclusive(() => this.reference()));
    on("rfs-stop", () => this.stopReference());
    on("tools-stop", () => this.stop());
    this.running = false;
    setInterval(() => this.pollStatus(), STATUS_MS);
  }

  shown(on) {
    this.visible = on;
    if (on) this.pollStatus();
  }

  setModule(ctx) {
    this.ctx = ctx;
    axisOptions(this.axis, ctx.profile);
    const t = ctx.profile?.tuning;
    this.tuning = t;
    const has = (x, ...roles) => !!x && roles.every((r) => x[r] !== undefined);
    const sgOk = has(t?.stallguard2, "threshold", "stop_speed", "load");
    const csOk = has(t?.coolstep, "max_current", "minimum", "down_step", "hysteresis", "up_step", "hysteresis_start", "actual_current", "threshold_speed", "load");
    const rfsOk = has(t?.reference_search, "mode");
    const enable = (what, ok) => {
      document.getElementById(`${what}-none`).hidden = ok;
      document.getElementById(`${what}-tool`).hidden = !ok;
    };
    enable("sg", sgOk);
    enable("cs", csOk);
    enable("rfs", rfsOk);
    document.getElementById("cs-how").textContent = ctx.virtual
      ? "The world's load is set step by step from 0 to the highest load, then back to what it was."
      : "The module reports its load value while it runs: load the motor by hand during the run.";
    document.getElementById("cs-load-row").hidden = !ctx.virtual;
    document.getElementById("rfs-mode").replaceChildren(
      el("option", { value: "", text: "as set (AP 193)" }),
      ...(ctx.profile?.reference_modes ?? []).map((x) => el("option", { value: String(x.value), text: x.name })),
    );
    for (const id of ["sg-result", "cs-result", "rfs-final", "rfs-state"]) document.getElementById(id).textContent = "";
    document.getElementById("rfs-events").replaceChildren();
    document.getElementById("sg-apply").disabled = true;
    this.suggestion = null;
    this.coolRows = [];
    this.events = [];
    this.sgCharts = null;
    this.csChart = null;
  }

  motor() {
    return Number(this.axis.value || 0);
  }

  row(number) {
    return this.ctx.profile.axis_parameters.find((r) => r.number === number);
  }

  say(text, bad) {
    this.message.textContent = text;
    this.message.classList.toggle("error", !!bad);
  }

  /** One tool at a time; its errors are shown. */
  async exclusive(f) {
    if (this.running) return this.say("a tool is running: wait for it, or stop it", true);
    this.running = true;
    this.stopped = false;
    this.say("");
    for (const b of document.querySelectorAll("#panel-tools button.run")) b.disabled = true;
    try {
      await f();
    } catch (e) {
      this.say(e.message, true);
    } finally {
      this.running = false;
      for (const b of document.querySelectorAll("#panel-tools button.run")) b.disabled = false;
    }
  }

  /** Stops the running tool (it stops the motor and sets back what it
   * changed); a reference search with RFS STOP. */
  stop() {
    this.stopped = true;
    if (this.searching) this.stopReference();
  }

  check() {
    if (this.stopped) throw new Error("stopped");
  }

  /** A TMCL command line; its value, or an error. */
  async cmd(line) {
    const r = await post(m(this.ctx.id, "command"), { line });
    if (r.error || r.status < 100) throw new Error(`${line}: ${r.error ?? r.status_text}`);
    return r.value;
  }

  sap(number, value) {
    return this.cmd(`SAP ${number}, ${this.motor()}, ${value}`);
  }

  /** Axis parameters of the motor, read. */
  async gap(...numbers) {
    const r = await post(m(this.ctx.id, "read"), { reads: numbers.map((number) => ({ kind: "ap", number, index: this.motor() })) });
    if (r.error) throw new Error(r.error);
    return r.values;
  }

  /** Speeds typed in the page's unit to the module's values and back, in
   * its motion units with the motor's conversion reads (divisors, unit
   * mode, microsteps) read now. */
  async speeds() {
    const p = this.ctx.profile;
    const reads = conversionReads(p, this.motor());
    const r = reads.length ? await post(m(this.ctx.id, "read"), { reads }) : { values: [] };
    if (r.error) throw new Error(r.error);
    const d = conversionOf(p, reads, r.values, this.motor());
    const f = factor("velocity", p.motion_units, p, d);
    if (f == null) throw new Error(`the motor's ${conversionNames(p)} could not be read: no speed conversion`);
    return {
      internal: (id) => {
        const v = toInternal(Number(document.getElementById(id).value), "velocity", p.motion_units, p, d);
        if (!Number.isFinite(v) || v < 0) throw new Error(`${id}: give a speed ≥ 0`);
        return v;
      },
      shown: (v) => Number(show(v * f)),
      unit: unitName("velocity", p.motion_units, d),
    };
  }

  /** Until the motor runs at `v` (AP 3), then a moment for the readings. */
  async reach(v) {
    for (let i = 0; i < 100; i++) {
      this.check();
      const [s] = await this.gap(3);
      if (s !== null && Math.abs(Math.abs(s) - v) <= Math.max(1, v * 0.01)) break;
      await sleep(50);
    }
    await sleep(200);
  }

  /** The median of a few readings of axis parameter `number`. */
  async median(number, n = 5) {
    const xs = [];
    for (let i = 0; i < n; i++) {
      const [x] = await this.gap(number);
      if (x !== null) xs.push(x);
      await sleep(40);
    }
    if (!xs.length) throw new Error(`AP ${number} could not be read`);
    xs.sort((a, b) => a - b);
    return xs[Math.floor(xs.length / 2)];
  }

  /** The world's load on the motor now (virtual modules), else null. */
  async worldLoad() {
    if (!this.ctx.virtual) return null;
    const w = await get(m(this.ctx.id, "world"));
    return w.error ? null : w.axes[this.motor()].load;
  }

  // --- stallGuard2 ---------------------------------------------------------

  /** Runs the motor at rising speeds up to the test speed, reading the load
   * value at each; then, at the test speed, finds the highest threshold at
   * which the load value reads 0 (a stall), by halving the range. Stop on
   * stall is off meanwhile; the threshold and stop on stall are set back. */
  async stallguard() {
    const sg = this.tuning.stallguard2;
    const a = this.motor();
    const u = await this.speeds();
    const speed = u.internal("sg-speed");
    const steps = Math.min(20, Math.max(1, Math.round(Number(document.getElementById("sg-steps").value) || 1)));
    if (speed <= 0) throw new Error("the test speed must be above 0");
    const row = this.row(sg.threshold);
    const [threshold0, stop0] = await this.gap(sg.threshold, sg.stop_speed);
    const result = document.getElementById("sg-result");
    const apply = document.getElementById("sg-apply");
    apply.disabled = true;
    this.suggestion = null;
    const unit = u.unit;
    const bySpeed = [];
    const byThreshold = new Map();
    const drawSpeed = xyChart(document.getElementById("sg-chart-speed"), `Load value at threshold ${threshold0}`, `speed (${unit})`, [{ label: "load value", scale: "0…1023", points: true }]);
    const drawThreshold = xyChart(document.getElementById("sg-chart-threshold"), "Load value at the test speed", "threshold", [{ label: "load value", scale: "0…1023", points: true }]);
    const load = await this.worldLoad();
    const under = load === null ? "" : ` (world load ${Number(load.toFixed(1))} %)`;
    try {
      await this.sap(sg.stop_speed, 0);
      for (let i = 1; i <= steps; i++) {
        const v = Math.round((speed * i) / steps);
        await this.cmd(`ROR ${a}, ${v}`);
        await this.reach(v);
        bySpeed.push([u.shown(v), await this.median(sg.load)]);
        drawSpeed(bySpeed);
        result.textContent = `measuring: ${bySpeed.length} of ${steps} speeds`;
      }
      const at = async (t) => {
        this.check();
        if (!byThreshold.has(t)) {
          await this.sap(sg.threshold, t);
          await sleep(150);
          byThreshold.set(t, await this.median(sg.load, 3));
          drawThreshold([...byThreshold]);
        }
        return byThreshold.get(t);
      };
      let lo = row.min;
      let hi = row.max;
      if ((await at(lo)) > 0) {
        result.textContent = `The load value stays above 0 at every threshold${under}: no stall to detect at this speed.`;
      } else if ((await at(hi)) === 0) {
        result.textContent = `The load value is 0 at every threshold${under}: the motor does not carry this load at this speed.`;
      } else {
        while (hi - lo > 1) {
          const mid = Math.floor((lo + hi) / 2);
          if ((await at(mid)) === 0) lo = mid;
          else hi = mid;
        }
        this.suggestion = { threshold: lo, stopSpeed: Math.max(1, Math.round(speed / 2)), speed };
        result.replaceChildren(
          "Suggested threshold ",
          el("b", { "data-testid": "sg-suggestion", text: String(lo) }),
          `: the highest at which this load${under} reads 0 at ${u.shown(speed)} ${unit} (at ${hi} it reads ${byThreshold.get(hi)}). ` +
            `Apply sets AP ${sg.threshold} to it and stop on stall (AP ${sg.stop_speed}) to half the test speed, ${u.shown(this.suggestion.stopSpeed)} ${unit}.`,
        );
        apply.disabled = false;
      }
    } finally {
      await this.cmd(`MST ${a}`);
      await this.sap(sg.threshold, threshold0);
      await this.sap(sg.stop_speed, stop0);
    }
  }

  async applyStall() {
    const s = this.suggestion;
    if (!s) return;
    const sg = this.tuning.stallguard2;
    try {
      await this.sap(sg.threshold, s.threshold);
      await this.sap(sg.stop_speed, s.stopSpeed);
      this.say(`AP ${sg.threshold} = ${s.threshold}, AP ${sg.stop_speed} = ${s.stopSpeed}: the motor stops on a stall`);
    } catch (e) {
      this.say(e.message, true);
    }
  }

  // --- coolStep ------------------------------------------------------------

  /** Sets the coolStep parameters, runs the motor and reads the current
   * scale and the load value at each load: the world's, stepped, on a
   * virtual module; what the module meets, in time slices, over a link. */
  async coolstep() {
    const cs = this.tuning.coolstep;
    const a = this.motor();
    const u = await this.speeds();
    const speed = u.internal("cs-speed");
    const fields = [
      ["cs-semin", cs.hysteresis_start],
      ["cs-semax", cs.hysteresis],
      ["cs-seimin", cs.minimum],
      ["cs-up", cs.up_step],
      ["cs-down", cs.down_step],
    ];
    const values = {};
    for (const [id, number] of fields) {
      const v = Number(document.getElementById(id).value);
      const r = this.row(number);
      if (!Number.isInteger(v) || v < r.min || v > r.max) throw new Error(`${r.name} (AP ${number}) takes ${r.min}…${r.max}`);
      values[number] = v;
    }
    const threshold = u.internal("cs-threshold");
    const steps = Math.min(20, Math.max(1, Math.round(Number(document.getElementById("cs-steps").value) || 1)));
    const dwell = Math.max(100, Number(document.getElementById("cs-dwell").value) * 1000 || 1000);
    const maxLoad = Number(document.getElementById("cs-load").value);
    for (const [number, v] of Object.entries(values)) await this.sap(number, v);
    await this.sap(cs.threshold_speed, threshold);
    const [current] = await this.gap(cs.max_current);
    // Manual, AP 6 and 168: the current scale goes in 32 steps (AP 6 / 8)
    // and down to 1/2 or 1/4 of it.
    const top = current >> 3;
    const bottom = Math.max(0, (top + 1) / (values[cs.minimum] === 1 ? 4 : 2) - 1);
    const semin = values[cs.hysteresis_start];
    const lower = semin * 32;
    const upper = (semin + values[cs.hysteresis] + 1) * 32;
    const world = this.ctx.virtual;
    const x = world ? "world load (%)" : "load value (AP 206)";
    const series = [
      { label: "current scale (AP 180)", scale: "0…31", points: true },
      { label: "maximum (AP 6 / 8)", scale: "0…31" },
      { label: "minimum (SEIMIN)", scale: "0…31" },
    ];
    if (world) series.push({ label: "load value (AP 206)", scale: "0…1023", points: true });
    const draw = xyChart(document.getElementById("cs-chart"), `coolStep: SEMIN ${semin}, SEMAX ${values[cs.hysteresis]}`, x, series);
    const result = document.getElementById("cs-result");
    const before = await this.worldLoad();
    this.coolRows = [];
    this.coolBand = { top, bottom, lower, upper };
    try {
      await this.cmd(`ROR ${a}, ${speed}`);
      await this.reach(speed);
      for (let i = 0; i <= steps; i++) {
        this.check();
        const load = world ? Math.round((maxLoad * i) / steps) : null;
        if (world) await this.world(`load ${a} ${load}`);
        await sleep(dwell);
        const scale = await this.median(cs.actual_current);
        const value = await this.median(cs.load);
        this.coolRows.push(world ? [load, scale, top, bottom, value] : [value, scale, top, bottom]);
        draw(this.coolRows);
        result.textContent = `step ${i + 1} of ${steps + 1}: current scale ${scale}, load value ${value}`;
      }
      result.textContent =
        `Current scale between ${bottom} and ${top} (SEIMIN ${values[cs.minimum]}); it rises while the load value is below ${lower} ` +
        `(SEMIN × 32) and falls while it is above ${upper} ((SEMIN + SEMAX + 1) × 32).`;
    } finally {
      await this.cmd(`MST ${a}`);
      if (world && before !== null) await this.world(`load ${a} ${before}`);
    }
  }

  async world(line) {
    const r = await post(m(this.ctx.id, "world"), { line });
    if (r.error) throw new Error(`${line}: ${r.error}`);
  }

  // --- reference search ----------------------------------------------------

  /** Sets mode and speeds, starts the search and follows it: each change of
   * a switch with the position then, until the module says it is done. */
  async reference() {
    const r = this.tuning.reference_search;
    const a = this.motor();
    const mode = document.getElementById("rfs-mode").value;
    if (mode) await this.sap(r.mode, mode);
    if (document.getElementById("rfs-search-speed").value !== "" || document.getElementById("rfs-switch-speed").value !== "") {
      const u = await this.speeds();
      for (const [id, role] of [["rfs-search-speed", "search_speed"], ["rfs-switch-speed", "switch_speed"]]) {
        if (document.getElementById(id).value !== "" && r[role] !== undefined) await this.sap(r[role], u.internal(id));
      }
    }
    const switches = ["left", "right", "home"].filter((s) => r[s] !== undefined);
    const list = document.getElementById("rfs-events");
    list.replaceChildren();
    this.events = [];
    document.getElementById("rfs-final").textContent = "";
    this.rfsStopped = false;
    const before = await this.gap(...switches.map((s) => r[s]));
    const t0 = performance.now();
    await this.cmd(`RFS START, ${a}`);
    this.showState(true);
    this.searching = true;
    try {
      await this.follow(a, r, switches, before, t0, list);
    } finally {
      this.searching = false;
    }
    this.showState(false);
    const extra = [r.distance, r.last_position].filter((n) => n !== undefined);
    const [position, ...more] = await this.gap(1, ...extra);
    const final = document.getElementById("rfs-final");
    final.replaceChildren(
      this.rfsStopped ? "Stopped at position " : "Done: final position ",
      el("b", { "data-testid": "rfs-position", text: String(position) }),
      " (AP 1)",
      ...extra.map((n, i) => ` · ${this.row(n).name} (AP ${n}) ${more[i] ?? "–"}`),
    );
  }

  /** Until RFS STATUS says the search is over: each change of a switch,
   * with the position read with it. */
  async follow(a, r, switches, before, t0, list) {
    for (;;) {
      // The status first: the switches read after it are the last ones.
      const done = (await this.cmd(`RFS STATUS, ${a}`)) === 0;
      const [position, ...now] = await this.gap(1, ...switches.map((s) => r[s]));
      now.forEach((v, i) => {
        if (v === null || v === before[i]) return;
        const e = { t: (performance.now() - t0) / 1000, which: switches[i], pressed: !!v, position };
        this.events.push(e);
        list.append(el("li", { "data-testid": "rfs-event", text: `${e.t.toFixed(2)} s: ${e.which} switch ${e.pressed ? "pressed" : "released"}, position read then ${position}` }));
      });
      before = now;
      if (done) return;
      await sleep(20);
    }
  }

  async stopReference() {
    this.rfsStopped = true;
    try {
      await this.cmd(`RFS STOP, ${this.motor()}`);
      await this.pollStatus(true);
    } catch (e) {
      this.say(e.message, true);
    }
  }

  showState(searching) {
    document.getElementById("rfs-state").textContent = searching ? "searching" : "not searching";
  }

  /** The search's state as the module reports it (RFS STATUS), while the
   * panel is shown: a search started or stopped elsewhere shows too. */
  async pollStatus(now) {
    if (!this.ctx || (!now && (!this.visible || this.running || this.polling)) || document.getElementById("rfs-tool").hidden) return;
    this.polling = true;
    try {
      const r = await post(m(this.ctx.id, "command"), { line: `RFS STATUS, ${this.motor()}` });
      if (!r.error && r.status >= 100) this.showState(r.value !== 0);
    } finally {
      this.polling = false;
    }
  }
}
