// The playground's example programs (examples/playground/index.json) do
// what their menu entries say, in the JavaScript binding.
import { test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { initSync, Module } from "../../target/wasm/tmclsim.js";

initSync({ module: readFileSync(new URL("../../target/wasm/tmclsim_bg.wasm", import.meta.url)) });

const root = new URL("../../", import.meta.url);
const examples = JSON.parse(readFileSync(new URL("examples/playground/index.json", root), "utf8"));
const source = (name) => readFileSync(new URL(examples.find((x) => x.name === name).source, root), "utf8");

/** A TMCM-1141 on the stage running example `name`. */
function running(name) {
  const m = new Module("tmcm-1141");
  const a = m.download(source(name));
  assert.ok(a.ok, JSON.stringify(a.diagnostics));
  m.run();
  return m;
}

const get = (m, line) => m.command(line).value;

/** Advances in steps of 0.1 s until `done()` or `limit` seconds. */
function until(m, done, limit) {
  for (let t = 0; t < limit && !done(); t += 0.1) m.advance(0.1);
  return done();
}

test("every example has a name, a title, a text and a source that assembles", () => {
  assert.deepEqual(examples.map((x) => x.name), ["first-steps", "homing", "reference-searches", "stallguard"]);
  const m = new Module("tmcm-1141");
  for (const x of examples) {
    assert.ok(x.title && x.about, x.name);
    const a = m.assemble(source(x.name));
    assert.ok(a.ok && a.words.length > 3, `${x.name}: ${JSON.stringify(a.diagnostics)}`);
  }
});

test("the manual's first program goes back and forth for an hour", () => {
  const m = running("first-steps");
  const seen = new Set();
  for (let i = 0; i < 60; i++) {
    m.advance(60);
    seen.add(Math.sign(get(m, "GAP 1, 0")));
  }
  assert.equal(m.state().mode, "run");
  assert.ok(seen.has(1) && seen.has(-1), [...seen].join());
});

test("homing ends homed at the home switch", () => {
  const m = running("homing");
  assert.ok(until(m, () => m.state().mode === "stop", 60));
  assert.equal(get(m, "GGP 0, 2"), 1);
  assert.equal(get(m, "GAP 1, 0"), 0);
});

test("homing without a home switch times out", () => {
  const m = running("homing");
  m.world("switch 0 home release");
  assert.ok(until(m, () => m.state().mode === "stop", 120));
  assert.equal(get(m, "GGP 0, 2"), 2);
});

test("the reference searches find the left stop, then the home switch", () => {
  const m = running("reference-searches");
  assert.ok(until(m, () => m.state().mode === "stop", 300));
  assert.equal(get(m, "GGP 0, 2"), 2);
  assert.equal(get(m, "GAP 1, 0"), 0);
  assert.match(m.world("show"), /home 1/);
});

test("stallGuard2 stops the motor under a full load, and it turns again without", () => {
  const m = running("stallguard");
  m.advance(1);
  assert.equal(get(m, "GAP 3, 0"), 500);
  m.world("load 0 100");
  assert.ok(until(m, () => get(m, "GGP 0, 2") >= 1, 5));
  assert.equal(get(m, "GAP 3, 0"), 0);
  m.world("load 0 0");
  m.advance(2);
  assert.equal(get(m, "GAP 3, 0"), 500);
});
