//! The playground's modules: the IDE's API (crates/web/README.md) answered
//! inside the page. The answers come from `tmclsim_ide`, the code the
//! server answers from, over a [`Target`] whose modules are [`Sim`]s in
//! virtual time that the page moves on.

use crate::sim::{Failure, Sim};
use serde::Deserialize;
use serde::de::DeserializeOwned;
use serde_json::{Value, json};
use std::sync::{Mutex, MutexGuard};
use tmclsim_firmware::Speed;
use tmclsim_firmware::snapshot::ModuleSnapshot;
use tmclsim_ide::answers::{self, Read, Write};
use tmclsim_ide::live::{Subscription, sample};
use tmclsim_ide::program::{self, ActionError};
use tmclsim_ide::target::check;
use tmclsim_ide::{ModuleEntry, Target, TargetError, profile_json};
use tmclsim_profile::Profile;
use tmclsim_protocol::{FRAME_LEN, Instruction, Request, opcode};

/// Most modules in one page.
pub const MAX_MODULES: usize = 64;

/// What the module list calls where the modules are.
const WHERE: &str = "in this page";

/// The page's modules, each on a bus of its own.
#[derive(Default)]
pub struct PageTarget {
    /// How fast virtual time runs against the page's clock.
    speed: Speed,
    entries: Vec<ModuleEntry>,
    sims: Vec<Mutex<Sim>>,
}

impl PageTarget {
    fn sim(&self, id: usize) -> Result<MutexGuard<'_, Sim>, TargetError> {
        let sim = self.sims.get(id).ok_or(TargetError::NoModule)?;
        // A panic cannot leave a module half changed here (wasm aborts on
        // one): a poisoned lock is taken as it is.
        Ok(sim.lock().unwrap_or_else(std::sync::PoisonError::into_inner))
    }
}

impl Target for PageTarget {
    fn kind(&self) -> &'static str {
        "virtual"
    }

    fn describe(&self) -> String {
        WHERE.into()
    }

    fn speed(&self) -> f64 {
        self.speed.factor()
    }

    fn modules(&self) -> &[ModuleEntry] {
        &self.entries
    }

    fn request(&self, id: usize, ins: Instruction) -> Result<[u8; FRAME_LEN], TargetError> {
        let mut sim = self.sim(id)?;
        // The module's address now: a program may have changed it.
        let frame = Request::new(sim.address(), ins).encode();
        let replies = sim.frame(&frame).map_err(|f| TargetError::Failed(f.message))?;
        replies
            .get(..FRAME_LEN)
            .and_then(|r| r.try_into().ok())
            .ok_or_else(|| TargetError::Failed("no reply (replies suppressed by GP 255?)".into()))
    }

    fn observe(&self, id: usize, all: &[Instruction]) -> Result<(Vec<[u8; FRAME_LEN]>, f64), TargetError> {
        let mut sim = self.sim(id)?;
        let replies = sim
            .observe(all)
            .into_iter()
            .zip(all)
            .map(|(r, ins)| r.ok_or_else(|| TargetError::Failed(format!("opcode {} is not a read", ins.opcode))))
            .collect::<Result<_, _>>()?;
        Ok((replies, sim.time()))
    }

    fn observes_the_model(&self) -> bool {
        true
    }

    fn blocks(&self) -> bool {
        false
    }

    fn time(&self, id: usize) -> f64 {
        self.sim(id).map_or(0.0, |s| s.time())
    }

    fn snapshot(&self, id: usize) -> Option<ModuleSnapshot> {
        Some(ModuleSnapshot::of(self.sim(id).ok()?.module()))
    }

    fn world(&self, id: usize, line: &str) -> Result<String, TargetError> {
        self.sim(id)?.world(line).map_err(|f| TargetError::Failed(f.message))
    }

    fn set_breakpoints(&self, id: usize, addresses: &[u16]) -> Result<(), TargetError> {
        self.sim(id)?.set_breakpoints(addresses);
        Ok(())
    }

    fn breakpoints(&self, id: usize) -> Vec<u16> {
        self.sim(id).map_or(Vec::new(), |s| s.module().program().breakpoints.clone())
    }

    fn breakpoint_hit(&self, id: usize) -> Option<u16> {
        self.sim(id).ok()?.module().program().hit_breakpoint
    }

    fn run(&self, id: usize, start: bool) -> Result<(), TargetError> {
        check(&self.request(id, Instruction::new(opcode::RUN_APPLICATION, u8::from(start), 0, 0))?)
    }
}

/// `POST /api/modules`: a module of a built-in profile, in a world.
#[derive(Deserialize)]
struct NewModule {
    profile: String,
    world: Option<String>,
}

#[derive(Deserialize)]
struct Line {
    line: String,
}

#[derive(Deserialize)]
struct Reads {
    reads: Vec<Read>,
}

#[derive(Deserialize)]
struct Source {
    source: String,
    profile: Option<String>,
}

#[derive(Deserialize)]
struct Breakpoints {
    addresses: Vec<u16>,
}

/// Why a request of the API gets an error answer (`{"error": …}`).
#[derive(Debug)]
enum RouteError {
    /// The body is not the JSON the request takes (the parser's words).
    Body(String),
    /// No request has this method and path.
    NoSuchRequest {
        /// `GET` or `POST`.
        method: String,
        /// The path, or its part after the module id.
        path: String,
    },
    /// The path's module id is no number.
    NotAModuleId(String),
    /// The page has no module of this id.
    NoSuchModule,
    /// tmclsim has no profile of the module's type.
    NoProfile,
    /// The request is refused: its line, value, program or profile is
    /// wrong (the answers' own words).
    Refused(String),
}

impl std::fmt::Display for RouteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RouteError::Body(e) => write!(f, "the request's JSON: {e}"),
            RouteError::NoSuchRequest { method, path } => write!(f, "no such request: {method} {path}"),
            RouteError::NotAModuleId(id) => write!(f, "'{id}' is not a module id"),
            RouteError::NoSuchModule => write!(f, "no such module"),
            RouteError::NoProfile => write!(f, "tmclsim has no profile of this module's type"),
            RouteError::Refused(message) => f.write_str(message),
        }
    }
}

/// The errors of the answers, which the app shows as they are.
macro_rules! refused_from {
    ($($t:ty),*) => {$(
        impl From<$t> for RouteError {
            fn from(e: $t) -> RouteError {
                RouteError::Refused(e.to_string())
            }
        }
    )*};
}

refused_from!(
    tmclsim_protocol::mnemonic::ParseError,
    answers::WriteError,
    program::TooLong,
    program::BreakpointError,
    tmclsim_profile::ProfileError
);

impl From<Failure> for RouteError {
    fn from(f: Failure) -> RouteError {
        RouteError::Refused(f.message)
    }
}

/// The body of a request as `T`, or what is wrong with it.
fn body<T: DeserializeOwned>(text: &str) -> Result<T, RouteError> {
    serde_json::from_str(if text.trim().is_empty() { "{}" } else { text }).map_err(|e| RouteError::Body(e.to_string()))
}

fn error(message: impl std::fmt::Display) -> Value {
    json!({ "error": message.to_string() })
}

/// A target's answer, or its error as the app shows errors.
fn answer(result: Result<Value, TargetError>) -> Value {
    result.unwrap_or_else(error)
}

/// The playground: the page's modules and the API over them.
#[derive(Default)]
pub struct Page {
    target: PageTarget,
}

impl Page {
    pub fn new() -> Page {
        Page::default()
    }

    pub fn target(&self) -> &PageTarget {
        &self.target
    }

    /// Adds a module of a built-in profile; its id.
    pub fn add(&mut self, profile: &str, world: Option<&str>) -> Result<usize, Failure> {
        if self.target.sims.len() >= MAX_MODULES {
            return Err(format!("at most {MAX_MODULES} modules in the page").into());
        }
        let sim = Sim::new(profile, world)?;
        let p = sim.module().profile().clone();
        let firmware = String::from_utf8_lossy(&p.version_text()).into_owned();
        self.target.entries.push(ModuleEntry { address: sim.address(), profile: Some(p), firmware, link: WHERE.into() });
        self.target.sims.push(Mutex::new(sim));
        Ok(self.target.sims.len() - 1)
    }

    /// Moves every module's virtual time on by `seconds`.
    pub fn advance(&mut self, seconds: f64) -> Result<(), Failure> {
        for sim in &mut self.target.sims {
            sim.get_mut().unwrap_or_else(|e| e.into_inner()).advance(seconds)?;
        }
        Ok(())
    }

    /// Virtual time runs `factor` times as fast as the page's clock (a
    /// positive number, as `tmclsim serve --speed`).
    pub fn set_speed(&mut self, factor: f64) -> Result<(), Failure> {
        self.target.speed = Speed::new(factor).map_err(|e| Failure::new(e.to_string()))?;
        Ok(())
    }

    /// Moves virtual time on by what `seconds` of the page's clock make
    /// at the speed.
    pub fn advance_wall(&mut self, seconds: f64) -> Result<(), Failure> {
        self.advance(seconds * self.target.speed.factor())
    }

    /// One sample of the live stream of module `id` for a subscription (its
    /// JSON): `{"t", "values", "program"?}` or `{"error"}`.
    pub fn sample(&self, id: usize, subscription: &str) -> Value {
        if id >= self.target.sims.len() {
            return error("no such module");
        }
        match Subscription::parse(subscription) {
            Ok(sub) => sample(&self.target, id, &sub),
            Err(e) => error(e),
        }
    }

    /// A request of the API: `method` (`GET`, `POST`), `path`
    /// (`/api/modules/0/command`) and the body's JSON text. The answer is
    /// what the server answers; a download's progress lines come as one
    /// array.
    pub fn request(&mut self, method: &str, path: &str, body_text: &str) -> Value {
        self.route(method, path, body_text).unwrap_or_else(error)
    }

    fn route(&mut self, method: &str, path: &str, text: &str) -> Result<Value, RouteError> {
        let t = &self.target;
        let parts: Vec<&str> = path.trim_start_matches('/').split('/').collect();
        let v = match (method, parts.as_slice()) {
            ("GET", ["api", "info"]) => json!({
                "target": "virtual", "link": WHERE, "speed": t.speed.factor(), "version": env!("CARGO_PKG_VERSION"),
                "playground": true, "profiles": Sim::profiles(),
            }),
            ("GET", ["api", "modules"]) => answers::modules_json(t),
            ("POST", ["api", "modules"]) => {
                let b: NewModule = body(text)?;
                let id = self.add(&b.profile, b.world.as_deref())?;
                json!({ "id": id })
            }
            ("POST", ["api", "scan"]) => answer(t.scan().map(|_| Value::Null)),
            ("POST", ["api", "assemble"]) => {
                let b: Source = body(text)?;
                program::check_size(&b.source)?;
                let profile = match &b.profile {
                    Some(name) => Some(Profile::built_in(&name.to_ascii_lowercase())?),
                    None => None,
                };
                program::assemble_json(&b.source, profile.as_deref())
            }
            (method, ["api", "modules", id, rest @ ..]) => {
                let id: usize = id.parse().map_err(|_| RouteError::NotAModuleId((*id).to_string()))?;
                if id >= t.sims.len() {
                    return Err(RouteError::NoSuchModule);
                }
                module_route(t, id, method, rest, text)?
            }
            _ => return Err(RouteError::NoSuchRequest { method: method.to_string(), path: path.to_string() }),
        };
        Ok(v)
    }
}

/// The requests of module `id` (`/api/modules/{id}/…`).
fn module_route(t: &PageTarget, id: usize, method: &str, rest: &[&str], text: &str) -> Result<Value, RouteError> {
    let v = match (method, rest) {
        ("GET", ["profile"]) => match &t.entries[id].profile {
            Some(p) => profile_json::of(p),
            None => return Err(RouteError::NoProfile),
        },
        ("POST", ["command"]) => {
            let b: Line = body(text)?;
            let ins = answers::parse_line(t, id, &b.line)?;
            answer(answers::exchange(t, id, ins))
        }
        ("POST", ["read"]) => answer(answers::read_json(t, id, &body::<Reads>(text)?.reads)),
        ("POST", ["write"]) => {
            let ins = body::<Write>(text)?.instruction()?;
            answer(answers::exchange(t, id, ins))
        }
        ("GET", ["world"]) => answers::world_state_json(&t.snapshot(id).ok_or(RouteError::NoSuchModule)?),
        ("POST", ["world"]) => answer(answers::world_json(t, id, &body::<Line>(text)?.line)),
        ("POST", ["program", "download"]) => {
            let b: Source = body(text)?;
            program::check_size(&b.source)?;
            let profile = t.entries[id].profile.clone();
            match program::assemble(&b.source, profile.as_deref()) {
                Err(diagnostics) => diagnostics,
                Ok(p) => {
                    let mut lines = Vec::new();
                    let end = program::download_end(t, id, &p, &mut |line| lines.push(line));
                    lines.push(end);
                    Value::Array(lines)
                }
            }
        }
        ("GET", ["program", "state"]) => answer(program::state_of(t, id)),
        ("GET", ["program", "source"]) => answer(program::source_json(t, id)),
        ("POST", ["program", "breakpoints"]) => {
            let b: Breakpoints = body(text)?;
            program::check_breakpoints(t, id, &b.addresses)?;
            answer(t.set_breakpoints(id, &b.addresses).and_then(|()| program::state_of(t, id)))
        }
        ("POST", ["program", action]) => match program::action(t, id, action) {
            Ok(v) => v,
            Err(ActionError::Unknown(e)) => return Err(RouteError::Refused(e)),
            Err(ActionError::Target(e)) => error(e),
        },
        _ => return Err(RouteError::NoSuchRequest { method: method.to_string(), path: rest.join("/") }),
    };
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn page() -> Page {
        let mut p = Page::new();
        assert_eq!(p.add("tmcm-1141", None).unwrap(), 0);
        p
    }

    fn post(p: &mut Page, path: &str, body: Value) -> Value {
        p.request("POST", path, &body.to_string())
    }

    #[test]
    fn modules_are_added_by_profile() {
        let mut p = page();
        let added = post(&mut p, "/api/modules", json!({"profile": "tmcm-3110"}));
        assert_eq!(added["id"], 1, "{added}");
        let list = p.request("GET", "/api/modules", "");
        assert_eq!(list[1]["profile"], "TMCM-3110");
        assert_eq!(list[1]["virtual"], true);
        let bad = post(&mut p, "/api/modules", json!({"profile": "tmcm-9999"}));
        assert!(bad["error"].as_str().unwrap().contains("tmcm-1141"), "{bad}");
        let info = p.request("GET", "/api/info", "");
        assert_eq!(info["playground"], true);
        assert!(info["profiles"].as_array().unwrap().iter().any(|n| n == "tmcm-1141"));
    }

    #[test]
    fn commands_are_answered_as_the_server_answers_them() {
        let mut p = page();
        let r = post(&mut p, "/api/modules/0/command", json!({"line": "SAP maximum_positioning_speed, 0, 1000"}));
        assert_eq!((r["status"].as_u64(), r["value"].as_i64()), (Some(100), Some(1000)), "{r}");
        assert_eq!(r["request"], "01 05 04 00 00 00 03 e8 f5");
        let v = post(&mut p, "/api/modules/0/command", json!({"line": "#136 0 0 0"}));
        assert_eq!(v["version"], "1141V146");
        let e = post(&mut p, "/api/modules/0/command", json!({"line": "SAP 4, 0, x"}));
        assert!(e["error"].as_str().unwrap().starts_with("column 11:"), "{e}");
        let w = post(&mut p, "/api/modules/0/write", json!({"kind": "ap", "number": 4, "index": 0, "value": 800}));
        assert_eq!(w["value"], 800);
        let r = post(&mut p, "/api/modules/0/read", json!({"reads": [{"kind": "ap", "number": 4, "index": 0}]}));
        assert_eq!(r["values"], json!([800]));
    }

    #[test]
    fn bad_requests_are_errors_not_panics() {
        let mut p = page();
        for (method, path, body) in [
            ("GET", "/api/modules/7/profile", ""),
            ("GET", "/api/modules/x/profile", ""),
            ("POST", "/api/modules/0/command", "not json"),
            ("POST", "/api/modules/0/command", "{}"),
            ("POST", "/api/modules/0/write", r#"{"kind": "input", "number": 0}"#),
            ("POST", "/api/modules/0/program/fly", ""),
            ("POST", "/api/modules/0/program/breakpoints", r#"{"addresses": [5000]}"#),
            ("GET", "/api/nothing", ""),
            ("POST", "/api/scan", ""),
        ] {
            let a = p.request(method, path, body);
            assert!(a["error"].is_string(), "{method} {path} {body}: {a}");
        }
        assert!(p.sample(3, "{}")["error"].is_string());
        assert!(p.sample(0, "[")["error"].is_string());
    }

    #[test]
    fn time_moves_the_motor_and_the_world_stops_it() {
        let mut p = page();
        post(&mut p, "/api/modules/0/command", json!({"line": "ROR 0, 500"}));
        p.advance(0.5).unwrap();
        let s = p.sample(0, r#"{"signals": [{"kind": "ap", "number": 3, "index": 0}]}"#);
        assert_eq!(s["values"], json!([500]));
        assert_eq!(s["t"], 0.5);
        let a = post(&mut p, "/api/modules/0/world", json!({"line": "switch 0 right press"}));
        assert!(a["ok"].is_string(), "{a}");
        p.advance(0.5).unwrap();
        let w = p.request("GET", "/api/modules/0/world", "");
        assert_eq!(w["axes"][0]["right"], true);
        assert_eq!(w["axes"][0]["speed"], 0, "{w}");
    }

    #[test]
    fn programs_download_and_stop_at_breakpoints() {
        let mut p = page();
        let bad = post(&mut p, "/api/modules/0/program/download", json!({"source": "CALC LOAD, 1\n  FOO 2\n"}));
        assert_eq!(
            (bad["ok"].as_bool(), &bad["diagnostics"][0]["line"], &bad["diagnostics"][0]["column"]),
            (Some(false), &json!(2), &json!(3))
        );
        let source = "Loop: CALC ADD, 1\n      JA Loop\n";
        let lines = post(&mut p, "/api/modules/0/program/download", json!({"source": source}));
        let end = lines.as_array().unwrap().last().unwrap();
        // The two words and the STOP appended after JA (docs/behaviour.md rule 93).
        assert_eq!((end["done"].as_bool(), end["verified"].as_bool(), end["words"].as_u64()), (Some(true), Some(true), Some(3)), "{lines}");
        let st = post(&mut p, "/api/modules/0/program/breakpoints", json!({"addresses": [1]}));
        assert_eq!(st["breakpoints"], json!([1]));
        post(&mut p, "/api/modules/0/program/run", json!({}));
        p.advance(0.01).unwrap();
        let st = p.request("GET", "/api/modules/0/program/state", "");
        assert_eq!((st["mode"].as_str(), st["pc"].as_u64(), st["breakpoint"].as_u64()), (Some("step"), Some(1), Some(1)), "{st}");
        assert_eq!(st["accumulator"], 1);
        let read = p.request("GET", "/api/modules/0/program/source", "");
        assert_eq!(read["words"], 3);
    }
}
