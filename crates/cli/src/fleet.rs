//! Fleets: many modules on many links from one `tmclsim serve --fleet FILE`
//! process, and `tmclsim fleet-bench`, the load generator that drives a
//! fleet from a second process and reports what it measured.
//!
//! The fleet file (TOML):
//!
//! ```toml
//! world = "stage"                # default world: stage, free or a file
//! speed = 50                     # optional: virtual time 50 × the wall clock
//!                                # (each link may say its own; --speed otherwise)
//! [[link]]
//! tcp = "127.0.0.1:20000"        # or pty = "/tmp/tmclsim-bus", or
//!                                # serial = "/dev/ttyUSB0" (or a list; COM5
//!                                # on Windows) with baud = 115200 (GP 65's
//!                                # rate otherwise)
//! count = 1000                   # 1000 such links, ports 20000, 20001, …
//! modules = ["tmcm-1141@1"]      # PROFILE@ADDRESS, any mix
//! [[link]]
//! tcp = "127.0.0.1:21000"
//! bus = "tmcm-1141"              # a bus of `size` modules, addresses 1…size
//! size = 250
//! ```

use serde::Deserialize;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tmclsim_firmware::{Eeprom, Module, Profile, Speed};
use tmclsim_server::{LinkSpec, ServerConfig};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FleetFile {
    #[serde(default = "stage")]
    world: String,
    /// Every link's speed (`--speed` otherwise).
    speed: Option<f64>,
    link: Vec<LinkFile>,
}

fn stage() -> String {
    "stage".into()
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LinkFile {
    tcp: Option<SocketAddr>,
    pty: Option<PathBuf>,
    serial: Option<Devices>,
    baud: Option<u32>,
    #[serde(default)]
    modules: Vec<String>,
    bus: Option<String>,
    size: Option<u16>,
    #[serde(default = "one")]
    count: usize,
    world: Option<String>,
    #[serde(default)]
    wire_timing: bool,
    /// This link's speed (the file's otherwise).
    speed: Option<f64>,
}
/// `serial = "DEVICE"` or `serial = ["DEVICE", …]`.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum Devices {
    One(String),
    Many(Vec<String>),
}

impl Devices {
    fn list(&self) -> Vec<String> {
        match self {
            Devices::One(d) => vec![d.clone()],
            Devices::Many(all) => all.clone(),
        }
    }
}

fn one() -> usize {
    1
}

/// One link of the expanded fleet: where, and which (profile, address).
#[derive(Clone, Debug)]
pub struct Link {
    pub tcp: Option<SocketAddr>,
    pub pty: Option<PathBuf>,
    pub serial: Vec<tmclsim_server::SerialLine>,
    pub modules: Vec<(String, u8)>,
    pub world: String,
    pub wire_timing: bool,
    /// The link's speed, when the file gives one.
    pub speed: Option<Speed>,
}

/// Most modules one fleet serves (about 32 KiB each).
pub const MAX_MODULES: usize = 10_000;

/// Reads a fleet file and expands counts and buses.
pub fn load(path: &std::path::Path) -> Result<Vec<Link>, String> {
    use tmclsim_server::files::{MAX_CONFIG_BYTES, read_text_limited};
    let text = read_text_limited(path, MAX_CONFIG_BYTES, "a fleet file")?;
    let f: FleetFile = toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Vec::new();
    for (i, l) in f.link.iter().enumerate() {
        let what = || format!("{}: link {}", path.display(), i + 1);
        let speed = l.speed.or(f.speed).map(Speed::new).transpose().map_err(|e| format!("{}: {e}", what()))?;
        let mut modules = Vec::new();
        for m in &l.modules {
            let (p, a) = m.split_once('@').ok_or_else(|| format!("{}: '{m}': write PROFILE@ADDRESS", what()))?;
            let a: u8 = a.parse().ok().filter(|a| *a >= 1).ok_or_else(|| format!("{}: '{m}': the address is 1…255", what()))?;
            modules.push((p.to_string(), a));
        }
        if let Some(p) = &l.bus {
            let size = l.size.unwrap_or(1);
            if !(1..=255).contains(&size) {
                return Err(format!("{}: a bus has 1…255 modules", what()));
            }
            modules.extend((1..=size).map(|a| (p.clone(), a as u8)));
        }
        if modules.is_empty() {
            return Err(format!("{}: no modules (give modules = [...] or bus = ...)", what()));
        }
        if let Some(a) = tmclsim_firmware::bus::duplicate_address(modules.iter().map(|(_, a)| *a)) {
            return Err(format!("{}: two modules at address {a} (each module of a bus has its own address)", what()));
        }
        let devices = l.serial.as_ref().map(Devices::list).unwrap_or_default();
        if l.tcp.is_none() && l.pty.is_none() && devices.is_empty() {
            return Err(format!("{}: give tcp = \"ADDR\", pty = \"PATH\" or serial = \"DEVICE\"", what()));
        }
        if l.count == 0 {
            return Err(format!("{}: count is at least 1", what()));
        }
        if let (Some(_), Some(why)) = (&l.pty, crate::platform::PTY_REFUSED) {
            return Err(format!("{}: pty: {why}", what()));
        }
        if !devices.is_empty() && l.count > 1 {
            return Err(format!("{}: a serial device is one link: count must be 1 with serial = ...", what()));
        }
        if l.baud.is_some() && devices.is_empty() {
            return Err(format!("{}: baud is the rate of a serial device: give serial = \"DEVICE\" too", what()));
        }
        if let Some(b) = l.baud {
            crate::check_baud(b).map_err(|e| format!("{}: {e}", what()))?;
        }
        let serial: Vec<tmclsim_server::SerialLine> =
            devices.into_iter().map(|device| tmclsim_server::SerialLine { device, baud: l.baud }).collect();
        let total = out.iter().map(|l: &Link| l.modules.len()).sum::<usize>();
        if l.count.saturating_mul(modules.len()).saturating_add(total) > MAX_MODULES {
            return Err(format!("{}: the fleet would have more than {MAX_MODULES} modules, the limit of one fleet", what()));
        }
        if let Some(a) = l.tcp
            && a.port() != 0
            && a.port() as usize + (l.count - 1) > u16::MAX as usize
        {
            return Err(format!("{}: {} links from port {} would pass port 65535", what(), l.count, a.port()));
        }
        for k in 0..l.count {
            let tcp = l.tcp.map(|a| SocketAddr::new(a.ip(), if a.port() == 0 { 0 } else { a.port() + k as u16 }));
            let pty = l.pty.as_ref().map(|p| if l.count > 1 { PathBuf::from(format!("{}-{k}", p.display())) } else { p.clone() });
            out.push(Link {
                tcp,
                pty,
                serial: serial.clone(),
                modules: modules.clone(),
                world: l.world.clone().unwrap_or_else(|| f.world.clone()),
                wire_timing: l.wire_timing,
                speed,
            });
        }
    }
    Ok(out)
}

pub fn serve(path: &std::path::Path, args: &crate::ServeArgs) -> Result<ExitCode, String> {
    let links = load(path)?;
    let mut specs = Vec::with_capacity(links.len());
    let mut total = 0;
    // One profile per kind of module, shared by all of them.
    let mut profiles: std::collections::HashMap<String, std::sync::Arc<Profile>> = Default::default();
    for l in &links {
        let mut modules = Vec::with_capacity(l.modules.len());
        for (p, a) in &l.modules {
            let profile = match profiles.get(p) {
                Some(pr) => pr.clone(),
                None => {
                    let pr = Profile::built_in(p)?;
                    profiles.insert(p.clone(), pr.clone());
                    pr
                }
            };
            let world = tmclsim_server::files::world_named(&l.world, profile.module.axes as usize)?;
            let mut m = Module::with_world(profile.clone(), Eeprom::new(&profile.module.name), world);
            m.set_address(*a);
            modules.push((m, None));
        }
        total += modules.len();
        let config = ServerConfig {
            tcp: l.tcp,
            pty: l.pty.clone(),
            serial: l.serial.clone(),
            inter_byte_timeout: crate::millis(args.inter_byte_timeout),
            max_connections: args.max_connections,
            bad_frame_limit: args.bad_frame_limit,
            wire_timing: l.wire_timing,
            speed: l.speed.unwrap_or(args.speed),
            log_frames: args.log_frames,
            ..ServerConfig::default()
        };
        specs.push(LinkSpec { modules, config });
    }
    let signals = crate::signal::Signals::install()?;
    let server = tmclsim_server::start_fleet(specs).map_err(|e| format!("cannot serve the fleet: {e}"))?;
    println!("tmclsim: fleet of {total} modules on {} links is serving", server.links().len());
    for line in tmclsim_server::bootloader_lines(server.links()) {
        println!("  {line}");
    }
    let web = crate::ide::start_web(args, server.links())?;
    if let Some(first) = server.links().first() {
        if let Some(a) = first.endpoints.pytrinamic_args() {
            println!("connect with: pytrinamic ConnectionManager(\"{a}\")  (first link)");
        } else if let Some(hint) = first.endpoints.serial_hint() {
            println!("connect with: {hint}  (first link)");
        }
    }
    use std::io::Write;
    let _ = std::io::stdout().flush();
    signals.wait();
    drop(web);
    let s = server.stats();
    println!("stats: frames {}, missed real-time deadlines {}, max lateness {} µs", s.frames, s.missed_deadlines, s.max_lateness_ns / 1000);
    let _ = std::io::stdout().flush();
    server.stop();
    Ok(ExitCode::SUCCESS)
}

#[derive(clap::Args)]
pub struct FleetBenchArgs {
    /// The fleet file to serve and drive.
    #[arg(long, value_name = "FILE")]
    pub fleet: PathBuf,
    /// Commands per second to each module (more than 0, at most 100000).
    #[arg(long, default_value_t = 10.0, value_parser = parse_rate)]
    pub rate: f64,
    /// How long to drive the fleet.
    #[arg(long = "for", value_name = "DURATION", default_value = "10s", value_parser = crate::duration::parse_duration)]
    pub duration: u64,
}

/// Most commands per second to one module `fleet-bench` sends.
const MAX_RATE: f64 = 100_000.0;

fn parse_rate(text: &str) -> Result<f64, String> {
    let rate: f64 = text.parse().map_err(|_| format!("'{text}' is not a number"))?;
    if rate > 0.0 && rate <= MAX_RATE {
        Ok(rate)
    } else {
        Err(format!("the rate is more than 0 and at most {MAX_RATE} commands per second"))
    }
}

/// Serves the fleet in a child process, drives every module at `rate`
/// with a mix of GAP/SAP/MVP over TCP, and prints the report.
pub fn bench(args: FleetBenchArgs) -> Result<ExitCode, String> {
    let links = load(&args.fleet)?;
    let modules: usize = links.iter().map(|l| l.modules.len()).sum();
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut child = crate::platform::stoppable(&mut std::process::Command::new(exe))
        .args(["serve", "--max-connections", "100000", "--fleet"])
        .arg(&args.fleet)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())?;
    let mut out = std::io::BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    use std::io::BufRead;
    out.read_line(&mut line).map_err(|e| e.to_string())?;
    if !line.contains("is serving") {
        let _ = child.kill();
        return Err(format!("the fleet did not start: {line}"));
    }
    let pid = child.id();
    let cpu0 = crate::platform::process_cpu(pid)?;
    let wall0 = Instant::now();
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().map_err(|e| e.to_string())?;
    let duration = Duration::from_nanos(args.duration);
    let results = rt.block_on(drive(links, args.rate, duration));
    let wall = wall0.elapsed();
    let cpu1 = crate::platform::process_cpu(pid)?;
    let rss_kib = crate::platform::resident_kib(pid).unwrap_or(0);
    // Stopped as Ctrl-C stops it, so that it prints its stats.
    crate::platform::stop(&mut child);
    let mut stats = String::new();
    loop {
        line.clear();
        if out.read_line(&mut line).map_err(|e| e.to_string())? == 0 {
            break;
        }
        if line.starts_with("stats:") {
            stats = line.trim().to_string();
        }
    }
    let _ = child.wait();
    let (mut rtt, errors) = results?;
    rtt.sort();
    let n = rtt.len();
    let pct = |p: f64| rtt.get(((n as f64 * p) as usize).min(n.saturating_sub(1))).copied().unwrap_or_default();
    let cpu = (cpu1.0 + cpu1.1).saturating_sub(cpu0.0 + cpu0.1);
    println!(
        "tmclsim fleet-bench: {modules} modules on {} links, {} commands/s each, {:.1} s, {} cores",
        rtt_links(&args.fleet),
        args.rate,
        wall.as_secs_f64(),
        std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
    );
    println!();
    println!("| measurement | result |");
    println!("|---|---|");
    println!("| commands | {n} ({:.0}/s), {errors} errors or timeouts |", n as f64 / wall.as_secs_f64());
    println!(
        "| round trip | p50 {:.0} µs, p99 {:.0} µs, max {:.0} µs |",
        us(pct(0.5)),
        us(pct(0.99)),
        us(rtt.last().copied().unwrap_or_default())
    );
    println!("| server | {stats} |");
    println!("| server CPU | {:.1} % of one core |", cpu.as_secs_f64() / wall.as_secs_f64() * 100.0);
    println!("| server memory | {} KiB resident, {:.1} KiB per module |", rss_kib, rss_kib as f64 / modules.max(1) as f64);
    Ok(ExitCode::SUCCESS)
}

fn rtt_links(path: &std::path::Path) -> usize {
    load(path).map_or(0, |l| l.len())
}

fn us(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

/// One task per link; it polls each module of its link in turn so that
/// every module sees `rate` commands per second.
async fn drive(links: Vec<Link>, rate: f64, duration: Duration) -> Result<(Vec<Duration>, u64), String> {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let mut tasks = tokio::task::JoinSet::new();
    for (i, l) in links.into_iter().enumerate() {
        let Some(addr) = l.tcp else { continue };
        tasks.spawn(async move {
            let mut rtt = Vec::new();
            let mut errors = 0u64;
            let Ok(mut s) = tokio::net::TcpStream::connect(addr).await else { return (rtt, 1) };
            let _ = s.set_nodelay(true);
            let per_link = rate * l.modules.len() as f64;
            let period = Duration::from_secs_f64(1.0 / per_link);
            // Spread the links over the first period.
            tokio::time::sleep(period.mul_f64((i % 97) as f64 / 97.0)).await;
            let start = tokio::time::Instant::now();
            let mut next = start;
            let mut k = 0u64;
            while start.elapsed() < duration {
                let (_, address) = l.modules[(k as usize) % l.modules.len()];
                let ins = match k % 4 {
                    0 => tmclsim_protocol::Instruction::new(6, 1, 0, 0),
                    1 => tmclsim_protocol::Instruction::new(5, 4, 0, 1000 + (k % 500) as i32),
                    2 => tmclsim_protocol::Instruction::new(4, 1, 0, if k % 8 == 2 { 1000 } else { -1000 }),
                    _ => tmclsim_protocol::Instruction::new(6, 8, 0, 0),
                };
                let frame = tmclsim_protocol::Request::new(address, ins).encode();
                let t = std::time::Instant::now();
                let mut reply = [0u8; 9];
                let ok = s.write_all(&frame).await.is_ok()
                    && tokio::time::timeout(Duration::from_secs(1), s.read_exact(&mut reply)).await.is_ok_and(|r| r.is_ok());
                if ok {
                    rtt.push(t.elapsed());
                } else {
                    errors += 1;
                }
                k += 1;
                next += period;
                tokio::time::sleep_until(next).await;
            }
            (rtt, errors)
        });
    }
    let mut all = Vec::new();
    let mut errors = 0;
    while let Some(r) = tasks.join_next().await {
        let (r, e) = r.map_err(|e| e.to_string())?;
        all.extend(r);
        errors += e;
    }
    Ok((all, errors))
}
