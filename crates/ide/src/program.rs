//! Programs: assembling with diagnostics and the source map, the download
//! with progress and verification (132, the words, the NOP TMCL-IDE sends
//! after them, 133, then 134 for every word), reading a program back, and
//! the program's state (135, user variables, and what only a virtual
//! module can add).

use crate::answers::entry;
use crate::download::DownloadError;
use crate::target::{Target, TargetError, check};
use serde_json::{Value, json};
use tmclsim_asm::{MemoryResolver, Program};
use tmclsim_profile::Profile;
use tmclsim_protocol::{Instruction, Status, opcode};

/// Longest source the app sends (the assembler's own limit per file).
pub const MAX_SOURCE: usize = 2 << 20;
/// User variables shown in the state.
const SHOWN_VARIABLES: u8 = 16;

/// A source longer than [`MAX_SOURCE`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TooLong;

impl std::fmt::Display for TooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "a program is at most 2 MiB of source")
    }
}

impl std::error::Error for TooLong {}

impl From<TooLong> for String {
    fn from(e: TooLong) -> String {
        e.to_string()
    }
}

/// A source too long to assemble, in words.
pub fn check_size(source: &str) -> Result<(), TooLong> {
    if source.len() > MAX_SOURCE { Err(TooLong) } else { Ok(()) }
}

/// The program, or `{"ok": false, "diagnostics": […]}`.
pub fn assemble(source: &str, profile: Option<&Profile>) -> Result<Program, Value> {
    tmclsim_asm::assemble(source, "program.tmc", &MemoryResolver::new(), profile).map_err(|diags| {
        let list: Vec<Value> =
            diags.iter().map(|d| json!({"file": d.file, "line": d.line, "column": d.column, "message": d.message})).collect();
        json!({"ok": false, "diagnostics": list})
    })
}

/// An assembled program as the app shows it: its size (the STOP the
/// assembler appends included, docs/behaviour.md rule 93), the source map
/// (which has no line for that STOP), the labels and a listing.
pub fn program_json(p: &Program) -> Value {
    let map: Vec<Value> = p
        .source_map
        .iter()
        .enumerate()
        .map(|(a, s)| json!({"address": a, "file": &*s.file, "line": s.line, "column": s.column, "text": s.text}))
        .collect();
    let appended = p.appended_stop_address().map(|a| a as usize);
    let listing: String = p
        .instructions
        .iter()
        .enumerate()
        .map(|(a, w)| {
            let note = if Some(a) == appended { "  // appended: the program does not end in STOP" } else { "" };
            format!("{a:5}  {}{note}\n", tmclsim_protocol::mnemonic::format(*w))
        })
        .collect();
    json!({
        "ok": true, "words": p.instructions.len(), "appended_stop": p.appended_stop, "diagnostics": [],
        "source_map": map, "symbols": p.symbols, "listing": listing,
    })
}

/// The answer to an assembly: the program or its diagnostics.
pub fn assemble_json(source: &str, profile: Option<&Profile>) -> Value {
    match assemble(source, profile) {
        Ok(p) => program_json(&p),
        Err(v) => v,
    }
}

/// Downloads the words and verifies them by reading them back
/// ([`crate::download`]), reporting progress (`{"progress": n, "total": n}`)
/// to `progress` every eight words.
pub fn download_words(target: &dyn Target, id: usize, words: &[Instruction], progress: &mut dyn FnMut(Value)) -> Result<(), TargetError> {
    let address = entry(target, id)?.address;
    let (len, total) = (words.len(), 2 * words.len());
    target.halt(id);
    let mut request = |ins: Instruction| target.request(id, ins);
    let mut report = |done: usize| {
        let k = if done > len { done - len } else { done };
        if k % 8 == 0 || k == len {
            progress(json!({"progress": done, "total": total}));
        }
    };
    crate::download::download_and_verify(&mut request, address, words, &mut report).map_err(|e| match e {
        DownloadError::Link(e) => e,
        e => TargetError::Failed(e.to_string()),
    })
}

/// The last line of a download's answer: done and verified, or the error.
pub fn download_end(target: &dyn Target, id: usize, program: &Program, progress: &mut dyn FnMut(Value)) -> Value {
    let words = &program.instructions;
    match download_words(target, id, words, progress) {
        Ok(()) => json!({"done": true, "verified": true, "words": words.len(), "program": program_json(program)}),
        Err(e) => json!({"error": e.to_string()}),
    }
}

/// The module's program memory as 134 reads it, up to the program's end
/// (the empty words after the last one are not part of it).
pub fn read_program(target: &dyn Target, id: usize) -> Result<Vec<Instruction>, TargetError> {
    let m = entry(target, id)?;
    let address = m.address;
    let words = m.profile.as_ref().map_or(u16::MAX, |p| p.module.program_memory);
    let mut all = Vec::new();
    for a in 0..i32::from(words) {
        let raw = target.request(id, Instruction::new(opcode::READ_MEMORY, 0, 0, a))?;
        match crate::reply::memory_word(&raw, address) {
            Ok(word) => all.push(word),
            // Past the memory's end (status 4), or code protection.
            Err(status) if a > 0 && status == Status::InvalidValue.code() => break,
            Err(status) => {
                return Err(TargetError::Failed(format!("reading word {a}: status {status} ({})", Status::text(status))));
            }
        }
    }
    let end = all.iter().rposition(|w| *w != Instruction::default()).map_or(0, |p| p + 1);
    all.truncate(end);
    Ok(all)
}

/// `{"words": n, "source": text}`: the program read back, disassembled.
pub fn source_json(target: &dyn Target, id: usize) -> Result<Value, TargetError> {
    let words = read_program(target, id)?;
    Ok(json!({"words": words.len(), "source": tmclsim_asm::disassemble(&words, None)}))
}

fn word(raw: &[u8; 9]) -> i32 {
    i32::from_be_bytes([raw[4], raw[5], raw[6], raw[7]])
}

/// The program's state as TMCL reports it (135), with what only a virtual
/// module can add.
pub fn state_of(target: &dyn Target, id: usize) -> Result<Value, TargetError> {
    let t = target;
    let variables = entry(t, id)?.profile.as_ref().map_or(0, |p| p.module.user_variables.min(u16::from(SHOWN_VARIABLES)) as u8);
    // One batch of reads, as an observer makes them (docs/behaviour.md
    // rule 86): 135 types 1…3, then the user variables.
    let mut reads: Vec<Instruction> = (1..=3).map(|kind| Instruction::new(opcode::APPLICATION_STATUS, kind, 0, 0)).collect();
    reads.extend((0..variables).map(|n| Instruction::new(opcode::GGP, n, 2, 0)));
    // The module's clock at the reads: a page that gets states by two ways
    // (the answers to its requests, the live stream) shows the newest and
    // drops one that comes late.
    let (replies, time) = t.observe(id, &reads)?;
    for raw in &replies[..3] {
        check(raw)?;
    }
    let status = word(&replies[0]) as u32;
    let (accumulator, x) = (word(&replies[1]), word(&replies[2]));
    let mode = match status >> 24 {
        0 => "stopped",
        1 => "running",
        2 => "step",
        _ => "reset",
    };
    // A breakpoint is where a paused program stands (step mode, its counter
    // on the hit): a stale hit is not one, whether a run or continue is
    // under way, the counter was read before the hit was noted, or the
    // program was stopped (128) or downloaded since.
    let pc = (status & 0xFFFF) as u16;
    let breakpoint = t.breakpoint_hit(id).filter(|&b| b == pc && mode == "step");
    let user: Vec<Option<i32>> = replies[3..].iter().map(|raw| (raw[2] >= 100).then(|| word(raw))).collect();
    let snap = t.snapshot(id);
    // The comparison flags JC tests (EQ/ZE, LT, GT) and the error flags.
    let flags = snap.as_ref().map(|s| {
        let p = &s.program;
        let mut f = vec![match p.compare {
            -1 => "LT",
            0 => "EQ ZE",
            _ => "GT",
        }];
        f.extend(crate::observe::error_flag_names(p.errors));
        f.join(" ")
    });
    Ok(json!({
        "mode": mode, "pc": pc, "waiting": (status >> 16) & 0xFF == 1,
        "accumulator": accumulator, "x": x, "flags": flags,
        "errors": snap.as_ref().map(|s| s.program.errors),
        "stack_depth": snap.as_ref().map(|s| s.program.stack_depth),
        "breakpoint": breakpoint, "breakpoints": t.breakpoints(id), "user_variables": user,
        "time": time,
    }))
}

/// Checks breakpoint addresses against module `id`'s program memory.
pub fn check_breakpoints(target: &dyn Target, id: usize, addresses: &[u16]) -> Result<(), BreakpointError> {
    let Some(p) = target.modules().get(id).and_then(|m| m.profile.clone()) else { return Ok(()) };
    // One breakpoint per word of program memory at most.
    let words = usize::from(p.module.program_memory);
    if let Some(a) = addresses.iter().find(|&&a| usize::from(a) >= words) {
        return Err(BreakpointError::Outside { address: *a, words });
    }
    if addresses.len() > words {
        return Err(BreakpointError::TooMany { words });
    }
    Ok(())
}

/// Why breakpoints were refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BreakpointError {
    /// An address past the program memory.
    Outside {
        /// The address.
        address: u16,
        /// Words of program memory.
        words: usize,
    },
    /// More breakpoints than words of program memory.
    TooMany {
        /// Words of program memory.
        words: usize,
    },
}

impl std::fmt::Display for BreakpointError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BreakpointError::Outside { address, words } => {
                write!(f, "breakpoint at {address}: the program memory has addresses 0…{}", words - 1)
            }
            BreakpointError::TooMany { words } => write!(f, "at most {words} breakpoints (one per word of program memory)"),
        }
    }
}

impl std::error::Error for BreakpointError {}

impl From<BreakpointError> for String {
    fn from(e: BreakpointError) -> String {
        e.to_string()
    }
}

/// run, continue, stop, pause, step or reset; then the state.
pub fn action(target: &dyn Target, id: usize, action: &str) -> Result<Value, ActionError> {
    let t = target;
    let ins = |op: u8| Instruction::new(op, 0, 0, 0);
    match action {
        "run" => t.run(id, true)?,
        "continue" => t.run(id, false)?,
        "stop" | "pause" => {
            t.halt(id);
            check(&t.request(id, ins(opcode::STOP_APPLICATION))?)?;
        }
        "step" => {
            t.halt(id);
            check(&t.request(id, ins(opcode::STEP_APPLICATION))?)?;
        }
        "reset" => {
            t.halt(id);
            check(&t.request(id, ins(opcode::RESET_APPLICATION))?)?;
        }
        other => return Err(ActionError::Unknown(format!("'{other}': use run, stop, pause, continue, step or reset"))),
    }
    Ok(state_of(t, id)?)
}

/// Why a program action failed: an unknown action, or the target's error.
#[derive(Debug)]
pub enum ActionError {
    /// No such action (the message says which there are).
    Unknown(String),
    /// The target failed.
    Target(TargetError),
}

impl From<TargetError> for ActionError {
    fn from(e: TargetError) -> ActionError {
        ActionError::Target(e)
    }
}
