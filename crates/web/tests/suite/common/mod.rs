//! Helpers shared by the IDE server's tests: a served virtual module with
//! the app in front of it, JSON requests, and TMCL over the module's TCP
//! link as a host sends it.
#![allow(dead_code)]

use serde_json::Value;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::Arc;
use tmclsim_firmware::{Module, Profile};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};
use tmclsim_server::{ServerConfig, ServerHandle};
use tmclsim_web::{VirtualTarget, WebConfig, WebHandle};

/// A TMCM-1141 on loopback TCP with the app beside it; both stop when
/// dropped (the app first).
pub struct Served {
    pub web: WebHandle,
    pub server: ServerHandle,
}

impl Served {
    pub fn new() -> Served {
        Served::with_limits(Default::default())
    }

    /// [`Served::new`] with the app's server limits given.
    pub fn with_limits(limits: tmclsim_web::Limits) -> Served {
        let module = Module::new(Profile::built_in("tmcm-1141").unwrap());
        let config = ServerConfig { tcp: Some("127.0.0.1:0".parse().unwrap()), warn_exposure: false, ..ServerConfig::default() };
        let server = tmclsim_server::start(module, config).unwrap();
        let target = Arc::new(VirtualTarget::new(server.links()));
        Served { web: app_on_loopback(target, limits), server }
    }

    pub fn tcp(&self) -> SocketAddr {
        self.server.endpoints().tcp.unwrap()
    }

    pub fn url(&self, path: &str) -> String {
        format!("http://{}{path}", self.web.addr())
    }

    /// A host's connection to the module's TCP link.
    pub fn host(&self) -> TcpStream {
        TcpStream::connect(self.tcp()).unwrap()
    }
}

/// The app in front of `target` on a free loopback port.
pub fn app_on_loopback(target: Arc<dyn tmclsim_web::Target>, limits: tmclsim_web::Limits) -> WebHandle {
    tmclsim_web::start(target, WebConfig { addr: "127.0.0.1:0".parse().unwrap(), public: false, limits }).unwrap()
}

/// The app over a TMCL link to the TCP endpoint `tcp`, with module 1 on it.
pub fn app_over_tcp(tcp: &str) -> WebHandle {
    let probe = tmclsim_web::Probe::Addresses(&[1]);
    let target = tmclsim_web::LinkTarget::open(Some(tcp), None, 9600, probe, std::time::Duration::from_secs(1)).unwrap();
    app_on_loopback(target, Default::default())
}

/// A JSON answer and its HTTP status, whatever the status.
pub fn answer(r: Result<ureq::http::Response<ureq::Body>, ureq::Error>) -> (u16, Value) {
    let mut r = r.unwrap();
    let status = r.status().as_u16();
    let text = r.body_mut().read_to_string().unwrap();
    (status, serde_json::from_str(&text).unwrap_or(Value::String(text)))
}

fn agent() -> ureq::Agent {
    ureq::Agent::config_builder().http_status_as_error(false).build().into()
}

pub fn get(url: &str) -> (u16, Value) {
    answer(agent().get(url).call())
}

pub fn post(url: &str, body: Value) -> (u16, Value) {
    answer(agent().post(url).send_json(body))
}

/// The raw text of a POST (newline-delimited JSON answers).
pub fn post_text(url: &str, body: Value) -> String {
    agent().post(url).send_json(body).unwrap().body_mut().read_to_string().unwrap()
}

/// Sends a command on a TMCL link and reads its reply, as a host does.
pub fn ask(s: &mut TcpStream, line: &str) -> Reply {
    s.write_all(&Request::new(1, parse_line(line).unwrap()).encode()).unwrap();
    let mut buf = [0u8; 9];
    s.read_exact(&mut buf).unwrap();
    Reply::decode(&buf).expect("reply checksum")
}

/// Polls `probe` until `ok` takes its value, for at most 10 s of wall
/// time: the value, or a failure naming `what` and the last value seen.
pub fn until<T: std::fmt::Debug>(what: &str, mut probe: impl FnMut() -> T, ok: impl Fn(&T) -> bool) -> T {
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    loop {
        let value = probe();
        if ok(&value) {
            return value;
        }
        assert!(std::time::Instant::now() < end, "waited 10 s for {what}; last saw {value:?}");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}
