//! The control socket: a line protocol to change the world of a served
//! module while it runs (docs/world.md lists the commands).

use crate::faults::LinkFaults;
use crate::shared::SharedModule;
use std::sync::Arc;
use std::time::Duration;
use tmclsim_firmware::world::Load;
use tokio::io::{AsyncBufReadExt, AsyncWriteExt, BufReader};
use tokio::net::TcpListener;
use tokio::sync::watch;

pub const HELP: &str = "commands: input N 0|1 | analog N VALUE | supply VOLTS | temperature CELSIUS | \
switch AXIS left|right|home press|release|auto | place AXIS left|right POSITION [WIDTH] | place AXIS home FROM TO | \
travel AXIS FROM TO | load AXIS TORQUE [FROM TO] | fault AXIS short-a|short-b|open-a|open-b on|off | \
link drop N | link corrupt N | link delay MS | link mute on|off | link clear | show [AXIS] | help";

pub(crate) async fn run(listener: TcpListener, module: Arc<SharedModule>, mut stop: watch::Receiver<bool>) {
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

fn num<T: std::str::FromStr>(w: Option<&str>, what: &str) -> Result<T, String> {
    let w = w.ok_or_else(|| format!("{what} is missing"))?;
    w.parse().map_err(|_| format!("'{w}' is not a valid {what}"))
}

fn on_off(w: Option<&str>) -> Result<bool, String> {
    match w {
        Some("on") | Some("1") => Ok(true),
        Some("off") | Some("0") => Ok(false),
        other => Err(format!("expected on or off, found {}", other.unwrap_or("nothing"))),
    }
}

/// Executes one control line; `Ok` carries what to print after `ok`.
pub fn execute(module: &SharedModule, line: &str) -> Result<String, String> {
    let mut w = line.split_whitespace();
    let Some(cmd) = w.next() else { return Ok(String::new()) };
    if cmd == "link" {
        let mut f: LinkFaults = module.link_faults();
        match w.next() {
            Some("drop") => f.drop = num(w.next(), "count")?,
            Some("corrupt") => f.corrupt = num(w.next(), "count")?,
            Some("delay") => f.delay = Duration::from_millis(num(w.next(), "delay in ms")?),
            Some("mute") => f.mute = on_off(w.next())?,
            Some("clear") => f = LinkFaults::default(),
            other => return Err(format!("link {}: use drop, corrupt, delay, mute or clear", other.unwrap_or(""))),
        }
        module.set_link_faults(f);
        return Ok(String::new());
    }
    if cmd == "help" {
        return Ok(HELP.to_string());
    }
    module.with(|m| {
        let axes = m.profile().module.axes as usize;
        let axis = |w: Option<&str>| -> Result<usize, String> {
            let a: usize = num(w, "axis")?;
            if a < axes { Ok(a) } else { Err(format!("axis {a} does not exist (the module has {axes})")) }
        };
        match cmd {
            "input" => {
                let n: u8 = num(w.next(), "input number")?;
                let level: u8 = num(w.next(), "level")?;
                m.world_mut().set_digital(n, level != 0);
            }
            "analog" => {
                let n: u8 = num(w.next(), "input number")?;
                let v: u16 = num(w.next(), "value")?;
                if v > 4095 {
                    return Err(format!("{v} is above 4095"));
                }
                m.world_mut().set_analog(n, v);
            }
            "supply" => {
                let v: f64 = num(w.next(), "voltage")?;
                m.world_mut().supply_decivolts = (v * 10.0).round().clamp(0.0, 1000.0) as u16;
            }
            "temperature" => m.world_mut().temperature = num(w.next(), "temperature")?,
            "switch" => {
                let a = axis(w.next())?;
                let which = w.next();
                let state = match w.next() {
                    Some("press") => Some(true),
                    Some("release") => Some(false),
                    Some("auto") => None,
                    other => return Err(format!("expected press, release or auto, found {}", other.unwrap_or("nothing"))),
                };
                let wa = &mut m.world_mut().axes[a];
                match which {
                    Some("left") => wa.forced_left = state,
                    Some("right") => wa.forced_right = state,
                    Some("home") => wa.forced_home = state,
                    other => return Err(format!("expected left, right or home, found {}", other.unwrap_or("nothing"))),
                }
            }
            "place" => {
                let a = axis(w.next())?;
                let which = w.next();
                let p: f64 = num(w.next(), "position")?;
                let rest: Option<f64> = w.next().map(|x| x.parse().map_err(|_| format!("'{x}' is not a number"))).transpose()?;
                let wa = &mut m.world_mut().axes[a];
                match which {
                    Some("left") => (wa.left_switch, wa.left_width) = (Some(p), rest),
                    Some("right") => (wa.right_switch, wa.right_width) = (Some(p), rest),
                    Some("home") => wa.home_switch = Some((p, rest.ok_or("place home takes FROM and TO")?)),
                    other => return Err(format!("expected left, right or home, found {}", other.unwrap_or("nothing"))),
                }
            }
            "travel" => {
                let a = axis(w.next())?;
                let lo: f64 = num(w.next(), "position")?;
                let hi: f64 = num(w.next(), "position")?;
                m.world_mut().axes[a].travel = Some((lo, hi));
            }
            "load" => {
                let a = axis(w.next())?;
                let torque: f64 = num(w.next(), "torque in %")?;
                let from = w.next().map(|x| x.parse::<f64>().map_err(|_| format!("'{x}' is not a number"))).transpose()?;
                let to = w.next().map(|x| x.parse::<f64>().map_err(|_| format!("'{x}' is not a number"))).transpose()?;
                let loads = &mut m.world_mut().axes[a].loads;
                loads.clear();
                if torque > 0.0 {
                    loads.push(Load { torque, from, to, ..Load::default() });
                }
            }
            "fault" => {
                let a = axis(w.next())?;
                let which = w.next();
                let on = on_off(w.next())?;
                let f = &mut m.world_mut().axes[a].faults;
                match which {
                    Some("short-a") => f.short_a = on,
                    Some("short-b") => f.short_b = on,
                    Some("open-a") => f.open_a = on,
                    Some("open-b") => f.open_b = on,
                    other => return Err(format!("expected short-a, short-b, open-a or open-b, found {}", other.unwrap_or("nothing"))),
                }
            }
            "show" => {
                let list: Vec<usize> = match w.next() {
                    Some(x) => vec![axis(Some(x))?],
                    None => (0..axes).collect(),
                };
                let mut out = format!("time {:.3} s", m.now_ns() as f64 * 1e-9);
                for a in list {
                    let (l, r, h) = m.switches(a);
                    out.push_str(&format!(
                        "; axis {a}: position {} carriage {:.1} speed {} left {} right {} home {}",
                        m.actual_position(a),
                        m.mechanical_position(a),
                        m.actual_speed(a),
                        l as u8,
                        r as u8,
                        h as u8
                    ));
                }
                return Ok(out);
            }
            other => return Err(format!("unknown command '{other}' ({HELP})")),
        }
        Ok(String::new())
    })
}
