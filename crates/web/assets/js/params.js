// The parameter grid: the profile's axis and global parameters with their
// live values, edited with validation against the range (SAP/SGP), stored
// and restored (STAP/RSAP, STGP/RSGP). Values that change flash. Speeds and
// accelerations are shown and typed in the page's unit, converted with the
// motor's conversion reads (divisors, unit mode, microsteps) read with the
// rows.
import { post, el, m, axisOptions, motorSelector } from "./api.js";
import { factor, show, toInternal, unitName, onUnits, conversionReads, conversionOf, conversionNames } from "./units.js";

const POLL_MS = 300;
const INT_MIN = -2147483648;
const INT_MAX = 2147483647;

export function inRange(row, v) {
  if (!Number.isInteger(v) || v < row.min || v > row.max) return false;
  return !row.ranges.length || row.ranges.some(([lo, hi]) => v >= lo && v <= hi);
}

export class ParamsPanel {
  constructor() {
    this.body = document.querySelector("#param-table tbody");
    this.filter = document.getElementById("param-filter");
    this.axis = document.getElementById("param-axis");
    this.status = document.getElementById("param-status");
    this.filter.addEventListener("input", () => this.draw());
    motorSelector(this.axis, () => this.draw());
    for (const r of document.querySelectorAll("input[name=ptable]")) r.addEventListener("change", () => this.draw());
    onUnits(() => this.draw());
    this.visible = false;
    // Only the rows on screen are read: a real module on a slow link answers
    // a few hundred requests a second at best.
    this.onScreen = new Set();
    this.observer = new IntersectionObserver(
      (entries) => {
        for (const e of entries) {
          if (e.isIntersecting) this.onScreen.add(e.target);
          else this.onScreen.delete(e.target);
        }
        this.poll();
      },
      { root: document.querySelector("#panel-params .table-wrap") },
    );
    setInterval(() => this.poll(), POLL_MS);
  }

  shown(on) {
    this.visible = on;
    if (on) this.poll();
  }

  setModule(ctx) {
    this.ctx = ctx;
    this.reads = {};
    axisOptions(this.axis, ctx.profile);
    this.draw();
  }

  table() {
    return document.querySelector("input[name=ptable]:checked").value;
  }

  draw() {
    const p = this.ctx?.profile;
    this.rows = [];
    this.observer.disconnect();
    this.onScreen.clear();
    if (!p) {
      this.body.replaceChildren();
      this.status.textContent = "no profile for this module type: use direct mode with numbers";
      return;
    }
    const words = this.filter.value.toLowerCase().trim();
    const global = this.table() === "global";
    const all = global ? p.global_parameters : p.axis_parameters;
    const rows = all.filter((r) => !words || r.name.toLowerCase().includes(words) || r.snake.includes(words) || String(r.number) === words);
    const motor = Number(this.axis.value || 0);
    document.getElementById("param-table").classList.toggle("axis", !global);
    this.axis.disabled = global;
    this.body.replaceChildren(
      ...rows.map((r) => {
        const index = global ? r.bank : motor;
        const kind = global ? "gp" : "ap";
        const value = el("td", { class: "value", "data-testid": `value-${kind}-${index}-${r.number}`, text: "–" });
        const input = el("input", { type: "number", "data-testid": `edit-${kind}-${index}-${r.number}`, step: r.quantity ? "any" : "1" });
        const set = el("button", { "data-testid": `set-${kind}-${index}-${r.number}`, text: "Set" });
        const writable = r.access.includes("W");
        input.disabled = set.disabled = !writable;
        // The typed value, in internal units (null: not a value).
        const typedValue = () => (input.value === "" ? null : r.quantity ? toInternal(Number(input.value), r.quantity, r.quantity_units, p, this.reads) : Number(input.value));
        input.addEventListener("input", () => input.classList.toggle("invalid", input.value !== "" && !inRange(r, typedValue())));
        const doSet = async () => {
          const v = typedValue();
          if (v === null || !inRange(r, v)) {
            const where = r.quantity ? `${range.textContent} ${unitName(r.quantity, r.quantity_units, this.reads)}` : `${r.min}…${r.max}${r.ranges.length ? " (" + r.ranges.map(([a, b]) => `${a}…${b}`).join(", ") + ")" : ""}`;
            this.say(v === null && input.value !== "" ? `${r.name}: the motor's ${conversionNames(p)} are not read yet` : `${r.name}: ${input.value} is outside ${where}`, true);
            input.classList.add("invalid");
            return;
          }
          const typed = input.value;
          const a = await post(m(this.ctx.id, "write"), { kind, number: r.number, index, value: v });
          this.answer(r, a);
          // Taken: the input empties, unless another value was typed meanwhile.
          if (!a.error && a.status >= 100 && input.value === typed) input.value = "";
          this.poll();
        };
        set.addEventListener("click", doSet);
        input.addEventListener("keydown", (e) => e.key === "Enter" && doSet());
        const extra = el("td", { class: "actions" });
        if (r.storable) {
          for (const op of ["store", "restore"]) {
            const b = el("button", { text: op === "store" ? "Store" : "Restore", "data-testid": `${op}-${kind}-${index}-${r.number}`, title: op === "store" ? "to EEPROM (STAP/STGP)" : "from EEPROM (RSAP/RSGP)" });
            b.addEventListener("click", async () => {
              this.answer(r, await post(m(this.ctx.id, "write"), { op, kind, number: r.number, index }));
              this.poll();
            });
            extra.append(b, " ");
          }
        }
        const range = el("td", { class: "range", title: `${r.min}…${r.max}` });
        const def = el("td", { class: "default", title: r.note ?? "" }, el("span"), " ", el("span", { class: `src src-${r.default_source}`, text: r.default_source }));
        const unit = el("td", { class: "unit-cell", text: r.quantity ? unitName(r.quantity, r.quantity_units, this.reads) : (r.unit ?? "") });
        const rangeText = r.ranges.length ? r.ranges.map(([a, b]) => `${a}…${b}`).join(", ") : r.min === INT_MIN && r.max === INT_MAX ? "signed 32 bit" : `${r.min}…${r.max}`;
        const tr = el("tr", { "data-testid": `row-${kind}-${index}-${r.number}` },
          el("td", { class: "num", text: String(r.number) }),
          el("td", { class: "num bank", text: global ? String(r.bank) : "" }),
          el("td", { class: "name", text: r.name, title: r.note ?? "" }),
          value,
          unit,
          el("td", { text: r.access }),
          range,
          def,
          el("td", { class: "actions" }, input, " ", set),
          extra);
        const row = { r, kind, index, value, tr, readable: r.access.includes("R"), range, rangeText, def: def.firstChild, unit };
        this.rows.push(row);
        this.inUnit(row);
        this.observer.observe(tr);
        return tr;
      }),
    );
    this.status.textContent = `${rows.length} parameters`;
    this.poll();
  }

  /** A row's factor: 1 for a value that is no speed or acceleration. */
  factor(r) {
    return r.quantity ? factor(r.quantity, r.quantity_units, this.ctx.profile, this.reads) : 1;
  }

  /** Range, default and unit of a row, in the page's unit for a speed or
   * an acceleration (as read with the last conversion reads). */
  inUnit(x) {
    const f = this.factor(x.r);
    const conv = (v) => (f === 1 ? String(v) : show(f == null ? null : v * f));
    x.range.textContent = f === 1 ? x.rangeText : `${conv(x.r.min)}…${conv(x.r.max)}`;
    x.def.textContent = conv(x.r.default);
    if (x.r.quantity) x.unit.textContent = unitName(x.r.quantity, x.r.quantity_units, this.reads);
  }

  answer(r, a) {
    if (a.error) this.say(a.error, true);
    else this.say(a.text + (a.status < 100 ? ` [status ${a.status}: ${a.status_text}]` : ""), a.status < 100);
  }

  say(text, bad) {
    this.status.textContent = text;
    this.status.classList.toggle("error", !!bad);
  }

  async poll() {
    if (!this.visible || !this.ctx || !this.rows?.length || this.polling) return;
    const rows = this.rows.filter((x) => x.readable && this.onScreen.has(x.tr));
    if (!rows.length) return;
    this.polling = true;
    try {
      // The motor's conversion reads come with the rows, for the speeds
      // among them.
      const motor = rows[0].kind === "ap" ? rows[0].index : null;
      const extra = motor === null ? [] : conversionReads(this.ctx.profile, motor);
      const reads = [...extra, ...rows.map((x) => ({ kind: x.kind, number: x.r.number, index: x.index }))];
      const a = await post(m(this.ctx.id, "read"), { reads });
      if (!a.values) return;
      if (motor !== null) this.reads = conversionOf(this.ctx.profile, extra, a.values, motor);
      const values = a.values.slice(extra.length);
      rows.forEach((x, i) => {
        if (x.r.quantity) this.inUnit(x);
        const f = this.factor(x.r);
        const text = values[i] === null ? "error" : f === 1 ? String(values[i]) : show(f == null ? null : values[i] * f);
        if (x.value.textContent !== text) {
          const changed = x.value.textContent !== "–";
          x.value.textContent = text;
          if (changed) {
            x.value.classList.remove("flash");
            void x.value.offsetWidth;
            x.value.classList.add("flash");
          }
        }
      });
    } finally {
      this.polling = false;
    }
  }
}
