//! The routes of the API (this crate's README) and the direct-mode,
//! parameter and world requests. Every command is a TMCL request through
//! the target.

use crate::app::{ApiError, App, bad, blocking};
use crate::security::Guard;
use axum::extract::{Path, State};
use axum::http::StatusCode;
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::Deserialize;
use serde_json::{Value, json};
use std::sync::Arc;
use tmclsim_ide::answers::{self, Read, Write};
use tmclsim_protocol::Instruction;

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
    Json(json!({
        "target": app.target.kind(), "link": app.target.describe(), "speed": app.target.speed(),
        "behind": app.target.fell_behind(), "version": env!("CARGO_PKG_VERSION"),
    }))
}

async fn modules(State(app): State<App>) -> Json<Value> {
    Json(answers::modules_json(app.target.as_ref()))
}

/// `POST /api/scan`: the modules that answer on a link target's link,
/// whether or not the app lists them.
async fn scan(State(app): State<App>) -> Result<Json<Value>, ApiError> {
    // A scan asks every address: none may be in download mode.
    let used = app.all_idle().map_err(|_| ApiError(StatusCode::CONFLICT, "a program is being downloaded: scan when it is done".into()))?;
    let listed: Vec<u8> = app.target.modules().iter().map(|m| m.address).collect();
    let found = blocking(move || {
        let _used = used;
        app.target.scan()
    })
    .await??;
    let list: Vec<Value> = found
        .iter()
        .map(|f| json!({"address": f.address, "firmware": f.firmware, "profile": f.profile, "listed": listed.contains(&f.address)}))
        .collect();
    Ok(Json(json!({ "modules": list })))
}

async fn profile(State(app): State<App>, Path(id): Path<usize>) -> Result<Json<Value>, ApiError> {
    let p = app.profile(id)?.ok_or_else(|| ApiError(StatusCode::NOT_FOUND, "tmclsim has no profile of this module's type".into()))?;
    Ok(Json(tmclsim_ide::profile_json::of(&p)))
}

/// A request and its reply as the app shows them.
pub fn exchange(app: &App, id: usize, ins: Instruction) -> Result<Value, ApiError> {
    Ok(answers::exchange(app.target.as_ref(), id, ins)?)
}

#[derive(Deserialize)]
struct CommandBody {
    line: String,
}

async fn command(State(app): State<App>, Path(id): Path<usize>, Json(body): Json<CommandBody>) -> Result<Json<Value>, ApiError> {
    let used = app.idle(id)?;
    let ins = answers::parse_line(app.target.as_ref(), id, &body.line).map_err(bad)?;
    Ok(Json(
        blocking(move || {
            let _used = used;
            exchange(&app, id, ins)
        })
        .await??,
    ))
}

#[derive(Deserialize)]
struct ReadBody {
    reads: Vec<Read>,
}

async fn read(State(app): State<App>, Path(id): Path<usize>, Json(body): Json<ReadBody>) -> Result<Json<Value>, ApiError> {
    let used = app.observable(id)?;
    Ok(Json(
        blocking(move || {
            let _used = used;
            answers::read_json(app.target.as_ref(), id, &body.reads)
        })
        .await??,
    ))
}

async fn write(State(app): State<App>, Path(id): Path<usize>, Json(w): Json<Write>) -> Result<Json<Value>, ApiError> {
    let used = app.idle(id)?;
    let ins = w.instruction().map_err(bad)?;
    Ok(Json(
        blocking(move || {
            let _used = used;
            exchange(&app, id, ins)
        })
        .await??,
    ))
}

#[derive(Deserialize)]
struct WorldBody {
    line: String,
}

async fn world(State(app): State<App>, Path(id): Path<usize>, Json(b): Json<WorldBody>) -> Result<Json<Value>, ApiError> {
    Ok(Json(blocking(move || answers::world_json(app.target.as_ref(), id, &b.line)).await??))
}

async fn world_state(State(app): State<App>, Path(id): Path<usize>) -> Result<Json<Value>, ApiError> {
    app.address(id)?;
    let s = blocking(move || app.target.snapshot(id))
        .await?
        .ok_or_else(|| ApiError(StatusCode::CONFLICT, "the world exists only around virtual modules".into()))?;
    Ok(Json(answers::world_state_json(&s)))
}
