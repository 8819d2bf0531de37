//! tmclsim in JavaScript: a WebAssembly module (wasm-bindgen) with one
//! virtual TMCL module per `Module` object, in stepped virtual time (the
//! wall clock is never read), and the assembler. `scripts/wasm` builds
//! `target/wasm/tmclsim.js`; docs/playground.md describes the API.
//!
//! [`sim::Sim`] holds the logic in plain Rust (tested natively); the
//! binding in `bindings.rs` turns its values into JavaScript ones.
//! [`page::Page`] is the playground's side of the browser IDE: its API
//! answered in the page, over `Sim`s (the class `Playground`).

// A binding: its public items are the JavaScript API that wasm-bindgen
// generates.
#![allow(missing_docs)]

mod bindings;
pub mod page;
pub mod sim;

pub use bindings::{JsModule, JsPlayground};
