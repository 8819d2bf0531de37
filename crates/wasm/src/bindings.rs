//! The JavaScript class `Module`: each method calls [`Sim`] and turns its
//! values into JavaScript ones (plain objects, `Uint8Array`s, `Error`s).

use crate::page::Page;
use crate::sim::{Answer, Assembled, Failure, Sim, mode_name};
use js_sys::{Array, Error, Object, Reflect};
use wasm_bindgen::prelude::*;

/// A plain object from `(key, value)` pairs.
fn object(fields: &[(&str, JsValue)]) -> JsValue {
    let o = Object::new();
    for (key, value) in fields {
        // Setting a property of a fresh plain object cannot fail.
        let _ = Reflect::set(&o, &JsValue::from_str(key), value);
    }
    o.into()
}

/// An `Error` with the message, and a `column` property for a line that
/// does not parse.
fn error(f: Failure) -> JsValue {
    let e = Error::new(&match f.column {
        Some(c) => format!("column {c}: {}", f.message),
        None => f.message,
    });
    if let Some(c) = f.column {
        let _ = Reflect::set(&e, &JsValue::from_str("column"), &JsValue::from(c as u32));
    }
    e.into()
}

fn answer(a: Answer) -> JsValue {
    let mut fields = vec![("status", JsValue::from(a.status)), ("value", JsValue::from(a.value))];
    if let Some(text) = a.text {
        fields.push(("text", JsValue::from(text)));
    }
    object(&fields)
}

fn assembled(a: Assembled) -> JsValue {
    let words: Array = a
        .words
        .iter()
        .map(|w| {
            let i = w.instruction;
            object(&[
                ("opcode", i.opcode.into()),
                ("type", i.kind.into()),
                ("motor", i.motor.into()),
                ("value", i.value.into()),
                ("text", w.text.as_str().into()),
                ("line", w.line.into()),
            ])
        })
        .collect();
    let diagnostics: Array = a
        .diagnostics
        .iter()
        .map(|d| object(&[("line", (d.line as u32).into()), ("column", (d.column as u32).into()), ("message", d.message.as_str().into())]))
        .collect();
    object(&[("ok", a.ok().into()), ("words", words.into()), ("diagnostics", diagnostics.into())])
}

/// One virtual TMCL module in virtual time that moves only when told.
#[wasm_bindgen(js_name = Module)]
pub struct JsModule {
    sim: Sim,
}

#[wasm_bindgen(js_class = Module)]
impl JsModule {
    /// `new Module("tmcm-1141")`, optionally in a world: `"stage"` (the
    /// default), `"free"` or the TOML text of a world. An unknown profile
    /// throws an `Error` that lists the known ones.
    #[wasm_bindgen(constructor)]
    pub fn new(profile: &str, world: Option<String>) -> Result<JsModule, JsValue> {
        Sim::new(profile, world.as_deref()).map(|sim| JsModule { sim }).map_err(error)
    }

    /// The built-in profiles' names.
    pub fn profiles() -> Vec<String> {
        Sim::profiles().into_iter().map(String::from).collect()
    }

    /// The module's name (`"TMCM-1141"`).
    #[wasm_bindgen(getter)]
    pub fn profile(&self) -> String {
        self.sim.profile()
    }

    /// The address the module answers to now.
    #[wasm_bindgen(getter)]
    pub fn address(&self) -> u8 {
        self.sim.address()
    }

    /// Nine bytes from the host; the reply's nine bytes, empty when the
    /// module does not answer.
    pub fn frame(&mut self, bytes: &[u8]) -> Result<Vec<u8>, JsValue> {
        self.sim.frame(bytes).map_err(error)
    }

    /// A mnemonic line (`"SAP 4, 0, 1000"`) → `{status, value, text?}`.
    pub fn command(&mut self, line: &str) -> Result<JsValue, JsValue> {
        self.sim.command(line).map(answer).map_err(error)
    }

    /// Moves virtual time on by `seconds`.
    pub fn advance(&mut self, seconds: f64) -> Result<(), JsValue> {
        self.sim.advance(seconds).map_err(error)
    }

    /// Virtual time in seconds.
    pub fn time(&self) -> f64 {
        self.sim.time()
    }

    /// `{ok, words, diagnostics}` for a TMCL source.
    pub fn assemble(&self, source: &str) -> JsValue {
        assembled(self.sim.assemble(source))
    }

    /// Assembles a source and loads it into program memory (as a
    /// download); the same answer as `assemble`.
    pub fn download(&mut self, source: &str) -> JsValue {
        assembled(self.sim.download(source))
    }

    /// Runs the program: on from where it is, or afresh from `start`.
    pub fn run(&mut self, start: Option<u32>) -> Result<(), JsValue> {
        self.sim.run(start).map_err(error)
    }

    /// Stops the program.
    pub fn stop(&mut self) -> Result<(), JsValue> {
        self.sim.stop().map_err(error)
    }

    /// Runs one instruction, then pauses; false when 10 s of virtual time
    /// passed first.
    pub fn step(&mut self) -> bool {
        self.sim.step()
    }

    /// `{pc, mode, accumulator, x, executed}`.
    pub fn state(&self) -> JsValue {
        let s = self.sim.state();
        object(&[
            ("pc", s.pc.into()),
            ("mode", mode_name(s.mode).into()),
            ("accumulator", s.accumulator.into()),
            ("x", s.x.into()),
            ("executed", (s.executed as f64).into()),
        ])
    }

    /// A world command (`"input 0 1"`, docs/world.md): its answer.
    pub fn world(&mut self, line: &str) -> Result<String, JsValue> {
        self.sim.world(line).map_err(error)
    }

    /// The 138 "target reached" events since the last call, nine bytes each.
    #[wasm_bindgen(js_name = takeEvents)]
    pub fn take_events(&mut self) -> Vec<js_sys::Uint8Array> {
        self.sim.take_events().iter().map(|e| js_sys::Uint8Array::from(&e[..])).collect()
    }
}

/// The browser IDE's modules in the page: its API (crates/web/README.md)
/// answered without a server, in JSON text.
#[wasm_bindgen(js_name = Playground)]
pub struct JsPlayground {
    page: Page,
}

#[wasm_bindgen(js_class = Playground)]
impl JsPlayground {
    /// A playground without modules.
    #[wasm_bindgen(constructor)]
    pub fn new() -> JsPlayground {
        JsPlayground { page: Page::new() }
    }

    /// A request of the API (`"POST"`, `"/api/modules/0/command"`, the
    /// body's JSON) → the answer's JSON; errors are `{"error": …}`.
    pub fn request(&mut self, method: &str, path: &str, body: &str) -> String {
        self.page.request(method, path, body).to_string()
    }

    /// One sample of module `id`'s live stream for a subscription's JSON.
    pub fn sample(&self, id: usize, subscription: &str) -> String {
        self.page.sample(id, subscription).to_string()
    }

    /// Moves every module's virtual time on by `seconds`.
    pub fn advance(&mut self, seconds: f64) -> Result<(), JsValue> {
        self.page.advance(seconds).map_err(error)
    }

    /// Virtual time runs `factor` times as fast as the page's clock (a
    /// positive number; an error says why another is refused).
    #[wasm_bindgen(js_name = setSpeed)]
    pub fn set_speed(&mut self, factor: f64) -> Result<(), JsValue> {
        self.page.set_speed(factor).map_err(error)
    }

    /// Moves virtual time on by what `seconds` of the page's clock make at
    /// the speed.
    #[wasm_bindgen(js_name = advanceWall)]
    pub fn advance_wall(&mut self, seconds: f64) -> Result<(), JsValue> {
        self.page.advance_wall(seconds).map_err(error)
    }
}

impl Default for JsPlayground {
    fn default() -> JsPlayground {
        JsPlayground::new()
    }
}
