//! The control socket: a line protocol to change the world of a served
//! module while it runs (docs/world.md lists the commands).

use crate::faults::LinkFaults;
use crate::shared::SharedBus;
use std::sync::Arc;
use std::time::Duration;
use tmclsim_firmware::world_command::{Addressed, on_off};
use tokio::io::{AsyncBufReadExt, AsyncWriteExt, BufReader};
use tokio::net::TcpListener;
use tokio::sync::watch;

pub use tmclsim_firmware::world_command::HELP;

pub(crate) async fn run(listener: TcpListener, module: Arc<SharedBus>, mut stop: watch::Receiver<bool>) {
    loop {
        tokio::select! {
            accepted = listener.accept() => {
                let Ok((stream, _)) = accepted else { continue };
                let module = module.clone();
                tokio::spawn(async move {
                    let (r, mut w) = stream.into_split();
                    let mut lines = BufReader::new(r).lines();
                    while let Ok(Some(line)) = lines.next_line().await {
                        let answer = match execute(&module, &line) {
                            Ok(text) => format!("ok{}{text}\n", if text.is_empty() { "" } else { " " }),
                            Err(e) => format!("error: {e}\n"),
                        };
                        if w.write_all(answer.as_bytes()).await.is_err() {
                            break;
                        }
                    }
                });
            }
            _ = stop.changed() => return,
        }
    }
}

/// Executes one control line (`[@ADDRESS] COMMAND …`, docs/world.md);
/// `Ok` carries what to print after `ok`. `link …` changes the link's
/// faults; everything else is a typed world command applied through the
/// bus to the addressed module (the first one without `@ADDRESS`).
pub fn execute(bus: &SharedBus, line: &str) -> Result<String, String> {
    let mut w = line.split_whitespace();
    match w.next() {
        None => return Ok(String::new()),
        Some("help") => return Ok(HELP.to_string()),
        Some("link") => {
            let mut f: LinkFaults = bus.link_faults();
            match w.next() {
                Some("drop") => f.drop = num(w.next(), "count")?,
                Some("corrupt") => f.corrupt = num(w.next(), "count")?,
                Some("delay") => f.delay = Duration::from_millis(num(w.next(), "delay in ms")?),
                Some("mute") => f.mute = on_off(w.next())?,
                Some("clear") => f = LinkFaults::default(),
                other => return Err(format!("link {}: use drop, corrupt, delay, mute or clear", other.unwrap_or(""))),
            }
            bus.set_link_faults(f);
            return Ok(String::new());
        }
        Some(_) => {}
    }
    let Addressed { address, command } = Addressed::parse(line)?;
    bus.apply_world(address, &command)
}

fn num<T: std::str::FromStr>(w: Option<&str>, what: &str) -> Result<T, String> {
    let w = w.ok_or_else(|| format!("{what} is missing"))?;
    w.parse().map_err(|_| format!("'{w}' is not a valid {what}"))
}
