// Direct mode: one command line with history and completion (mnemonics and
// parameter names), replies decoded by the server.
import { post, el, m } from "./api.js";

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
    this.names = p ? [...p.axis_parameters, ...p.global_parameters].map((r) => r.snake) : [];
    this.fillCompletions();
  }

  /** Candidates for the word being typed: a mnemonic first, then names. */
  candidates() {
    const text = this.input.value;
    const words = text.split(/[\s,]+/);
    const word = words[words.length - 1];
    const pool = words.length <= 1 ? this.commands : this.names;
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
    const add = hits.length === 1 ? hits[0] + (text.trim().split(/\s+/).length <= 1 ? " " : "") : common;
    this.input.value = text.slice(0, text.length - word.length) + add;
  }

  async send() {
    const line = this.input.value.trim();
    if (!line || !this.ctx) return;
    if (this.history[this.history.length - 1] !== line) this.history.push(line);
    localStorage.setItem("tmclsim-history", JSON.stringify(this.history.slice(-200)));
    this.at = this.history.length;
    const r = await post(m(this.ctx.id, "command"), { line });
    const entry = el("div", { "data-testid": "direct-entry" });
    entry.append(el("div", { class: "req", text: `> ${line}` }));
    if (r.error) entry.append(el("div", { class: "err", "data-testid": "direct-reply", text: r.error }));
    else {
      entry.append(el("div", { class: r.status >= 100 ? "ok" : "err", "data-testid": "direct-reply", text: `${r.text}   [${r.status} ${r.status_text}]` }));
      entry.append(el("div", { class: "req", text: `  ${r.request}  →  ${r.reply}` }));
    }
    this.log.append(entry);
    this.log.scrollTop = this.log.scrollHeight;
    this.input.value = "";
  }
}
