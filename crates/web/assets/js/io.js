// IO: digital inputs, outputs (set with SIO), analog inputs, from the live
// stream.
import { post, el, m } from "./api.js";

export class IoPanel {
  setModule(ctx) {
    this.ctx = ctx;
    const p = ctx.profile;
    this.inputs = (p?.inputs ?? []).filter((x) => x.bank === 0 && !x.analog);
    this.analog = (p?.inputs ?? []).filter((x) => x.analog);
    this.outputs = (p?.outputs ?? []).filter((x) => x.bank === 2);
    this.inLeds = this.inputs.map((x) => el("span", { class: "led", "data-testid": `in-${x.number}`, text: x.name }));
    this.outLeds = this.outputs.map((x) => {
      const led = el("span", { class: "led clickable", "data-testid": `out-${x.number}`, text: x.name, title: "click: SIO toggles it" });
      led.addEventListener("click", () => post(m(ctx.id, "command"), { line: `SIO ${x.number}, 2, ${led.classList.contains("on") ? 0 : 1}` }));
      return led;
    });
    this.cells = this.analog.map(() => el("td", { class: "value", text: "–" }));
    document.getElementById("io-inputs").replaceChildren(...this.inLeds);
    document.getElementById("io-outputs").replaceChildren(...this.outLeds);
    document.getElementById("io-analog").replaceChildren(
      ...this.analog.map((x, i) => el("tr", { "data-testid": `analog-${x.bank}-${x.number}` }, el("td", { text: `${x.name} (GIO ${x.number}, ${x.bank})` }), this.cells[i], el("td", { text: x.unit ?? "" }))),
    );
  }

  signals() {
    return [
      ...this.inputs.map((x) => ({ kind: "input", number: x.number, index: x.bank })),
      ...this.analog.map((x) => ({ kind: "input", number: x.number, index: x.bank })),
      ...this.outputs.map((x) => ({ kind: "output", number: x.number, index: 2 })),
    ];
  }

  onSample(t, values) {
    const a = this.inputs.length;
    const b = a + this.analog.length;
    this.inLeds.forEach((l, i) => l.classList.toggle("on", !!values[i]));
    this.cells.forEach((c, i) => (c.textContent = values[a + i] ?? "–"));
    this.outLeds.forEach((l, i) => l.classList.toggle("on", !!values[b + i]));
  }
}
