//! Starting the real `tmclsim serve` process in tests, and talking to it
//! in frames over TCP.
#![allow(dead_code)]

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Reply, Request};

/// `tmclsim serve ARGS` with standard output and error piped.
pub fn serve_command(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tmclsim"));
    c.arg("serve").args(args).stdout(Stdio::piped()).stderr(Stdio::piped());
    c
}

/// Reads what a starting server prints up to its line beginning with
/// `last` (`None` when it ends first), then keeps draining its standard
/// output so that it never blocks.
fn read_banner(child: &mut Child, last: &str) -> Option<Vec<String>> {
    let mut out = BufReader::new(child.stdout.take().expect("stdout piped"));
    let mut banner = Vec::new();
    loop {
        let mut line = String::new();
        if out.read_line(&mut line).unwrap() == 0 {
            return None;
        }
        let done = line.starts_with(last);
        banner.push(line.trim().to_string());
        if done {
            break;
        }
    }
    std::thread::spawn(move || {
        let _ = out.read_to_end(&mut vec![]);
    });
    Some(banner)
}

/// The value a server printed after `KEY: ` (its first word).
fn printed(banner: &[String], key: &str) -> String {
    let prefix = format!("{key}: ");
    let line = banner.iter().find_map(|l| l.strip_prefix(&prefix)).unwrap_or_else(|| panic!("no {key} in {banner:?}"));
    line.split_whitespace().next().unwrap().to_string()
}

/// Starts `tmclsim serve` with `args` (plus `--tcp 127.0.0.1:0`) and waits
/// until it serves; returns the process and its TCP endpoint.
pub fn serve(args: &[&str], stderr: Stdio) -> (Child, String) {
    let mut child = serve_command(&[&["--tcp", "127.0.0.1:0"][..], args].concat()).stderr(stderr).spawn().unwrap();
    let banner = read_banner(&mut child, "connect with:").expect("the server ended before serving");
    (child, printed(&banner, "tcp"))
}

/// A `tmclsim serve` process of a test: what it printed up to `connect
/// with:` and its standard error, line by line as it comes. Dropped, it is
/// killed and reaped.
pub struct Server {
    pub child: Child,
    pub banner: Vec<String>,
    pub log: Arc<Mutex<Vec<String>>>,
    /// The thread that reads standard error into `log`; it ends when the
    /// process closes it.
    reader: Option<std::thread::JoinHandle<()>>,
}

impl Server {
    /// `tmclsim serve ARGS`, once it serves.
    pub fn start(args: &[&str]) -> Server {
        Server::spawn(serve_command(args))
    }

    pub fn spawn(mut command: Command) -> Server {
        Server::of(command.spawn().unwrap())
    }

    /// `tmclsim ide ARGS --web 127.0.0.1:0`, once it serves the app (its
    /// URL is `printed("open")`).
    pub fn ide(args: &[&str]) -> Server {
        let mut c = Command::new(env!("CARGO_BIN_EXE_tmclsim"));
        c.arg("ide").args(args).args(["--web", "127.0.0.1:0"]).stdout(Stdio::piped()).stderr(Stdio::piped());
        Server::serving(c.spawn().unwrap(), "open:")
    }

    /// A started server process (its standard output piped; its standard
    /// error, if piped, becomes the log).
    pub fn of(child: Child) -> Server {
        Server::serving(child, "connect with:")
    }

    /// A started process, once it printed its line beginning with `last`.
    fn serving(mut child: Child, last: &str) -> Server {
        let log = Arc::new(Mutex::new(Vec::new()));
        let reader = child.stderr.take().map(|err| {
            let l = log.clone();
            std::thread::spawn(move || {
                for line in BufReader::new(err).lines().map_while(Result::ok) {
                    l.lock().unwrap().push(line);
                }
            })
        });
        let Some(banner) = read_banner(&mut child, last) else {
            let _ = child.wait();
            // The process is gone: its standard error is read to the end.
            if let Some(r) = reader {
                let _ = r.join();
            }
            panic!("the server ended before serving: {:?}", log.lock().unwrap());
        };
        Server { child, banner, log, reader }
    }

    /// The value printed after `KEY: ` (first word).
    pub fn printed(&self, key: &str) -> String {
        printed(&self.banner, key)
    }

    pub fn tcp(&self) -> String {
        self.printed("tcp")
    }

    pub fn control(&self) -> String {
        self.printed("control")
    }

    /// A connection to the TCP endpoint, with a 5 s read timeout.
    pub fn connect(&self) -> TcpStream {
        let s = TcpStream::connect(self.tcp()).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        s
    }

    /// The module still answers correctly: SAP, GAP and GGP over a new
    /// connection.
    pub fn check(&self) {
        let mut s = self.connect();
        for (line, expect) in [("SAP 4, 0, 1234", 1234), ("GAP 4, 0", 1234), ("GGP 66, 0", 1)] {
            let r = ask(&mut s, line).unwrap_or_else(|| panic!("{line}: no reply"));
            assert_eq!((r.status, r.value), (100, expect), "{line}");
        }
    }

    /// The module answers correctly ([`Server::check`]) as soon as the
    /// server took in what happened before (closed connections freeing
    /// their slots): tried every 20 ms for up to 10 s, failing with what
    /// the last try saw.
    pub fn check_soon(&self) {
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            let seen = (|| -> Result<(), String> {
                let mut s = TcpStream::connect(self.tcp()).map_err(|e| format!("connect: {e}"))?;
                s.set_read_timeout(Some(Duration::from_secs(2))).map_err(|e| e.to_string())?;
                for (line, expect) in [("SAP 4, 0, 1234", 1234), ("GAP 4, 0", 1234), ("GGP 66, 0", 1)] {
                    let r = ask(&mut s, line).ok_or_else(|| format!("{line}: no reply"))?;
                    if (r.status, r.value) != (100, expect) {
                        return Err(format!("{line}: status {} value {}", r.status, r.value));
                    }
                }
                Ok(())
            })();
            match seen {
                Ok(()) => return,
                Err(e) if Instant::now() > deadline => {
                    panic!("the module did not answer within 10 s: {e}; log {:?}", self.log.lock().unwrap())
                }
                Err(_) => std::thread::sleep(Duration::from_millis(20)),
            }
        }
    }

    /// Resident memory in KiB.
    #[cfg(unix)]
    pub fn rss_kib(&self) -> u64 {
        let s = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).unwrap();
        s.lines().find(|l| l.starts_with("VmRSS:")).unwrap().split_whitespace().nth(1).unwrap().parse().unwrap()
    }

    /// Resident memory (the working set) in KiB.
    #[cfg(windows)]
    pub fn rss_kib(&self) -> u64 {
        use std::os::windows::io::AsRawHandle;
        use windows_sys::Win32::System::ProcessStatus::{K32GetProcessMemoryInfo, PROCESS_MEMORY_COUNTERS};
        // SAFETY: the counters are plain data, written by the call with the
        // size given, for the handle of the child this test started.
        let counters = unsafe {
            let mut c: PROCESS_MEMORY_COUNTERS = std::mem::zeroed();
            let size = std::mem::size_of::<PROCESS_MEMORY_COUNTERS>() as u32;
            assert_ne!(K32GetProcessMemoryInfo(self.child.as_raw_handle(), &mut c, size), 0, "{}", std::io::Error::last_os_error());
            c
        };
        counters.WorkingSetSize as u64 / 1024
    }

    /// The first log line holding every piece, waiting up to 10 s for it
    /// (the log arrives through a pipe, after a client's answer).
    pub fn logged(&self, pieces: &[&str]) -> Option<String> {
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            if let Some(l) = self.log.lock().unwrap().iter().find(|l| pieces.iter().all(|p| l.contains(p))) {
                return Some(l.clone());
            }
            if Instant::now() > deadline {
                return None;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// How many log lines contain `what`, waiting up to 10 s for the first.
    pub fn log_has(&self, what: &str) -> usize {
        self.log_has_at_least(what, 1)
    }

    /// How many log lines contain `what`, waiting up to 10 s for `n` of them.
    pub fn log_has_at_least(&self, what: &str, n: usize) -> usize {
        let count = || self.log.lock().unwrap().iter().filter(|l| l.contains(what)).count();
        let until = Instant::now() + Duration::from_secs(10);
        while count() < n && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(10));
        }
        count()
    }

    /// Waits up to `limit` for the process to end; its exit code.
    pub fn exit_code_within(&mut self, limit: Duration) -> Option<i32> {
        exit_within(&mut self.child, limit).and_then(|s| s.code())
    }

    /// Stops the server as Ctrl-C would (SIGTERM; see [`interrupt`]) and
    /// waits for it.
    pub fn stop(mut self) {
        interrupt(&mut self.child);
        let _ = self.child.wait();
    }

    /// Everything the server wrote on standard error, once it stopped (as
    /// Ctrl-C stops it): for what must not be in the log.
    pub fn whole_log(mut self) -> Vec<String> {
        interrupt(&mut self.child);
        let _ = self.child.wait();
        if let Some(r) = self.reader.take() {
            let _ = r.join();
        }
        self.log.lock().unwrap().clone()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Waits up to `limit` for `child` to end (polling every 20 ms); its exit
/// status, or `None` when it still runs.
pub fn exit_within(child: &mut Child, limit: Duration) -> Option<std::process::ExitStatus> {
    let started = Instant::now();
    while started.elapsed() < limit {
        if let Some(status) = child.try_wait().unwrap() {
            return Some(status);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    None
}

/// Asks a child process to stop as Ctrl-C would: SIGTERM. On Windows
/// that is a console control event, which Wine does not deliver to another
/// process: the child is killed there, and the tests of a clean stop are
/// Unix's.
pub fn interrupt(child: &mut Child) {
    #[cfg(unix)]
    // SAFETY: signalling the child this test started.
    unsafe {
        libc::kill(child.id() as i32, libc::SIGTERM);
    }
    #[cfg(not(unix))]
    let _ = child.kill();
}

/// The request frame of a command (mnemonic or `#op type motor value`) to
/// module address 1.
pub fn frame(line: &str) -> [u8; 9] {
    Request::new(1, parse_line(line).unwrap()).encode()
}

/// Sends a command and reads the reply; `None` when the connection fails
/// or the reply is not a valid frame.
pub fn ask(s: &mut TcpStream, line: &str) -> Option<Reply> {
    s.write_all(&frame(line)).ok()?;
    let mut buf = [0u8; 9];
    s.read_exact(&mut buf).ok()?;
    Reply::decode(&buf)
}

/// Runs `tmclsim ARGS` to the end with standard input closed.
pub fn tmclsim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tmclsim")).args(args).stdin(Stdio::null()).output().unwrap()
}

/// Standard output and standard error of a finished command, together.
pub fn text(o: &std::process::Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Sends one HTTP/1.1 request to the app at `url` (`http://ADDR/`): the
/// status line and the body.
pub fn http(url: &str, method: &str, path: &str, json: Option<&str>) -> (String, String) {
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    let mut s = TcpStream::connect(addr).unwrap();
    let headers = json.map_or(String::new(), |j| format!("Content-Type: application/json\r\nContent-Length: {}\r\n", j.len()));
    write!(s, "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n{headers}\r\n{}", json.unwrap_or("")).unwrap();
    let mut all = String::new();
    s.read_to_string(&mut all).unwrap();
    let (head, body) = all.split_once("\r\n\r\n").unwrap();
    (head.lines().next().unwrap().to_string(), body.to_string())
}

pub fn get(url: &str, path: &str) -> (String, String) {
    http(url, "GET", path, None)
}

pub fn post(url: &str, path: &str, json: &str) -> (String, String) {
    http(url, "POST", path, Some(json))
}

/// An HTTP POST whose head is padded to a multiple of nine bytes, so that
/// a server that took the head for bad frames would meet the body's
/// frames in step: what a web page sends with `fetch(…, {mode:
/// "no-cors", method: "POST", body})`.
pub fn http_post_with_frames(addr: &str, body: &[u8]) -> Vec<u8> {
    let mut head = format!("POST / HTTP/1.1\r\nHost: {addr}\r\nContent-Type: text/plain\r\nContent-Length: {}\r\nX-Pad: ", body.len());
    while (head.len() + 4) % 9 != 0 {
        head.push('a');
    }
    head.push_str("\r\n\r\n");
    [head.into_bytes(), body.to_vec()].concat()
}

/// Sends `bytes` on a new connection and reads until the server closes it
/// (at most 5 s): what came back.
pub fn send_and_read_to_close(addr: &str, bytes: &[u8]) -> Vec<u8> {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    s.write_all(bytes).unwrap();
    let mut back = Vec::new();
    let _ = s.read_to_end(&mut back);
    back
}
