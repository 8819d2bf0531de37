//! Who may drive the motors: the app binds to loopback by default; a
//! request whose `Origin` is another site, or whose `Host` is not a name of
//! this machine's loopback (DNS rebinding), is refused. A non-loopback bind
//! needs a token in every request: `?token=` once (the page then sets a
//! cookie), the cookie, or the `x-tmclsim-token` header.

use axum::extract::{Request, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

pub const COOKIE: &str = "tmclsim_token";

/// Requests refused for a wrong or missing token, one after another: the
/// n-th waits 2^n × 10 ms before its answer, at most [`MAX_PENALTY`], so
/// that guessing the 128-bit token is slower still than it is hopeless.
#[derive(Default)]
pub struct Failures(std::sync::Mutex<u32>);

/// The longest wait of a refused token.
pub const MAX_PENALTY: std::time::Duration = std::time::Duration::from_secs(2);

impl Failures {
    /// Counts one more failure; the wait before it is answered.
    pub fn penalty(&self) -> std::time::Duration {
        let mut n = self.0.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        *n = n.saturating_add(1);
        std::time::Duration::from_millis(10u64 << (*n).min(8)).min(MAX_PENALTY)
    }

    /// A request with the right token ends the run of failures.
    pub fn clear(&self) {
        *self.0.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = 0;
    }
}

/// 128 random bits from the operating system, in hex.
pub fn new_token() -> std::io::Result<String> {
    let mut b = [0u8; 16];
    getrandom::fill(&mut b).map_err(std::io::Error::other)?;
    Ok(b.iter().map(|x| format!("{x:02x}")).collect())
}

/// The host part of `host[:port]` or `[v6]:port`.
fn host_of(authority: &str) -> &str {
    if let Some(rest) = authority.strip_prefix('[') {
        return rest.split(']').next().unwrap_or(rest);
    }
    authority.rsplit_once(':').map_or(authority, |(h, _)| h)
}

fn is_loopback_name(host: &str) -> bool {
    host.eq_ignore_ascii_case("localhost") || host.parse::<std::net::IpAddr>().is_ok_and(|ip| ip.is_loopback())
}

fn refuse(why: &str) -> Response {
    (StatusCode::FORBIDDEN, axum::Json(serde_json::json!({ "error": why }))).into_response()
}

fn token_of(req: &Request) -> Option<String> {
    let h = req.headers();
    if let Some(t) = h.get("x-tmclsim-token").and_then(|v| v.to_str().ok()) {
        return Some(t.to_string());
    }
    let query = req.uri().query().unwrap_or("");
    if let Some(t) = query.split('&').find_map(|kv| kv.strip_prefix("token=")) {
        return Some(t.to_string());
    }
    cookie(h)
}

fn cookie(h: &HeaderMap) -> Option<String> {
    h.get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .find_map(|kv| kv.trim().strip_prefix(COOKIE).and_then(|r| r.strip_prefix('=')).map(str::to_string))
}

/// What the checks in front of every route need: the token requests must
/// carry (non-loopback binds only) and the refused ones in a row.
pub struct Guard {
    token: Option<String>,
    failures: Failures,
}

impl Guard {
    pub fn new(token: Option<String>) -> Guard {
        Guard { token, failures: Failures::default() }
    }
}

/// The checks, in front of every route.
pub async fn guard(State(guard): State<std::sync::Arc<Guard>>, req: Request, next: Next) -> Response {
    let host = req.headers().get(header::HOST).and_then(|v| v.to_str().ok()).unwrap_or("").to_string();
    if let Some(origin) = req.headers().get(header::ORIGIN) {
        let origin = origin.to_str().unwrap_or("");
        let authority = origin.split_once("://").map_or("", |(_, a)| a);
        if authority != host {
            return refuse(&format!("requests from {origin} are refused: the IDE answers its own pages only"));
        }
    }
    match &guard.token {
        None if !is_loopback_name(host_of(&host)) => {
            return refuse(&format!("host '{host}' is not this machine's loopback (a DNS-rebinding request is refused)"));
        }
        None => {}
        Some(token) => {
            let given = token_of(&req);
            if !given.as_deref().is_some_and(|g| tmclsim_server::control::same_token(g, token)) {
                // Each failure in a row waits longer before its answer.
                tokio::time::sleep(guard.failures.penalty()).await;
                return refuse("this IDE needs the token printed when it started (?token=…)");
            }
            guard.failures.clear();
            let set = req.uri().query().is_some_and(|q| q.contains("token="));
            let mut response = next.run(req).await;
            if set {
                let c = format!("{COOKIE}={token}; Path=/; HttpOnly; SameSite=Strict");
                if let Ok(v) = c.parse() {
                    response.headers_mut().insert(header::SET_COOKIE, v);
                }
            }
            return response;
        }
    }
    next.run(req).await
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hosts_and_loopback_names() {
        assert_eq!(host_of("127.0.0.1:8141"), "127.0.0.1");
        assert_eq!(host_of("[::1]:8141"), "::1");
        assert_eq!(host_of("localhost"), "localhost");
        assert!(is_loopback_name("localhost") && is_loopback_name("127.0.0.1") && is_loopback_name("::1"));
        assert!(!is_loopback_name("evil.example") && !is_loopback_name("10.0.0.1"));
        assert_eq!(new_token().unwrap().len(), 32);
    }
}
