// Direct mode: one command line with history and completion (mnemonics and
// parameter names), replies decoded by the server.
import { post, el, m } from "./api.js";

// The symbolic first operands the command line takes (the protocol crate's
// mnemonic tables); parameter names for the parameter commands.
const CALC = ["ADD", "SUB", "MUL", "DIV", "MOD", "AND", "OR", "XOR", "NOT", "LOAD", "SWAP", "COMP"];
const SYMBOLS = {
  MVP: ["ABS", "REL", "COORD"],
  MVPA: ["ABS", "REL", "COORD"],
  RFS: ["START", "STOP", "STATUS"],
  JC: ["ZE", "NZ", "EQ", "NE", "GT", "GE", "LT", "LE", "ETO", "EAL", "EDV", "EPO"],
  WAIT: ["TICKS", "POS", "REFSW", "LIMSW", "RFS"],
  CLE: ["ALL", "ETO", "EAL", "EDV", "EPO", "ESD"],
  ...Object.fromEntries(["CALC", "CALCX", "CALCV", "CALCVV", "CALCVA", "CALCAV", "CALCVX", "CALCXV"].map((c) => [c, CALC])),
};
const AXIS_COMMANDS = ["SAP", "GAP", "STAP", "RSAP", "AAP"];
const GLOBAL_COMMANDS = ["SGP", "GGP", "STGP", "RSGP", "AGP"];

export class DirectPanel {
  constructor() {
    this.input = document.getElementById("direct-input");
    this.log = document.getElementById("direct-log");
    this.list = document.getElementById("direct-completions");
    this.history = JSON.parse(localStorage.getItem("tmclsim-history") || "[]");
    this.at = this.history.length;
    document.getElementById("direct-send").addEventListener("click", () => this.send());
    this.input.addEventListener("keydown", (e) => {
      if (e.key === "Enter") this.send();
      else if (e.key === "ArrowUp" && this.at > 0) {
        this.input.value = this.history[--this.at];
        e.preventDefault();
      } else if (e.key === "ArrowDown") {
        this.at = Math.min(this.history.length, this.at + 1);
        this.input.value = this.history[this.at] ?? "";
        e.preventDefault();
      } else if (e.key === "Tab") {
        e.preventDefault();
        this.complete();
      }
    });
    this.input.addEventListener("input", () => this.fillCompletions());
  }

  setModule(ctx) {
    this.ctx = ctx;
    const p = ctx.profile;
    this.commands = p ? p.commands : [];
    this.axisNames = p ? [...new Set(p.axis_parameters.map((r) => r.snake))] : [];
    this.globalNames = p ? [...new Set(p.global_parameters.map((r) => r.snake))] : [];
    this.fillCompletions();
  }

  /** Candidates for the word being typed: a mnemonic first, then its
   * first operand's symbols or parameter names. */
  candidates() {
    const text = this.input.value;
    const words = text.split(/[\s,]+/);
    const word = words[words.length - 1];
    const cmd = words[0].toUpperCase();
    let pool = [];
    if (words.length <= 1) pool = this.commands;
    else if (words.length === 2) pool = SYMBOLS[cmd] ?? (AXIS_COMMANDS.includes(cmd) ? this.axisNames : GLOBAL_COMMANDS.includes(cmd) ? this.globalNames : []);
    return { word, text, hits: pool.filter((c) => c.toLowerCase().startsWith(word.toLowerCase())) };
  }

  fillCompletions() {
    const { word, text, hits } = this.candidates();
    const head = text.slice(0, text.length - word.length);
    this.list.replaceChildren(...hits.slice(0, 30).map((h) => el("option", { value: head + h })));
  }

  complete() {
    const { word, text, hits } = this.candidates();
    if (!hits.length) return;
    let common = hits[0];
    for (const h of hits) while (!h.toLowerCase().startsWith(common.toLowerCase())) common = common.slice(0, -1);
    // A unique mnemonic gets its space, a unique first operand its comma.
    const add = hits.length === 1 ? hits[0] + (text.trim().split(/[\s,]+/).length <= 1 ? " " : ", ") : common;
    this.input.value = text.slice(0, text.length - word.length) + add;
  }

  async send() {
    const line = this.input.value.trim();
    if (!line || !this.ctx) return;
    if (this.history[this.history.length - 1] !== line) this.history.push(line);
    localStorage.setItem("tmclsim-history", JSON.stringify(this.history.slice(-200)));
    this.at = this.history.length;
    // The line leaves the input and takes its place in the log at once, so
    // the next one can be typed while this one is on its way, and replies
    // stand in the order of their commands.
    this.input.value = "";
    const entry = el("div", { "data-testid": "direct-entry" });
    entry.append(el("div", { class: "req", text: `> ${line}` }));
    this.log.append(entry);
    const r = await post(m(this.ctx.id, "command"), { line });
    if (r.error) entry.append(el("div", { class: "err", "data-testid": "direct-reply", text: r.error }));
    else {
      // 136 type 0 answers text in place of a status and a value.
      const ok = r.version !== undefined || r.status >= 100;
      const text = r.version !== undefined ? r.text : `${r.text}   [${r.status} ${r.status_text}]`;
      entry.append(el("div", { class: ok ? "ok" : "err", "data-testid": "direct-reply", text }));
      entry.append(el("div", { class: "req", text: `  ${r.request}  →  ${r.reply}` }));
    }
    this.log.scrollTop = this.log.scrollHeight;
  }
}
