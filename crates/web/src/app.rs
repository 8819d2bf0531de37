//! The app's state shared by every route ([`App`]: the target, the token,
//! downloads under way) and the error answer of a request.

use axum::Json;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde_json::json;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use tmclsim_ide::target::{Target, TargetError};
use tmclsim_profile::Profile;

/// Assemblies at once (`/api/assemble` and downloads); another request
/// meanwhile is answered 503 (docs/robustness.md).
pub const ASSEMBLERS: usize = 2;

/// What every request of the app is served with: the target and what the
/// app keeps of it.
#[derive(Clone)]
pub struct App {
    pub target: Arc<dyn Target>,
    pub token: Option<String>,
    /// Assemblies running at once (bounded: each may take a core).
    pub assemblers: Arc<tokio::sync::Semaphore>,
    /// Per module: who is sending to it. In download mode a module stores
    /// every command it receives as a program word, so the app sends
    /// nothing else to it meanwhile (its live stream pauses, other
    /// requests are answered 409), and a download begins only when the
    /// requests already under way have their replies.
    gates: Arc<Vec<Gate>>,
}

#[derive(Default)]
struct Gate {
    state: Mutex<Users>,
    free: Condvar,
}

#[derive(Default)]
struct Users {
    requests: usize,
    downloading: bool,
}

impl Gate {
    fn users(&self) -> MutexGuard<'_, Users> {
        self.state.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

/// A request's use of a module, from its check to its last reply: a
/// download waits for it. Move it into the work that sends.
pub struct InUse(Arc<Vec<Gate>>, usize);

impl Drop for InUse {
    fn drop(&mut self) {
        let gate = &self.0[self.1];
        gate.users().requests -= 1;
        gate.free.notify_all();
    }
}

/// Marks a module as downloading until dropped.
pub struct Downloading(Arc<Vec<Gate>>, usize);

impl Downloading {
    /// Blocks until the requests that were under way when the download
    /// was claimed have their replies (call it on a blocking thread).
    pub fn wait_for_requests(&self) {
        let gate = &self.0[self.1];
        let mut users = gate.users();
        while users.requests > 0 {
            users = gate.free.wait(users).unwrap_or_else(std::sync::PoisonError::into_inner);
        }
    }
}

impl Drop for Downloading {
    fn drop(&mut self) {
        self.0[self.1].users().downloading = false;
    }
}

fn conflict() -> ApiError {
    ApiError(StatusCode::CONFLICT, "a program is being downloaded to this module: wait until the download ends".into())
}

impl App {
    pub fn new(target: Arc<dyn Target>, token: Option<String>) -> App {
        let gates = Arc::new(target.modules().iter().map(|_| Gate::default()).collect());
        let assemblers = Arc::new(tokio::sync::Semaphore::new(ASSEMBLERS));
        App { target, token, gates, assemblers }
    }

    /// The module exists and takes requests now (no download under way);
    /// a download claimed later waits until the answer is dropped.
    pub fn idle(&self, id: usize) -> Result<InUse, ApiError> {
        self.not_in_bootloader(id)?;
        self.gate(id)
    }

    /// A module in its bootloader takes none of the app's tools (the
    /// bootloader answers only its own commands, docs/behaviour.md rule 99).
    fn not_in_bootloader(&self, id: usize) -> Result<(), ApiError> {
        match self.target.bootloader(id) {
            None => Ok(()),
            Some(text) => Err(ApiError(
                StatusCode::CONFLICT,
                format!(
                    "the module is in its bootloader ({text}): a firmware update did not complete, and until one does it answers only \
                     the bootloader's commands (BOOT_*), at the bootloader's address"
                ),
            )),
        }
    }

    /// The module's gate, taken for a request.
    fn gate(&self, id: usize) -> Result<InUse, ApiError> {
        self.address(id)?;
        let mut users = self.gates[id].users();
        if users.downloading {
            return Err(conflict());
        }
        users.requests += 1;
        Ok(InUse(self.gates.clone(), id))
    }

    /// Every module takes requests now (a scan asks every address).
    pub fn all_idle(&self) -> Result<Vec<InUse>, ApiError> {
        (0..self.gates.len()).map(|id| self.gate(id)).collect()
    }

    /// The module exists and may be observed now: always on a target that
    /// observes its model (no use to hold), otherwise while no download is
    /// under way.
    pub fn observable(&self, id: usize) -> Result<Option<InUse>, ApiError> {
        self.not_in_bootloader(id)?;
        if self.target.observes_the_model() { self.address(id).map(|_| None) } else { self.gate(id).map(Some) }
    }

    /// Claims the module for a download; refused while another runs.
    /// Nothing may be sent before [`Downloading::wait_for_requests`].
    pub fn start_download(&self, id: usize) -> Result<Downloading, ApiError> {
        self.not_in_bootloader(id)?;
        self.address(id)?;
        let mut users = self.gates[id].users();
        if users.downloading {
            return Err(ApiError(StatusCode::CONFLICT, "a program is being downloaded to this module already".into()));
        }
        users.downloading = true;
        Ok(Downloading(self.gates.clone(), id))
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
