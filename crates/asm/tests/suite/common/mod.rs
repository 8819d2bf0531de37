//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use tmclsim_asm::{Diagnostic, MemoryResolver, NoIncludes, Profile, Program, assemble};
use tmclsim_firmware::{Bus, Module};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

/// One millisecond of virtual time.
pub const MS: u64 = 1_000_000;

/// A module on a bus of its own, as the tests drive it: requests and
/// looks go to the module (it derefs to it), time moves on the bus.
pub struct BusOfOne(Bus);

impl BusOfOne {
    pub fn new(module: Module) -> BusOfOne {
        BusOfOne(Bus::single(module))
    }

    /// Moves virtual time on by `dt_ns`.
    pub fn advance(&mut self, dt_ns: u64) {
        self.0.advance(dt_ns);
    }
}

impl std::ops::Deref for BusOfOne {
    type Target = Module;
    fn deref(&self) -> &Module {
        self.0.module(0)
    }
}

impl std::ops::DerefMut for BusOfOne {
    fn deref_mut(&mut self) -> &mut Module {
        self.0.module_mut(0)
    }
}

pub fn tmcm_1141() -> Arc<Profile> {
    Profile::built_in("tmcm-1141").expect("built-in profile")
}

pub fn programs_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/programs")
}

/// Every example program under tests/programs, sorted by name.
pub fn example_programs() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(programs_dir())
        .expect("tests/programs")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "tmc"))
        .collect();
    files.sort();
    files
}

/// Assembles a source file of the tests, named by its path. The test reads
/// it (the assembler reads no files); its includes are the shipped ones.
/// Includes from disk are tested with the file resolver, in the server's
/// tests (crates/server/tests/suite/sources.rs).
pub fn assemble_path(path: impl AsRef<Path>, profile: Option<&Profile>) -> Result<Program, Vec<Diagnostic>> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assemble(&text, &path.display().to_string(), &NoIncludes, profile)
}

/// Assembles a source text without includes; panics with the diagnostics.
pub fn asm(source: &str) -> Program {
    assemble(source, "prog.tmc", &MemoryResolver::new(), None).unwrap_or_else(|d| panic!("{}", tmclsim_asm::render(&d)))
}

/// Assembles against the TMCM-1141; panics with the diagnostics.
pub fn asm_1141(source: &str) -> Program {
    let p = tmcm_1141();
    assemble(source, "prog.tmc", &MemoryResolver::new(), Some(&p)).unwrap_or_else(|d| panic!("{}", tmclsim_asm::render(&d)))
}

/// The diagnostics of a source that must fail, rendered one per line.
pub fn errors(source: &str, profile: bool) -> Vec<String> {
    let p = tmcm_1141();
    match assemble(source, "prog.tmc", &MemoryResolver::new(), profile.then_some(&*p)) {
        Ok(_) => panic!("expected errors for:\n{source}"),
        Err(d) => d.iter().map(ToString::to_string).collect(),
    }
}

/// A small deterministic random generator (xorshift64*).
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }

    pub fn byte(&mut self) -> u8 {
        self.next() as u8
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len() as u64) as usize]
    }
}

/// Sends a command (mnemonic or `#op type motor value`) to module address
/// 1; it must succeed (status 100). Returns its value.
pub fn send(m: &mut Module, line: &str) -> i32 {
    let f = Request::new(1, parse_line(line).unwrap()).encode();
    let r = Reply::decode(&m.handle_frame(&f).unwrap()).unwrap();
    assert_eq!(r.status, 100, "{line}");
    r.value
}
