//! The routes of the API (this crate's README) and the direct-mode,
//! parameter and world requests. Every command is a TMCL request through
//! the target.

use crate::app::{ApiError, App, bad, blocking};
use crate::read::{Read, ReadKind, read_all};
use crate::security::Guard;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::Deserialize;
use serde_json::{Value, json};
use std::sync::Arc;
use tmclsim_profile::Profile;
use tmclsim_protocol::{FRAME_LEN, Instruction, Request, opcode};

pub fn router(app: App) -> Router {
    let m = "/api/modules/{id}";
    Router::new()
        .route("/", get(crate::assets::index))
        .route("/assets/{*path}", get(crate::assets::asset))
        .route("/api/info", get(info))
        .route("/api/modules", get(modules))
        .route("/api/scan", post(scan))
        .route(&format!("{m}/profile"), get(profile))
        .route(&format!("{m}/command"), post(command))
        .route(&format!("{m}/read"), post(read))
        .route(&format!("{m}/write"), post(write))
        .route(&format!("{m}/world"), get(world_state).post(world))
        .route(&format!("{m}/live"), get(crate::live::live))
        .route("/api/assemble", post(crate::program::assemble))
        .route(&format!("{m}/program/download"), post(crate::program::download))
        .route(&format!("{m}/program/state"), get(crate::program::state))
        .route(&format!("{m}/program/source"), get(crate::program::source))
        .route(&format!("{m}/program/breakpoints"), post(crate::program::breakpoints))
        .route(&format!("{m}/program/{{action}}"), post(crate::program::action))
        .layer(axum::middleware::from_fn_with_state(Arc::new(Guard::new(app.token.clone())), crate::security::guard))
        .with_state(app)
}

async fn info(State(app): State<App>) -> Json<Value> {
    Json(json!({ "target": app.target.kind(), "link": app.target.describe(), "version": env!("CARGO_PKG_VERSION") }))
}

async fn modules(State(app): State<App>) -> Json<Value> {
    let virt = app.target.kind() == "virtual";
    let list: Vec<Value> = app
        .target
        .modules()
        .iter()
        .enumerate()
        .map(|(id, m)| {
            json!({"id": id, "address": m.address, "profile": m.profile.as_ref().map(|p| p.module.name.clone()),
                   "firmware": m.firmware, "link": m.link, "virtual": virt})
        })
        .collect();
    Json(Value::Array(list))
}

/// `POST /api/scan`: the modules that answer on a link target's link,
/// whether or not the app lists them.
async fn scan(State(app): State<App>) -> Result<Json<Value>, ApiError> {
    if (0..app.target.modules().len()).any(|id| app.is_downloading(id)) {
        return Err(ApiError(StatusCode::CONFLICT, "a program is being downloaded: scan when it is done".into()));
    }
    let listed: Vec<u8> = app.target.modules().iter().map(|m| m.address).collect();
    let found = blocking(move || app.target.scan()).await??;
    let list: Vec<Value> = found
        .iter()
        .map(|f| json!({"address": f.address, "firmware": f.firmware, "profile": f.profile, "listed": listed.contains(&f.address)}))
        .collect();
    Ok(Json(json!({ "modules": list })))
}

async fn profile(State(app): State<App>, Path(id): Path<usize>) -> Result<Json<Value>, ApiError> {
    let p = app.profile(id)?.ok_or_else(|| ApiError(StatusCode::NOT_FOUND, "tmclsim has no profile of this module's type".into()))?;
    Ok(Json(crate::profile_json::of(&p)))
}

pub fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect::<Vec<_>>().join(" ")
}

/// A request and its reply as the app shows them.
pub fn exchange(app: &App, id: usize, ins: Instruction) -> Result<Value, ApiError> {
    let address = app.address(id)?;
    let profile = app.profile(id)?;
    let raw = app.target.request(id, ins)?;
    Ok(described(address, profile.as_deref(), ins, &raw))
}

fn described(address: u8, profile: Option<&Profile>, ins: Instruction, raw: &[u8; FRAME_LEN]) -> Value {
    let value = i32::from_be_bytes([raw[4], raw[5], raw[6], raw[7]]);
    if ins.opcode == opcode::FIRMWARE_VERSION && ins.kind == 0 {
        // The reply is text from its second byte on: no status, no value.
        let version = String::from_utf8_lossy(&raw[1..]).trim_end_matches('\0').to_string();
        return json!({
            "request": hex(&Request::new(address, ins).encode()), "reply": hex(raw),
            "status": null, "status_text": null, "value": null, "version": version,
            "text": format!("version {version}"),
        });
    }
    json!({
        "request": hex(&Request::new(address, ins).encode()), "reply": hex(raw),
        "status": raw[2], "status_text": crate::target::status_text(raw[2]), "value": value,
        "text": tmclsim_host::reply::describe(ins, raw, address, profile),
    })
}

#[derive(Deserialize)]
struct CommandBody {
    line: String,
}

async fn command(State(app): State<App>, Path(id): Path<usize>, Json(body): Json<CommandBody>) -> Result<Json<Value>, ApiError> {
    app.idle(id)?;
    let profile = app.profile(id)?;
    let ins = tmclsim_host::line::parse(&body.line, profile.as_deref()).map_err(|e| bad(format!("column {}: {}", e.column, e.message)))?;
    Ok(Json(blocking(move || exchange(&app, id, ins)).await??))
}

#[derive(Deserialize)]
struct ReadBody {
    reads: Vec<Read>,
}

async fn read(State(app): State<App>, Path(id): Path<usize>, Json(body): Json<ReadBody>) -> Result<Json<Value>, ApiError> {
    app.observable(id)?;
    if body.reads.len() > 4096 {
        return Err(bad("at most 4096 reads at once"));
    }
    let (values, t) = blocking(move || read_all(app.target.as_ref(), id, &body.reads)).await??;
    Ok(Json(json!({ "values": values, "t": t })))
}

#[derive(Deserialize)]
struct WriteBody {
    kind: ReadKind,
    number: u8,
    #[serde(default)]
    index: u8,
    value: Option<i64>,
    op: Option<String>,
}

async fn write(State(app): State<App>, Path(id): Path<usize>, Json(b): Json<WriteBody>) -> Result<Json<Value>, ApiError> {
    app.idle(id)?;
    let axis = match b.kind {
        ReadKind::Ap => true,
        ReadKind::Gp => false,
        _ => return Err(bad("write takes kind 'ap' or 'gp'; outputs are set with SIO in a command")),
    };
    let (set, store, restore) = if axis { (opcode::SAP, opcode::STAP, opcode::RSAP) } else { (opcode::SGP, opcode::STGP, opcode::RSGP) };
    let ins = match (b.op.as_deref(), b.value) {
        (None | Some("set"), Some(v)) => {
            let v = i32::try_from(v).map_err(|_| bad(format!("{v} does not fit a 32-bit value")))?;
            Instruction::new(set, b.number, b.index, v)
        }
        (None | Some("set"), None) => return Err(bad("give a value")),
        (Some("store"), _) => Instruction::new(store, b.number, b.index, 0),
        (Some("restore"), _) => Instruction::new(restore, b.number, b.index, 0),
        (Some(other), _) => return Err(bad(format!("op '{other}': use set, store or restore"))),
    };
    Ok(Json(blocking(move || exchange(&app, id, ins)).await??))
}

#[derive(Deserialize)]
struct WorldBody {
    line: String,
}

async fn world(State(app): State<App>, Path(id): Path<usize>, Json(b): Json<WorldBody>) -> Result<Json<Value>, ApiError> {
    if b.line.len() > 4096 {
        return Err(bad("a world line is at most 4096 bytes"));
    }
    let text = blocking(move || app.target.world(id, &b.line)).await??;
    Ok(Json(json!({ "ok": text })))
}

async fn world_state(State(app): State<App>, Path(id): Path<usize>) -> Result<Json<Value>, ApiError> {
    app.address(id)?;
    let s = blocking(move || app.target.snapshot(id))
        .await?
        .ok_or_else(|| ApiError(StatusCode::CONFLICT, "the world exists only around virtual modules".into()))?;
    let axes: Vec<Value> = s
        .axes
        .iter()
        .map(|a| {
            json!({"left": a.left, "right": a.right, "home": a.home, "load": a.load, "carriage": a.carriage,
                        "position": a.position, "speed": a.speed, "current": a.current, "stallguard": a.stallguard,
                        "stopped_by_switch": a.stopped_by_switch})
        })
        .collect();
    Ok(Json(json!({"time": s.time_ns as f64 * 1e-9, "axes": axes, "inputs": s.io.inputs, "outputs": s.io.outputs,
                   "analog": s.io.analog, "supply": s.io.supply, "temperature": s.io.temperature})))
}
