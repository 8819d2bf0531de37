//! Programs from the app: assembling with diagnostics and the source map,
//! download with progress and verification (132, the words, 133, then 134
//! for every word), run/stop/pause/step/continue/reset (128–131), the
//! breakpoints, and the program's state (135, user variables).

use crate::app::{ASSEMBLERS, ApiError, App, bad, blocking};
use crate::target::{TargetError, check};
use axum::Json;
use axum::body::Body;
use axum::extract::{Path, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde::Deserialize;
use serde_json::{Value, json};
use tmclsim_asm::{MemoryResolver, Program};
use tmclsim_profile::Profile;
use tmclsim_protocol::{Instruction, Status, opcode};

/// Longest source the app sends (the assembler's own limit per file).
const MAX_SOURCE: usize = 2 << 20;
/// Assembles on the blocking pool, at most [`ASSEMBLERS`] at once.
async fn assemble_bounded(app: &App, source: String, profile: Option<std::sync::Arc<Profile>>) -> Result<Result<Program, Value>, ApiError> {
    let Ok(_slot) = app.assemblers.clone().try_acquire_owned() else {
        return Err(ApiError(
            axum::http::StatusCode::SERVICE_UNAVAILABLE,
            format!("the assembler is busy with {ASSEMBLERS} programs; try again when one is done"),
        ));
    };
    blocking(move || assembled(&source, profile.as_deref())).await
}
/// User variables shown in the state.
const SHOWN_VARIABLES: u8 = 16;

fn assembled(source: &str, profile: Option<&Profile>) -> Result<Program, Value> {
    tmclsim_asm::assemble(source, "program.tmc", &MemoryResolver::new(), profile).map_err(|diags| {
        let list: Vec<Value> =
            diags.iter().map(|d| json!({"file": d.file, "line": d.line, "column": d.column, "message": d.message})).collect();
        json!({"ok": false, "diagnostics": list})
    })
}

fn program_json(p: &Program) -> Value {
    let map: Vec<Value> = p
        .source_map
        .iter()
        .enumerate()
        .map(|(a, s)| json!({"address": a, "file": &*s.file, "line": s.line, "column": s.column, "text": s.text}))
        .collect();
    let listing: String =
        p.instructions.iter().enumerate().map(|(a, w)| format!("{a:5}  {}\n", tmclsim_protocol::mnemonic::format(*w))).collect();
    json!({"ok": true, "words": p.instructions.len(), "diagnostics": [], "source_map": map, "symbols": p.symbols, "listing": listing})
}

#[derive(Deserialize)]
pub struct AssembleBody {
    source: String,
    profile: Option<String>,
}

pub async fn assemble(State(app): State<App>, Json(b): Json<AssembleBody>) -> Result<Json<Value>, ApiError> {
    if b.source.len() > MAX_SOURCE {
        return Err(bad("a program is at most 2 MiB of source"));
    }
    let profile = match &b.profile {
        Some(name) => Some(Profile::built_in(&name.to_ascii_lowercase()).map_err(bad)?),
        None => None,
    };
    Ok(Json(match assemble_bounded(&app, b.source, profile).await? {
        Ok(p) => program_json(&p),
        Err(v) => v,
    }))
}

#[derive(Deserialize)]
pub struct DownloadBody {
    source: String,
}

/// Downloads and verifies, reporting progress on `tx` as JSON lines.
fn download_words(app: &App, id: usize, words: &[Instruction], tx: &tokio::sync::mpsc::Sender<String>) -> Result<(), TargetError> {
    let t = &app.target;
    let send = |v: Value| {
        let _ = tx.blocking_send(format!("{v}\n"));
    };
    let total = 2 * words.len();
    t.halt(id);
    check(&t.request(id, Instruction::new(opcode::STOP_APPLICATION, 0, 0, 0))?)?;
    check(&t.request(id, Instruction::new(opcode::ENTER_DOWNLOAD, 0, 0, 0))?)?;
    for (a, w) in words.iter().enumerate() {
        let r = t.request(id, *w)?;
        if r[2] != Status::Loaded.code() {
            let _ = t.request(id, Instruction::new(opcode::EXIT_DOWNLOAD, 0, 0, 0));
            return Err(TargetError::Failed(format!("word {a} was not stored: status {} ({})", r[2], crate::target::status_text(r[2]))));
        }
        if a % 8 == 7 || a + 1 == words.len() {
            send(json!({"progress": a + 1, "total": total}));
        }
    }
    check(&t.request(id, Instruction::new(opcode::EXIT_DOWNLOAD, 0, 0, 0))?)?;
    let address = app.target.modules().get(id).ok_or(TargetError::NoModule)?.address;
    for (a, w) in words.iter().enumerate() {
        let raw = t.request(id, Instruction::new(opcode::READ_MEMORY, 0, 0, a as i32))?;
        if raw[1] == address && raw[2] < 100 && raw[3] == opcode::READ_MEMORY {
            return Err(TargetError::Failed(format!("reading back word {a}: status {} (code protection?)", raw[2])));
        }
        let stored = Instruction::from_bytes(raw[1..8].try_into().expect("seven bytes"));
        if stored != *w {
            let f = tmclsim_protocol::mnemonic::format;
            return Err(TargetError::Failed(format!("word {a} reads back as {}, not {}", f(stored), f(*w))));
        }
        if a % 8 == 7 || a + 1 == words.len() {
            send(json!({"progress": words.len() + a + 1, "total": total}));
        }
    }
    Ok(())
}

pub async fn download(State(app): State<App>, Path(id): Path<usize>, Json(b): Json<DownloadBody>) -> Result<Response, ApiError> {
    if b.source.len() > MAX_SOURCE {
        return Err(bad("a program is at most 2 MiB of source"));
    }
    let profile = app.profile(id)?;
    let program = match assemble_bounded(&app, b.source, profile).await? {
        Ok(p) => p,
        Err(diagnostics) => return Ok(Json(diagnostics).into_response()),
    };
    let claim = app.start_download(id)?;
    let (tx, rx) = tokio::sync::mpsc::channel::<String>(64);
    tokio::task::spawn_blocking(move || {
        let _claim = claim;
        let words = &program.instructions;
        let end = match download_words(&app, id, words, &tx) {
            Ok(()) => json!({"done": true, "verified": true, "words": words.len(), "program": program_json(&program)}),
            Err(TargetError::Failed(e) | TargetError::Unsupported(e)) => json!({"error": e}),
            Err(TargetError::NoModule) => json!({"error": "no such module"}),
        };
        let _ = tx.blocking_send(format!("{end}\n"));
    });
    let stream = tokio_stream::StreamExt::map(tokio_stream::wrappers::ReceiverStream::new(rx), Ok::<_, std::convert::Infallible>);
    Ok(([(header::CONTENT_TYPE, "application/x-ndjson")], Body::from_stream(stream)).into_response())
}

/// The module's program memory as 134 reads it, up to the program's end
/// (the empty words after the last one are not part of it).
fn read_program(app: &App, id: usize) -> Result<Vec<Instruction>, TargetError> {
    let t = &app.target;
    let address = t.modules().get(id).ok_or(TargetError::NoModule)?.address;
    let words = app.profile(id).ok().flatten().map_or(u16::MAX, |p| p.module.program_memory);
    let mut all = Vec::new();
    for a in 0..i32::from(words) {
        let raw = t.request(id, Instruction::new(opcode::READ_MEMORY, 0, 0, a))?;
        if raw[1] == address && raw[2] < 100 && raw[3] == opcode::READ_MEMORY {
            // Past the memory's end (status 4), or code protection.
            if a > 0 && raw[2] == Status::InvalidValue.code() {
                break;
            }
            return Err(TargetError::Failed(format!("reading word {a}: status {} ({})", raw[2], crate::target::status_text(raw[2]))));
        }
        all.push(Instruction::from_bytes(raw[1..8].try_into().expect("seven bytes")));
    }
    let end = all.iter().rposition(|w| *w != Instruction::default()).map_or(0, |p| p + 1);
    all.truncate(end);
    Ok(all)
}

/// `GET program/source`: the program read back from the module (134),
/// disassembled.
pub async fn source(State(app): State<App>, Path(id): Path<usize>) -> Result<Json<Value>, ApiError> {
    app.idle(id)?;
    let words = blocking(move || read_program(&app, id)).await??;
    Ok(Json(json!({"words": words.len(), "source": tmclsim_asm::disassemble(&words, None)})))
}

fn word(raw: &[u8; 9]) -> i32 {
    i32::from_be_bytes([raw[4], raw[5], raw[6], raw[7]])
}

/// The program's state as TMCL reports it (135), with what only a virtual
/// module can add.
pub fn state_of(app: &App, id: usize) -> Result<Value, ApiError> {
    let t = &app.target;
    let variables = app.profile(id)?.map_or(0, |p| p.module.user_variables.min(u16::from(SHOWN_VARIABLES)) as u8);
    // One batch of reads, as an observer makes them (docs/behaviour.md
    // rule 86): 135 types 1…3, then the user variables.
    let mut reads: Vec<Instruction> = (1..=3).map(|kind| Instruction::new(opcode::APPLICATION_STATUS, kind, 0, 0)).collect();
    reads.extend((0..variables).map(|n| Instruction::new(opcode::GGP, n, 2, 0)));
    let (replies, _) = t.observe(id, &reads)?;
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
    // A breakpoint is where a stopped program stands: a stale hit (a run or
    // continue under way, a counter read before the hit was noted) is not
    // one.
    let pc = (status & 0xFFFF) as u16;
    let breakpoint = t.breakpoint_hit(id).filter(|&b| b == pc && mode != "running");
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
        use tmclsim_firmware::module::error_flag as e;
        for (bit, name) in [(e::TIMEOUT, "ETO"), (e::ALARM, "EAL"), (e::DEVIATION, "EDV"), (e::POSITION, "EPO"), (e::SHUTDOWN, "ESD")] {
            if p.errors & bit != 0 {
                f.push(name);
            }
        }
        f.join(" ")
    });
    Ok(json!({
        "mode": mode, "pc": pc, "waiting": (status >> 16) & 0xFF == 1,
        "accumulator": accumulator, "x": x, "flags": flags,
        "errors": snap.as_ref().map(|s| s.program.errors),
        "stack_depth": snap.as_ref().map(|s| s.program.stack_depth),
        "breakpoint": breakpoint, "breakpoints": t.breakpoints(id), "user_variables": user,
        "time": t.time(id),
    }))
}

pub async fn state(State(app): State<App>, Path(id): Path<usize>) -> Result<Json<Value>, ApiError> {
    app.observable(id)?;
    Ok(Json(blocking(move || state_of(&app, id)).await??))
}

#[derive(Deserialize)]
pub struct BreakpointsBody {
    addresses: Vec<u16>,
}

pub async fn breakpoints(State(app): State<App>, Path(id): Path<usize>, Json(b): Json<BreakpointsBody>) -> Result<Json<Value>, ApiError> {
    app.idle(id)?;
    // One breakpoint per word of program memory at most.
    if let Some(p) = app.profile(id)? {
        let words = usize::from(p.module.program_memory);
        if let Some(a) = b.addresses.iter().find(|&&a| usize::from(a) >= words) {
            return Err(bad(format!("breakpoint at {a}: the program memory has addresses 0…{}", words - 1)));
        }
        if b.addresses.len() > words {
            return Err(bad(format!("at most {words} breakpoints (one per word of program memory)")));
        }
    }
    Ok(Json(
        blocking(move || {
            app.target.set_breakpoints(id, &b.addresses)?;
            state_of(&app, id)
        })
        .await??,
    ))
}

pub async fn action(State(app): State<App>, Path((id, action)): Path<(usize, String)>) -> Result<Json<Value>, ApiError> {
    app.idle(id)?;
    let ins = |op: u8, kind: u8| Instruction::new(op, kind, 0, 0);
    let out = blocking(move || -> Result<Value, ApiError> {
        let t = &app.target;
        match action.as_str() {
            "run" => t.run(id, true)?,
            "continue" => t.run(id, false)?,
            "stop" | "pause" => {
                t.halt(id);
                check(&t.request(id, ins(opcode::STOP_APPLICATION, 0))?)?;
            }
            "step" => {
                t.halt(id);
                check(&t.request(id, ins(opcode::STEP_APPLICATION, 0))?)?;
            }
            "reset" => {
                t.halt(id);
                check(&t.request(id, ins(opcode::RESET_APPLICATION, 0))?)?;
            }
            other => return Err(bad(format!("'{other}': use run, stop, pause, continue, step or reset"))),
        }
        state_of(&app, id)
    })
    .await??;
    Ok(Json(out))
}
