//! The routes of the API (this crate's README) and the direct-mode,
//! parameter and world requests. Every command is a TMCL request through
//! the target.

use crate::target::{Target, TargetError};
use axum::extract::{Path, State};
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::Deserialize;
use serde_json::{Value, json};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use tmclsim_profile::Profile;
use tmclsim_protocol::{FRAME_LEN, Instruction, Request, opcode};

#[derive(Clone)]
pub struct App {
    pub target: Arc<dyn Target>,
    pub token: Option<String>,
    /// Refused tokens in a row (each waits longer).
    pub failures: Arc<crate::security::Failures>,
    /// Assemblies running at once (bounded: each may take a core).
    pub assemblers: Arc<tokio::sync::Semaphore>,
    /// Per module: a download is under way. In download mode a module
    /// stores every command it receives as a program word, so the app
    /// sends nothing else to it meanwhile (its live stream pauses, other
    /// requests are answered 409).
    downloading: Arc<Vec<AtomicBool>>,
}

/// Marks a module as downloading until dropped.
pub struct Downloading(Arc<Vec<AtomicBool>>, usize);

impl Drop for Downloading {
    fn drop(&mut self) {
        self.0[self.1].store(false, Ordering::SeqCst);
    }
}

impl App {
    pub fn new(target: Arc<dyn Target>, token: Option<String>) -> App {
        let downloading = Arc::new(target.modules().iter().map(|_| AtomicBool::new(false)).collect());
        let assemblers = Arc::new(tokio::sync::Semaphore::new(crate::program::ASSEMBLERS));
        App { target, token, downloading, failures: Default::default(), assemblers }
    }

    pub fn is_downloading(&self, id: usize) -> bool {
        self.downloading.get(id).is_some_and(|d| d.load(Ordering::SeqCst))
    }

    /// The module exists and takes requests now (no download under way).
    pub fn idle(&self, id: usize) -> Result<(), ApiError> {
        self.address(id)?;
        if self.is_downloading(id) {
            return Err(ApiError(
                StatusCode::CONFLICT,
                "a program is being downloaded to this module: wait until the download ends".into(),
            ));
        }
        Ok(())
    }

    /// The module exists and may be observed now: always on a target that
    /// observes its model, otherwise while no download is under way.
    pub fn observable(&self, id: usize) -> Result<(), ApiError> {
        if self.target.observes_the_model() { self.address(id).map(|_| ()) } else { self.idle(id) }
    }

    /// Claims the module for a download; refused while another runs.
    pub fn start_download(&self, id: usize) -> Result<Downloading, ApiError> {
        self.address(id)?;
        if self.downloading[id].compare_exchange(false, true, Ordering::SeqCst, Ordering::SeqCst).is_err() {
            return Err(ApiError(StatusCode::CONFLICT, "a program is being downloaded to this module already".into()));
        }
        Ok(Downloading(self.downloading.clone(), id))
    }

    pub fn profile(&self, id: usize) -> Result<Option<Arc<Profile>>, ApiError> {
        Ok(self.target.modules().get(id).ok_or_else(no_module)?.profile.clone())
    }

    pub fn address(&self, id: usize) -> Result<u8, ApiError> {
        Ok(self.target.modules().get(id).ok_or_else(no_module)?.address)
    }
}

/// An error answer: `{"error": text}` with its HTTP status.
pub struct ApiError(pub StatusCode, pub String);

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (self.0, Json(json!({ "error": self.1 }))).into_response()
    }
}

impl From<TargetError> for ApiError {
    fn from(e: TargetError) -> ApiError {
        match e {
            TargetError::NoModule => no_module(),
            TargetError::Unsupported(s) => ApiError(StatusCode::CONFLICT, s),
            TargetError::Failed(s) if s.contains("no reply") => ApiError(StatusCode::GATEWAY_TIMEOUT, s),
            TargetError::Failed(s) => ApiError(StatusCode::BAD_REQUEST, s),
        }
    }
}

pub fn no_module() -> ApiError {
    ApiError(StatusCode::NOT_FOUND, "no such module".into())
}

pub fn bad(text: impl Into<String>) -> ApiError {
    ApiError(StatusCode::BAD_REQUEST, text.into())
}

/// Runs `f` off the async threads: targets block on locks and links.
pub async fn blocking<R: Send + 'static>(f: impl FnOnce() -> R + Send + 'static) -> Result<R, ApiError> {
    tokio::task::spawn_blocking(f).await.map_err(|e| ApiError(StatusCode::INTERNAL_SERVER_ERROR, format!("internal error: {e}")))
}

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
        .layer(axum::middleware::from_fn_with_state(app.clone(), crate::security::guard))
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
        "status": raw[2], "status_text": crate::status_text(raw[2]), "value": value,
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

#[derive(Deserialize, Clone, Copy)]
pub struct Read {
    pub kind: ReadKind,
    pub number: u8,
    #[serde(default)]
    pub index: u8,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ReadKind {
    Ap,
    Gp,
    Input,
    Output,
}

impl Read {
    pub fn instruction(self) -> Instruction {
        match self.kind {
            ReadKind::Ap => Instruction::new(opcode::GAP, self.number, self.index, 0),
            ReadKind::Gp => Instruction::new(opcode::GGP, self.number, self.index, 0),
            ReadKind::Input => Instruction::new(opcode::GIO, self.number, self.index, 0),
            ReadKind::Output => Instruction::new(opcode::GIO, self.number, 2, 0),
        }
    }
}

/// The values of `reads` (`None` where the module answered an error) and
/// the module's clock after them.
pub fn read_all(target: &dyn Target, id: usize, reads: &[Read]) -> Result<(Vec<Option<i32>>, f64), TargetError> {
    let all: Vec<Instruction> = reads.iter().map(|r| r.instruction()).collect();
    let (replies, t) = target.observe(id, &all)?;
    Ok((replies.iter().map(|raw| (raw[2] >= 100).then(|| i32::from_be_bytes([raw[4], raw[5], raw[6], raw[7]]))).collect(), t))
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
