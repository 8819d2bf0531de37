//! Programs from the app (tmclsim_ide::program does the work): assembling
//! on the blocking pool, at most [`ASSEMBLERS`] at once, the download
//! streamed as progress lines, run/stop/pause/step/continue/reset
//! (128–131), the breakpoints, and the program's state.

use crate::app::{ASSEMBLERS, ApiError, App, bad, blocking};
use axum::Json;
use axum::body::Body;
use axum::extract::{Path, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde::Deserialize;
use serde_json::Value;
use tmclsim_asm::Program;
use tmclsim_ide::program::{self as ide, ActionError};
use tmclsim_profile::Profile;

/// Assembles on the blocking pool, at most [`ASSEMBLERS`] at once.
async fn assemble_bounded(app: &App, source: String, profile: Option<std::sync::Arc<Profile>>) -> Result<Result<Program, Value>, ApiError> {
    let Ok(_slot) = app.assemblers.clone().try_acquire_owned() else {
        return Err(ApiError(
            axum::http::StatusCode::SERVICE_UNAVAILABLE,
            format!("the assembler is busy with {ASSEMBLERS} programs; try again when one is done"),
        ));
    };
    blocking(move || ide::assemble(&source, profile.as_deref())).await
}

#[derive(Deserialize)]
pub struct AssembleBody {
    source: String,
    profile: Option<String>,
}

pub async fn assemble(State(app): State<App>, Json(b): Json<AssembleBody>) -> Result<Json<Value>, ApiError> {
    ide::check_size(&b.source).map_err(bad)?;
    let profile = match &b.profile {
        Some(name) => Some(Profile::built_in(&name.to_ascii_lowercase()).map_err(bad)?),
        None => None,
    };
    Ok(Json(match assemble_bounded(&app, b.source, profile).await? {
        Ok(p) => ide::program_json(&p),
        Err(v) => v,
    }))
}

#[derive(Deserialize)]
pub struct DownloadBody {
    source: String,
}

pub async fn download(State(app): State<App>, Path(id): Path<usize>, Json(b): Json<DownloadBody>) -> Result<Response, ApiError> {
    ide::check_size(&b.source).map_err(bad)?;
    let profile = app.profile(id)?;
    let program = match assemble_bounded(&app, b.source, profile).await? {
        Ok(p) => p,
        Err(diagnostics) => return Ok(Json(diagnostics).into_response()),
    };
    let claim = app.start_download(id)?;
    let (tx, rx) = tokio::sync::mpsc::channel::<String>(64);
    tokio::task::spawn_blocking(move || {
        claim.wait_for_requests();
        let mut send = |v: Value| {
            let _ = tx.blocking_send(format!("{v}\n"));
        };
        let end = ide::download_end(app.target.as_ref(), id, &program, &mut send);
        send(end);
        drop(claim);
    });
    let stream = tokio_stream::StreamExt::map(tokio_stream::wrappers::ReceiverStream::new(rx), Ok::<_, std::convert::Infallible>);
    Ok(([(header::CONTENT_TYPE, "application/x-ndjson")], Body::from_stream(stream)).into_response())
}

/// `GET program/source`: the program read back from the module (134),
/// disassembled.
pub async fn source(State(app): State<App>, Path(id): Path<usize>) -> Result<Json<Value>, ApiError> {
    let used = app.idle(id)?;
    Ok(Json(
        blocking(move || {
            let _used = used;
            ide::source_json(app.target.as_ref(), id)
        })
        .await??,
    ))
}

pub async fn state(State(app): State<App>, Path(id): Path<usize>) -> Result<Json<Value>, ApiError> {
    let used = app.observable(id)?;
    Ok(Json(
        blocking(move || {
            let _used = used;
            ide::state_of(app.target.as_ref(), id)
        })
        .await??,
    ))
}

#[derive(Deserialize)]
pub struct BreakpointsBody {
    addresses: Vec<u16>,
}

pub async fn breakpoints(State(app): State<App>, Path(id): Path<usize>, Json(b): Json<BreakpointsBody>) -> Result<Json<Value>, ApiError> {
    let used = app.idle(id)?;
    ide::check_breakpoints(app.target.as_ref(), id, &b.addresses).map_err(bad)?;
    Ok(Json(
        blocking(move || {
            let _used = used;
            app.target.set_breakpoints(id, &b.addresses)?;
            ide::state_of(app.target.as_ref(), id)
        })
        .await??,
    ))
}

pub async fn action(State(app): State<App>, Path((id, action)): Path<(usize, String)>) -> Result<Json<Value>, ApiError> {
    let used = app.idle(id)?;
    let out = blocking(move || {
        let _used = used;
        ide::action(app.target.as_ref(), id, &action)
    })
    .await?;
    out.map(Json).map_err(|e| match e {
        ActionError::Unknown(s) => bad(s),
        ActionError::Target(e) => e.into(),
    })
}
