//! The app's state shared by every route ([`App`]: the target, the token,
//! downloads under way) and the error answer of a request.

use axum::Json;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde_json::json;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
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
        let assemblers = Arc::new(tokio::sync::Semaphore::new(ASSEMBLERS));
        App { target, token, downloading, assemblers }
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
