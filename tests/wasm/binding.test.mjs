// The JavaScript binding (crates/wasm) as scripts/wasm builds it, in node:
// `node --test tests/wasm/` after scripts/wasm.
import { test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import init, { initSync, Module } from "../../target/wasm/tmclsim.js";

const wasm = readFileSync(new URL("../../target/wasm/tmclsim_bg.wasm", import.meta.url));
initSync({ module: wasm });

const checksum = (bytes) => bytes.slice(0, 8).reduce((a, b) => (a + b) & 0xff, 0);
const int32 = (b) => new DataView(b.buffer, b.byteOffset + 4, 4).getInt32(0);

test("init is the default export, as a page imports it", () => {
    assert.equal(typeof init, "function");
});

test("profiles, address and the profile's name", () => {
    const profiles = Module.profiles();
    assert.ok(profiles.includes("tmcm-1141"), profiles.join());
    const m = new Module("tmcm-1141");
    assert.equal(m.profile, "TMCM-1141");
    assert.equal(m.address, 1);
    assert.equal(new Module("1310").profile, "TMCM-1310");
});

test("an unknown profile throws an Error naming the known ones", () => {
    assert.throws(() => new Module("tmcm-9999"), (e) => e instanceof Error && /tmcm-9999/.test(e.message) && /tmcm-1141/.test(e.message));
    assert.throws(() => new Module("tmcm-1141", "moon"), /no built-in world 'moon'/);
});

test("SAP and GAP through command", () => {
    const m = new Module("tmcm-1141");
    assert.deepEqual(m.command("SAP 4, 0, 1000"), { status: 100, value: 1000 });
    assert.deepEqual(m.command("GAP 4, 0"), { status: 100, value: 1000 });
    assert.deepEqual(m.command("GAP 250, 0"), { status: 3, value: 0, text: "wrong type" });
    assert.equal(m.command("#136 0 0 0").text, "1141V146");
});

test("a line that does not parse throws with its column", () => {
    const m = new Module("tmcm-1141");
    assert.throws(() => m.command("SAP 4, 0, x"), (e) => e instanceof Error && e.column === 11 && /^column 11: /.test(e.message));
});

test("the manual's frame gets a 9-byte reply with status 100", () => {
    const m = new Module("tmcm-1141");
    const reply = m.frame(new Uint8Array([0x01, 0x06, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08]));
    assert.ok(reply instanceof Uint8Array);
    assert.equal(reply.length, 9);
    assert.deepEqual([...reply.slice(0, 4)], [2, 1, 100, 6]);
    assert.equal(reply[8], checksum(reply));
    assert.equal(int32(reply), 0, "GAP 1, 0 of a module at rest");
});

test("a wrong checksum gets status 1", () => {
    const m = new Module("tmcm-1141");
    const reply = m.frame([0x01, 0x06, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x09]);
    assert.equal(reply.length, 9);
    assert.equal(reply[2], 1);
});

test("a frame for another address gets no reply", () => {
    const m = new Module("tmcm-1141");
    const frame = [0x05, 0x06, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0];
    frame[8] = checksum(frame);
    const reply = m.frame(new Uint8Array(frame));
    assert.ok(reply instanceof Uint8Array);
    assert.equal(reply.length, 0);
});

test("a frame of another length throws", () => {
    const m = new Module("tmcm-1141");
    assert.throws(() => m.frame(new Uint8Array(8)), /a TMCL frame is 9 bytes, not 8/);
    assert.throws(() => m.frame(new Uint8Array(10)), /not 10/);
});

test("ROR moves the motor as virtual time advances", () => {
    const m = new Module("tmcm-1141");
    assert.equal(m.command("ROR 0, 500").status, 100);
    assert.equal(m.time(), 0);
    assert.equal(m.command("GAP 1, 0").value, 0, "time stands still until advanced");
    m.advance(1);
    assert.equal(m.time(), 1);
    assert.ok(m.command("GAP 1, 0").value > 0);
});

test("MVP ABS reaches its target after enough virtual time", () => {
    const m = new Module("tmcm-1141");
    m.command("MVP ABS, 0, 51200");
    m.advance(0.01);
    assert.equal(m.command("GAP 8, 0").value, 0);
    let waited = 0;
    while (m.command("GAP 8, 0").value !== 1 && waited < 60) {
        m.advance(0.5);
        waited += 0.5;
    }
    assert.equal(m.command("GAP 8, 0").value, 1, "target reached");
    assert.equal(m.command("GAP 1, 0").value, 51200);
});

test("advance refuses what is not a duration", () => {
    const m = new Module("tmcm-1141");
    for (const bad of [-1, NaN, Infinity, 1e12]) {
        assert.throws(() => m.advance(bad), Error, String(bad));
    }
    assert.equal(m.time(), 0);
});

test("a downloaded program runs to accumulator 7", () => {
    const m = new Module("tmcm-1141");
    const program = m.download("CALC LOAD, 5\nCALC ADD, 2\nSTOP\n");
    assert.equal(program.ok, true);
    assert.deepEqual(program.diagnostics, []);
    assert.deepEqual(
        program.words.map((w) => [w.opcode, w.type, w.motor, w.value, w.line]),
        [[19, 9, 0, 5, 1], [19, 0, 0, 2, 2], [28, 0, 0, 0, 3]],
    );
    assert.equal(program.words[1].text, "CALC ADD, 2");
    assert.deepEqual(m.state(), { pc: 0, mode: "reset", accumulator: 0, x: 0, executed: 0 });
    m.run();
    m.advance(0.01);
    const state = m.state();
    assert.equal(state.accumulator, 7);
    assert.equal(state.mode, "stop");
    assert.equal(state.executed, 3);
});

test("step runs one instruction, stop stops", () => {
    const m = new Module("tmcm-1141");
    m.download("Loop: CALC ADD, 1\nJA Loop\n");
    assert.equal(m.step(), true);
    assert.deepEqual([m.state().pc, m.state().accumulator, m.state().mode], [1, 1, "step"]);
    m.run();
    m.advance(0.001);
    assert.equal(m.state().mode, "run");
    m.stop();
    const stopped = m.state();
    assert.equal(stopped.mode, "stop");
    m.advance(0.1);
    assert.equal(m.state().accumulator, stopped.accumulator);
    assert.throws(() => m.run(5000), /invalid value/);
});

test("a source error is a diagnostic with line and column", () => {
    const m = new Module("tmcm-1141");
    const result = m.assemble("CALC LOAD, 5\n  FOO 1\n");
    assert.equal(result.ok, false);
    assert.deepEqual(result.words, []);
    assert.equal(result.diagnostics[0].line, 2);
    assert.equal(result.diagnostics[0].column, 3);
    assert.match(result.diagnostics[0].message, /FOO/);
    assert.equal(m.download("  FOO 1\n").ok, false, "nothing is loaded");
});

test("world commands change the inputs; bad ones throw", () => {
    const m = new Module("tmcm-1141");
    assert.equal(m.command("GIO 0, 0").value, 0);
    m.world("input 0 1");
    assert.equal(m.command("GIO 0, 0").value, 1);
    assert.match(m.world("help"), /input N/);
    assert.throws(() => m.world("fly 0"), Error);
});

test("target reached events are kept until taken", () => {
    const m = new Module("tmcm-1141");
    m.command("#138 0 0 1");
    m.command("MVP ABS, 0, 1000");
    m.advance(5);
    const events = m.takeEvents();
    assert.equal(events.length, 1);
    assert.equal(events[0][2], 128);
    assert.equal(m.takeEvents().length, 0);
});

test("the playground's speed: virtual time runs N times as fast as the page's clock", async () => {
  const { Playground } = await import("../../target/wasm/tmclsim.js");
  const p = new Playground();
  const info = () => JSON.parse(p.request("GET", "/api/info", ""));
  assert.equal(info().speed, 1);
  p.request("POST", "/api/modules", JSON.stringify({ profile: "tmcm-1141" }));
  const ticks = () => JSON.parse(p.request("POST", "/api/modules/0/command", JSON.stringify({ line: "GGP 132, 0" }))).value;
  p.setSpeed(50);
  assert.equal(info().speed, 50);
  const before = ticks();
  p.advanceWall(0.1);
  assert.equal(ticks() - before, 5000, "0.1 s of the page's clock are 5 virtual seconds");
  for (const bad of [0, -1, NaN, Infinity]) {
    assert.throws(() => p.setSpeed(bad), /is not a positive finite number/, String(bad));
  }
  assert.equal(info().speed, 50, "a refused speed changes nothing");
});
