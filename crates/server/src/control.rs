//! The control socket: a line protocol to change the world of a served
//! module while it runs (docs/world.md lists the commands).

use crate::ServerConfig;
use crate::SharedBus;
use crate::slots::{Activity, Slots, accept};
use std::sync::Arc;
use tmclsim_protocol::preamble::{Preamble, Verdict};
use tokio::io::{AsyncBufRead, AsyncBufReadExt, AsyncRead, AsyncReadExt, AsyncWriteExt, BufReader};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::watch;

pub use tmclsim_firmware::world_command::HELP;
/// A control line on a bus (the bus's own: the Python package runs lines
/// there too).
pub use tmclsim_host::shared::execute;

/// Serves the control socket: at most `config.control_max_connections`
/// clients at once (docs/robustness.md), each line at most
/// `config.control_max_line` bytes, and with `config.control_token` set,
/// only clients whose first line is `auth TOKEN`.
pub(crate) async fn run(listener: TcpListener, bus: Arc<SharedBus>, config: ServerConfig, mut stop: watch::Receiver<bool>) {
    let mut slots = Slots::new("control connection", config.control_max_connections, config.idle_timeout);
    let token: Option<Arc<str>> = config.control_token.as_deref().map(Arc::from);
    let mut failing = false;
    loop {
        tokio::select! {
            accepted = accept(&listener, &mut failing, "a control connection") => {
                let Some((stream, peer)) = accepted else { continue };
                if let Err(why) = slots.make_room() {
                    eprintln!("tmclsim: {}", crate::log_lines::refused("control connection", peer, why));
                    // A fresh socket's send buffer is empty: the line fits.
                    let _ = stream.try_write(format!("error: {why}\n").as_bytes());
                    continue;
                }
                let activity = Arc::new(Activity::new());
                let session = session(stream, bus.clone(), token.clone(), config.control_max_line, activity.clone());
                slots.spawn(peer, activity, session);
            }
            _ = slots.reap(), if !slots.is_empty() => {}
            _ = stop.changed() => break,
        }
    }
    slots.close_all();
}

/// One control client: a line in, an answer line out.
async fn session(stream: TcpStream, bus: Arc<SharedBus>, token: Option<Arc<str>>, max_line: usize, activity: Arc<Activity>) {
    let (mut r, mut w) = stream.into_split();
    // A client that opens with another protocol (a web page's request) is
    // closed before anything runs (docs/behaviour.md rule 90).
    let first = match screen(&mut r).await {
        Ok((Verdict::Tmcl, first)) => first,
        Ok((foreign, _)) => {
            eprintln!(
                "tmclsim: closing control connection: it opened with {}, not control lines; nothing was executed",
                foreign.describe()
            );
            return;
        }
        Err(_) => return,
    };
    let mut r = BufReader::new(std::io::Cursor::new(first).chain(r));
    let mut authenticated = token.is_none();
    let mut line = Vec::new();
    loop {
        let answer = match read_line(&mut r, max_line, &mut line).await {
            Ok(Line::End) | Err(_) => return,
            Ok(Line::TooLong { ended }) => {
                let answer = format!("error: line longer than {max_line} bytes\n");
                if w.write_all(answer.as_bytes()).await.is_err() {
                    return;
                }
                if !ended && skip_line(&mut r).await.is_err() {
                    return;
                }
                continue;
            }
            Ok(Line::Text) => {
                activity.touch();
                let text = String::from_utf8_lossy(&line);
                let mut command: &str = &text;
                if !authenticated {
                    match authenticate(command, token.as_deref().unwrap_or_default()) {
                        Ok(rest) => {
                            authenticated = true;
                            command = rest;
                        }
                        Err(e) => {
                            let _ = w.write_all(format!("error: {e}\n").as_bytes()).await;
                            return;
                        }
                    }
                }
                match execute(&bus, command) {
                    Ok(text) => format!("ok{}{text}\n", if text.is_empty() { "" } else { " " }),
                    Err(e) => format!("error: {e}\n"),
                }
            }
        };
        if w.write_all(answer.as_bytes()).await.is_err() {
            return;
        }
    }
}

/// Reads the connection's first bytes until they tell whether they are an
/// HTTP request or a TLS hello (the control protocol's lines, lower-case
/// words and `@ADDRESS`, never open like either); returns the verdict and
/// the bytes read, which belong to the first line.
async fn screen(r: &mut (impl AsyncRead + Unpin)) -> std::io::Result<(Verdict, Vec<u8>)> {
    let mut preamble = Preamble::new();
    let mut byte = [0u8; 1];
    loop {
        if r.read(&mut byte).await? == 0 {
            return Ok((Verdict::Tmcl, preamble.held().to_vec()));
        }
        match preamble.push(byte[0]) {
            Verdict::Undecided => continue,
            Verdict::Tmcl => return Ok((Verdict::Tmcl, preamble.held().to_vec())),
            foreign => return Ok((foreign, Vec::new())),
        }
    }
}

/// `auth TOKEN [COMMAND…]`: the command after the token (may be empty),
/// or why the client is turned away.
fn authenticate<'a>(line: &'a str, token: &str) -> Result<&'a str, &'static str> {
    let rest = line
        .trim_start()
        .strip_prefix("auth")
        .filter(|r| r.is_empty() || r.starts_with(char::is_whitespace))
        .ok_or("this control socket needs a token: send \"auth TOKEN\" first")?
        .trim_start();
    let (given, command) = rest.split_once(char::is_whitespace).unwrap_or((rest, ""));
    if same_token(given, token) { Ok(command) } else { Err("wrong token") }
}

/// Whether a token a client gave is the secret one, compared in a time
/// that does not depend on where they differ (only on the given length).
pub fn same_token(given: &str, secret: &str) -> bool {
    let (g, s) = (given.as_bytes(), secret.as_bytes());
    let differ = (0..g.len()).fold(u8::from(g.len() != s.len()), |acc, i| acc | (g[i] ^ s.get(i).copied().unwrap_or(0)));
    differ == 0
}

enum Line {
    /// A line (without its line end) is in the buffer.
    Text,
    /// The line passed the limit; `ended`: its line end was read too.
    TooLong { ended: bool },
    /// The client closed its side.
    End,
}

/// Reads one line into `line`, keeping at most `max` bytes in memory.
async fn read_line(r: &mut (impl AsyncBufRead + Unpin), max: usize, line: &mut Vec<u8>) -> std::io::Result<Line> {
    line.clear();
    loop {
        let available = r.fill_buf().await?;
        if available.is_empty() {
            return Ok(if line.is_empty() { Line::End } else { Line::Text });
        }
        let (taken, ended) = match available.iter().position(|&b| b == b'\n') {
            Some(i) => (i, true),
            None => (available.len(), false),
        };
        if line.len() + taken > max {
            r.consume(taken + usize::from(ended));
            return Ok(Line::TooLong { ended });
        }
        line.extend_from_slice(&available[..taken]);
        r.consume(taken + usize::from(ended));
        if ended {
            if line.last() == Some(&b'\r') {
                line.pop();
            }
            return Ok(Line::Text);
        }
    }
}

/// Reads and drops the rest of a line.
async fn skip_line(r: &mut (impl AsyncBufRead + Unpin)) -> std::io::Result<()> {
    loop {
        let available = r.fill_buf().await?;
        if available.is_empty() {
            return Ok(());
        }
        match available.iter().position(|&b| b == b'\n') {
            Some(i) => {
                r.consume(i + 1);
                return Ok(());
            }
            None => {
                let n = available.len();
                r.consume(n);
            }
        }
    }
}
