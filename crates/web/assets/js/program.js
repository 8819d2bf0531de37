// Programs: the editor (TMCL highlighting), assembler diagnostics inline at
// line and column, download with progress and verification (134),
// run/stop/pause/step/continue/reset, breakpoints on source lines (mapped to
// addresses with the assembler's source map), the current line and the
// interpreter's registers live.
import "./tmcl-mode.js";
import { get, post, postLines, el, m } from "./api.js";

const EXAMPLE = `// A shuttle: back and forth between two positions, counting the trips.
        SAP 4, 0, 1000          // maximum positioning speed
        SAP 5, 0, 500           // maximum acceleration
Loop:   MVP ABS, 0, 51200
        WAIT POS, 0, 0
        CALC ADD, 1             // trips, in the accumulator
        AAP 1, 0                // nothing moves: shows AAP
        MVP ABS, 0, 0
        WAIT POS, 0, 0
        JA Loop
`;

export class ProgramPanel {
  constructor() {
    this.editor = CodeMirror(document.getElementById("editor"), {
      value: localStorage.getItem("tmclsim-program") ?? EXAMPLE,
      mode: "tmcl",
      lineNumbers: true,
      gutters: ["breakpoints", "CodeMirror-linenumbers"],
      indentUnit: 8,
    });
    window.tmclEditor = this.editor;
    this.map = null; // address → line, from the last download
    this.widgets = [];
    this.editor.on("gutterClick", (cm, line) => this.toggle(line + 1));
    this.editor.on("change", () => {
      localStorage.setItem("tmclsim-program", this.editor.getValue());
      this.stale = true;
    });
    const on = (id, f) => document.getElementById(id).addEventListener("click", f);
    on("prog-assemble", () => this.assemble());
    on("prog-download", () => this.download());
    on("prog-read", () => this.readBack());
    for (const action of ["run", "stop", "pause", "step", "continue", "reset"]) on(`prog-${action}`, () => this.act(action));
    this.message = document.getElementById("prog-message");
    this.examples = document.getElementById("prog-example");
    this.examples.addEventListener("change", () => {
      const pick = this.examples.value;
      this.examples.value = "";
      if (pick) this.openExample(pick);
    });
  }

  /** The playground's example programs (examples/index.json beside the
   * page): a menu, and `?example=NAME` opens one. */
  async loadExamples() {
    if (this.list) return;
    const r = await fetch("examples/index.json").catch(() => null);
    if (!r?.ok) return;
    this.list = await r.json();
    this.examples.append(...this.list.map((x) => el("option", { value: x.name, text: x.title })));
    this.examples.hidden = false;
    const wanted = new URLSearchParams(location.search).get("example");
    if (wanted) {
      document.querySelector("[data-tab=program]").click();
      await this.openExample(wanted);
    }
  }

  async openExample(name) {
    const x = this.list.find((e) => e.name === name);
    if (!x) return this.say(`no example '${name}'`, true);
    const r = await fetch(`examples/${x.name}.tmc`);
    if (!r.ok) return this.say(`examples/${x.name}.tmc: HTTP ${r.status}`, true);
    this.editor.setValue(await r.text());
    this.clearDiagnostics();
    this.map = null;
    this.say(x.about);
  }

  shown(on) {
    this.visible = on;
    if (on) setTimeout(() => this.editor.refresh(), 0);
  }

  setModule(ctx) {
    this.ctx = ctx;
    this.map = null;
    this.showState(null);
    if (ctx.info.playground) this.loadExamples();
  }

  say(text, bad) {
    this.message.textContent = text;
    this.message.classList.toggle("error", !!bad);
  }

  clearDiagnostics() {
    for (const w of this.widgets) w.clear();
    this.widgets = [];
    this.editor.eachLine((h) => this.editor.removeLineClass(h, "background", "cm-error-line"));
    document.getElementById("prog-diagnostics").replaceChildren();
  }

  showDiagnostics(list) {
    this.clearDiagnostics();
    const ul = document.getElementById("prog-diagnostics");
    for (const d of list) {
      const line = Math.max(0, d.line - 1);
      this.editor.addLineClass(line, "background", "cm-error-line");
      const text = `${" ".repeat(Math.max(0, d.column - 1))}^ ${d.line}:${d.column}: ${d.message}`;
      // A long diagnostic wraps within the editor's width.
      this.widgets.push(this.editor.addLineWidget(line, el("div", { class: "diag-widget", "data-testid": "diagnostic", text }), { noHScroll: true }));
      const li = el("li", { "data-testid": "diagnostic-item", text: `${d.line}:${d.column}: ${d.message}` });
      li.addEventListener("click", () => {
        this.editor.setCursor({ line, ch: Math.max(0, d.column - 1) });
        this.editor.focus();
      });
      ul.append(li);
    }
  }

  async assemble() {
    const a = await post("/api/assemble", { source: this.editor.getValue(), profile: this.ctx?.profile?.name });
    if (a.error) return this.say(a.error, true);
    this.showDiagnostics(a.diagnostics);
    const room = this.ctx?.profile ? ` of ${this.ctx.profile.program_memory}` : "";
    if (a.ok) this.say(`assembled: ${a.words} words${room}`);
    else this.say(`${a.diagnostics.length} error(s)`, true);
    return a;
  }

  useMap(sourceMap) {
    this.map = new Map(sourceMap.filter((e) => e.file === "program.tmc").map((e) => [e.address, e.line]));
    this.stale = false;
  }

  async download() {
    const bar = document.getElementById("prog-progress");
    const button = document.getElementById("prog-download");
    bar.value = 0;
    this.say("downloading…");
    button.disabled = true;
    const last = await postLines(m(this.ctx.id, "program/download"), { source: this.editor.getValue() }, (x) => {
      if (x.progress !== undefined) {
        bar.max = x.total;
        bar.value = x.progress;
      }
    }).finally(() => (button.disabled = false));
    if (!last) return this.say("no answer", true);
    if (last.ok === false) {
      this.showDiagnostics(last.diagnostics);
      return this.say(`${last.diagnostics.length} error(s): not downloaded`, true);
    }
    if (last.error) return this.say(last.error, true);
    this.clearDiagnostics();
    this.useMap(last.program.source_map);
    await this.sendBreakpoints();
    if (last.verified) this.say(`downloaded ${last.words} words, verified by reading back (134)`);
    else this.say(`downloaded ${last.words} words, but reading them back (134) found a difference`, true);
  }

  /** The module's program (134), disassembled, in the editor. */
  async readBack() {
    this.say("reading the program memory (134)…");
    const r = await get(m(this.ctx.id, "program/source"));
    if (r.error) return this.say(r.error, true);
    this.clearDiagnostics();
    this.editor.setValue(r.source);
    this.map = null;
    this.say(`read ${r.words} words from the module; download it to debug with its lines`);
  }

  /** The first address at a line, or at the next line with an instruction. */
  addressOf(line) {
    let best = null;
    for (const [a, l] of this.map ?? []) if (l >= line && (best === null || l < best[1] || (l === best[1] && a < best[0]))) best = [a, l];
    return best;
  }

  /** Lines (1-based) with a breakpoint marker: the markers move with
   * their lines as the source is edited. */
  breakLines() {
    const lines = [];
    this.editor.eachLine((h) => {
      if (h.gutterMarkers?.breakpoints) lines.push(this.editor.getLineNumber(h) + 1);
    });
    return lines;
  }

  toggle(line) {
    const on = !this.editor.lineInfo(line - 1).gutterMarkers?.breakpoints;
    this.editor.setGutterMarker(line - 1, "breakpoints", on ? el("div", { class: "breakpoint", "data-testid": "breakpoint", text: "●" }) : null);
    if (!this.map) return;
    // The addresses come from the downloaded program's source map: after an
    // edit, they are sent with the next download.
    if (this.stale) this.say("edited since the download: the breakpoints apply after the next download");
    else this.sendBreakpoints();
  }

  async sendBreakpoints() {
    const addresses = this.breakLines().map((l) => this.addressOf(l)).filter(Boolean).map(([a]) => a);
    const st = await post(m(this.ctx.id, "program/breakpoints"), { addresses });
    if (st.error) this.say(st.error, true);
    else this.showState(st);
  }

  async act(action) {
    const st = await post(m(this.ctx.id, `program/${action}`));
    if (st.error) this.say(st.error, true);
    else this.showState(st);
  }

  onSample(t, values, msg) {
    if (msg.program) this.showState(msg.program);
  }

  showState(st) {
    // States come by two ways, the answers to this page's requests and the
    // live stream, and may arrive out of order: one older than the state
    // shown (by the module's clock at its reads) is dropped, so a late
    // answer to "run" cannot hide the breakpoint hit that followed it.
    if (st && this.shownTime !== undefined && st.time < this.shownTime) {
      const ps = document.getElementById("ps-mode").dataset;
      ps.dropped = String(Number(ps.dropped ?? 0) + 1);
      return;
    }
    this.shownTime = st ? st.time : undefined;
    const set = (id, v) => (document.getElementById(id).textContent = v ?? "–");
    if (this.current !== undefined) {
      this.editor.removeLineClass(this.current, "background", "cm-current-line");
      this.current = undefined;
    }
    if (!st) {
      for (const id of ["ps-mode", "ps-pc", "ps-acc", "ps-x", "ps-flags", "ps-stack", "ps-break"]) set(id, null);
      return;
    }
    set("ps-mode", `${st.mode}${st.waiting ? " (WAIT)" : ""}`);
    set("ps-pc", String(st.pc));
    set("ps-acc", String(st.accumulator));
    set("ps-x", String(st.x));
    set("ps-flags", st.flags ?? "not reported over TMCL");
    set("ps-stack", st.stack_depth ?? "not reported over TMCL");
    set("ps-break", st.breakpoint === null ? "–" : `at address ${st.breakpoint}`);
    document.getElementById("ps-vars").replaceChildren(
      ...st.user_variables.flatMap((v, i) => [el("span", { class: "var", text: `#${i}` }), el("span", { "data-testid": `var-${i}`, text: v ?? "–" })]),
    );
    const line = this.map?.get(st.pc);
    if (line !== undefined && !this.stale) {
      this.current = this.editor.getLineHandle(line - 1);
      this.editor.addLineClass(this.current, "background", "cm-current-line");
      document.getElementById("editor").dataset.currentLine = String(line);
    } else {
      delete document.getElementById("editor").dataset.currentLine;
    }
  }
}
