//! `tmclsim bench`: commands per second in-process, round trips over TCP
//! and the pty with a Rust client, and the server's CPU time per command.

use crate::platform::{process_cpu, self_cpu};
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tmclsim_firmware::{Bus, Module, Profile};
use tmclsim_protocol::Request;
use tmclsim_protocol::mnemonic::parse_line;

/// The modules the in-process and motion rows measure, each with what its
/// rows add to its name and the commands that set it up first: the TMC429
/// family's, the sixPoint family's and a TMC4361A module's with its
/// S-shaped ramp (each row names its module).
const BENCH_MODULES: [(&str, &str, &[&str]); 3] =
    [("tmcm-1141", "", &[]), ("tmcm-1260", "", &[]), ("tmcm-1316", ", S-shaped ramp", S_SHAPED)];

/// The TMC4361A's S-shaped ramp (AP 14 = 1) with the four bows at
/// 51200 pps³: a second from no acceleration to the default AMAX (51200
/// pps²). With the bows at their default 0 the S-shaped ramp would be the
/// trapezoid (docs/behaviour.md rule 116).
const S_SHAPED: &[&str] = &["SAP 14, 0, 1", "SAP 22, 0, 51200", "SAP 23, 0, 51200", "SAP 24, 0, 51200", "SAP 25, 0, 51200"];

/// A module of its own for the rows, set up with the `setup` commands (each
/// must succeed: status 100).
fn set_up(profile: &Arc<Profile>, setup: &[&str]) -> Result<Module, String> {
    let mut m = Module::new(profile.clone());
    for line in setup {
        let reply = m.handle_frame(&Request::new(1, parse_line(line).unwrap()).encode());
        if reply.is_none_or(|r| r[2] != 100) {
            return Err(format!("{}: `{line}` answered {reply:?}", profile.module.name));
        }
    }
    Ok(m)
}

/// The command mix every measurement uses.
const MIX: &[&str] = &["GAP 1, 0", "SAP 4, 0, 1500", "GGP 66, 0", "GIO 0, 0", "MVP ABS, 0, 5000", "GAP 8, 0"];

/// Prints a table row above the stage bar (see `STAGES`).
macro_rules! row {
    ($($t:tt)*) => {
        STAGES.with(|s| match &*s.borrow() {
            Some(stages) => stages.println(&format!($($t)*)),
            None => println!($($t)*),
        })
    };
}

thread_local! {
    /// The benchmark's stages on the terminal, while it runs.
    static STAGES: std::cell::RefCell<Option<crate::progress::Stages>> = const { std::cell::RefCell::new(None) };
}

/// The next stage of the benchmark begins.
fn stage(what: &str) {
    STAGES.with(|s| {
        if let Some(stages) = &*s.borrow() {
            stages.start(what);
        }
    });
}

pub fn run(args: crate::BenchArgs) -> Result<std::process::ExitCode, String> {
    let frames: Vec<[u8; 9]> = MIX.iter().map(|l| Request::new(1, parse_line(l).unwrap()).encode()).collect();
    row!("tmclsim bench: command mix {MIX:?}, {} cores\n", std::thread::available_parallelism().map_or(1, std::num::NonZero::get));
    row!("| measurement | commands | result |");
    row!("|---|---:|---|");

    STAGES.with(|s| *s.borrow_mut() = Some(crate::progress::Stages::new(7)));
    let result = measure(&args, &frames);
    if let Some(stages) = STAGES.with(|s| s.borrow_mut().take()) {
        stages.finish();
    }
    result?;
    Ok(std::process::ExitCode::SUCCESS)
}

/// Every row of the table, stage by stage.
fn measure(args: &crate::BenchArgs, frames: &[[u8; 9]]) -> Result<(), String> {
    // In-process, one core: a TMC429 module, a sixPoint module (the
    // TMCM-1260's ramp) and a TMC4361A module (the TMCM-1316's S-shaped
    // ramp), the same command mix.
    stage("in-process handle_frame");
    for (module, suffix, setup) in BENCH_MODULES {
        let mut m = set_up(&Profile::built_in(module)?, setup)?;
        let n = args.in_process;
        let t = Instant::now();
        let mut sink = 0u64;
        for i in 0..n {
            if let Some(r) = m.handle_frame(&frames[i % frames.len()]) {
                sink = sink.wrapping_add(u64::from(r[7]));
            }
        }
        let dt = t.elapsed();
        std::hint::black_box(sink);
        row!(
            "| in-process `handle_frame`, {}{suffix} | {n} | {:.1} M commands/s ({:.1} ns each) |",
            m.profile().module.name,
            n as f64 / dt.as_secs_f64() / 1e6,
            dt.as_nanos() as f64 / n as f64
        );
    }

    stage("programs in virtual time");
    programs()?;
    served_programs(args.idle_seconds)?;
    stage("round trips over TCP");

    // Over the links of a `tmclsim serve` process.
    let dir = std::env::temp_dir().join(format!("tmclsim-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    // The pty where there are ptys (not on Windows).
    let pty = crate::platform::PTY_REFUSED.is_none().then(|| dir.join("pty"));
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut child = Command::new(exe)
        .args(["serve", "--tcp", "127.0.0.1:0"])
        .args(pty.iter().flat_map(|p| [std::ffi::OsStr::new("--pty"), p.as_os_str()]))
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| e.to_string())?;
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut tcp = None;
    loop {
        let mut line = String::new();
        if out.read_line(&mut line).map_err(|e| e.to_string())? == 0 {
            return Err("the server did not start".into());
        }
        if let Some(a) = line.trim().strip_prefix("tcp: ") {
            tcp = Some(a.to_string());
        }
        if line.starts_with("connect with:") {
            break;
        }
    }
    let tcp = tcp.ok_or("no tcp endpoint")?;
    let pid = child.id();
    let result = (|| -> Result<(), String> {
        let mut s = std::net::TcpStream::connect(&tcp).map_err(|e| e.to_string())?;
        s.set_nodelay(true).ok();
        report("TCP round trip, Rust client", &mut s, frames, args.round_trips, Some(pid))?;
        if let Some(pty) = &pty {
            stage("round trips over the pty");
            let mut port = std::fs::OpenOptions::new().read(true).write(true).open(pty).map_err(|e| e.to_string())?;
            report("pty round trip, Rust client", &mut port, frames, args.round_trips, Some(pid))?;
        }
        Ok(())
    })();
    stage("echo baseline");
    echo_baseline(frames, args.round_trips)?;
    let _ = child.kill();
    let _ = child.wait();
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn report(name: &str, link: &mut (impl Read + Write), frames: &[[u8; 9]], n: usize, pid: Option<u32>) -> Result<(), String> {
    let mut buf = [0u8; 9];
    for f in frames.iter().cycle().take(200) {
        link.write_all(f).map_err(|e| e.to_string())?;
        link.read_exact(&mut buf).map_err(|e| e.to_string())?;
    }
    let cpu0 = pid.map(process_cpu).transpose()?;
    let mut samples = Vec::with_capacity(n);
    for f in frames.iter().cycle().take(n) {
        let t = Instant::now();
        link.write_all(f).map_err(|e| e.to_string())?;
        link.read_exact(&mut buf).map_err(|e| e.to_string())?;
        samples.push(t.elapsed());
        if buf[3] != f[1] || buf[2] != 100 {
            return Err(format!("{name}: reply {buf:02X?} does not answer {f:02X?}"));
        }
    }
    let cpu = match (pid, cpu0) {
        (Some(pid), Some(c0)) => {
            let c1 = process_cpu(pid)?;
            let (user, system) = (c1.0 - c0.0, c1.1 - c0.1);
            format!(
                "; server CPU {:.1} µs/command ({:.1} user + {:.1} kernel)",
                us(user + system) / n as f64,
                us(user) / n as f64,
                us(system) / n as f64
            )
        }
        _ => String::new(),
    };
    samples.sort();
    let pct = |p: f64| samples[((samples.len() as f64 * p) as usize).min(samples.len() - 1)];
    row!("| {name} | {n} | p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs{cpu} |", us(pct(0.50)), us(pct(0.99)), us(*samples.last().unwrap()),);
    Ok(())
}

/// The program interpreter and the assembler.
fn programs() -> Result<(), String> {
    let profile = tmclsim_firmware::Profile::built_in("tmcm-1141")?;
    let asm =
        |src: &str| tmclsim_asm::assemble(src, "bench.tmc", &tmclsim_asm::NoIncludes, Some(&profile)).map_err(|d| tmclsim_asm::render(&d));
    // A compute-only loop: 3 instructions per turn, never ending.
    let compute = asm("Loop:\n  CALC ADD, 1\n  COMP 2000000000\n  JC LT, Loop\n  STOP\n")?;
    let (n, wall) = run_program(&profile, &[], &compute, 3_600_000_000_000)?;
    row!(
        "| VM, compute-only loop, 1 h of virtual time | {n} | {:.1} M instructions/s, {:.0}× real time |",
        n as f64 / wall / 1e6,
        3600.0 / wall
    );
    // The manual's 2.4 program (moves and WAIT POS) for an hour.
    let motion = asm(FIRST_STEPS)?;
    let (n, wall) = run_program(&profile, &[], &motion, 3_600_000_000_000)?;
    row!("| VM, manual 2.4 program (MVP/WAIT POS), 1 h of virtual time | {n} | {:.0}× real time ({:.3} ms) |", 3600.0 / wall, wall * 1e3);
    // A busy motion loop: GAP/COMP/JC polling while the motor moves, on
    // each motion controller.
    for (module, suffix, setup) in BENCH_MODULES {
        let profile = tmclsim_firmware::Profile::built_in(module)?;
        let asm = |src: &str| {
            tmclsim_asm::assemble(src, "bench.tmc", &tmclsim_asm::NoIncludes, Some(&profile)).map_err(|d| tmclsim_asm::render(&d))
        };
        let polling = asm(
            "Loop:\n  MVP ABS, 0, 512000\nWait1:\n  GAP 8, 0\n  JC ZE, Wait1\n  MVP ABS, 0, 0\nWait2:\n  GAP 8, 0\n  JC ZE, Wait2\n  JA Loop\n",
        )?;
        let (n, wall) = run_program(&profile, setup, &polling, 600_000_000_000)?;
        row!(
            "| VM, polling motion loop (GAP 8/JC), 10 min of virtual time, {}{suffix} | {n} | {:.1} M instructions/s, {:.0}× real time |",
            profile.module.name,
            n as f64 / wall / 1e6,
            600.0 / wall
        );
        // Virtual time alone with a move in progress: a host's GAP now and
        // then, the motor running back and forth.
        let wall = moving_module(&profile, setup)?;
        row!(
            "| motion, 1 h of virtual time with moves in progress, {}{suffix} | 3600 s | {:.0} simulated s per wall s |",
            profile.module.name,
            3600.0 / wall
        );
    }
    // The assembler.
    let mut src = String::from("Speed = 1000\nAccel = Speed / 2 + 3\n");
    let lines = 50_000;
    for i in 0..lines / 5 {
        src.push_str(&format!("L{i}:\n  SAP 4, 0, Speed\n  MVP ABS, 0, {i} * 100 + Accel\n  WAIT POS, 0, 0\n  JC NZ, L{}\n", i / 2));
    }
    let t = Instant::now();
    let p = tmclsim_asm::assemble(&src, "bench.tmc", &tmclsim_asm::NoIncludes, None).map_err(|d| tmclsim_asm::render(&d))?;
    let wall = t.elapsed().as_secs_f64();
    row!("| assembler ({} instructions) | {lines} lines | {:.2} M lines/s |", p.instructions.len(), f64::from(lines) / wall / 1e6);
    Ok(())
}

/// An hour of virtual time on a module of its own whose motor moves back
/// and forth all the time (a move of 10 million µsteps each way at the
/// profile's default ramp after the `setup` commands, a host's GAP 1 every
/// 10 ms): the wall time in seconds.
fn moving_module(profile: &Arc<Profile>, setup: &[&str]) -> Result<f64, String> {
    let mut bus = Bus::single(set_up(profile, setup)?);
    let frame = |line: &str| Request::new(1, parse_line(line).unwrap()).encode();
    let (out, back, gap, reached) = (frame("MVP ABS, 0, 10000000"), frame("MVP ABS, 0, 0"), frame("GAP 1, 0"), frame("GAP 8, 0"));
    let t = Instant::now();
    let mut outward = true;
    bus.handle_frame(&out);
    for _ in 0..360_000 {
        bus.advance(10_000_000);
        bus.handle_frame(&gap);
        if bus.handle_frame(&reached).replies.first().is_some_and(|r| r[7] == 1) {
            outward = !outward;
            bus.handle_frame(if outward { &out } else { &back });
        }
    }
    Ok(t.elapsed().as_secs_f64())
}

/// Runs `program` on a module of its own, set up with the `setup`
/// commands, for `ns` of virtual time: the instructions it executed and the
/// wall time, in seconds, that took.
fn run_program(profile: &Arc<Profile>, setup: &[&str], program: &tmclsim_asm::Program, ns: u64) -> Result<(u64, f64), String> {
    let mut m = set_up(profile, setup)?;
    m.load_program(&program.instructions).map_err(|s| s.to_string())?;
    m.start_program();
    let mut bus = Bus::single(m);
    let t = Instant::now();
    bus.advance(ns);
    Ok((bus.module(0).program().executed, t.elapsed().as_secs_f64()))
}

/// Served modules that run standalone programs while no host talks to them:
/// the server's CPU share comes only from the programs' own deadlines.
fn served_programs(seconds: f64) -> Result<(), String> {
    let profile = tmclsim_firmware::Profile::built_in("tmcm-1141")?;
    let asm =
        |src: &str| tmclsim_asm::assemble(src, "bench.tmc", &tmclsim_asm::NoIncludes, Some(&profile)).map_err(|d| tmclsim_asm::render(&d));
    let module = |program: &tmclsim_asm::Program| -> Result<Module, String> {
        let mut m = Module::new(profile.clone());
        m.load_program(&program.instructions).map_err(|s| s.to_string())?;
        m.start_program();
        Ok(m)
    };
    let waiting = asm("Loop:\n  WAIT TICKS, 0, 1000\n  JA Loop\n")?;
    let config =
        |port: u16| tmclsim_server::ServerConfig { tcp: Some(std::net::SocketAddr::from(([127, 0, 0, 1], port))), ..Default::default() };
    stage("idle served module");
    let one = tmclsim_server::start(module(&waiting)?, config(0)).map_err(|e| e.to_string())?;
    idle_row("served module, program looping on `WAIT TICKS, 0, 1000`", 1, seconds, &one)?;
    one.stop();
    stage("idle fleet of 1000 modules");
    let timer = asm(TIMER_INTERRUPT)?;
    let links = (0..1000)
        .map(|_| Ok(tmclsim_server::LinkSpec { modules: vec![(module(&timer)?, None)], config: config(0) }))
        .collect::<Result<Vec<_>, String>>()?;
    let fleet = tmclsim_server::start_fleet(links).map_err(|e| e.to_string())?;
    idle_row("fleet of 1000 modules on TCP, each running the manual's timer-interrupt example", 1000, seconds, &fleet)?;
    fleet.stop();
    Ok(())
}

/// CPU used by this process (the server's thread) while nobody talks to
/// it, with the clock's wake-ups.
fn idle_row(name: &str, modules: usize, seconds: f64, server: &tmclsim_server::ServerHandle) -> Result<(), String> {
    std::thread::sleep(Duration::from_millis(200));
    let (cpu0, wake0) = (self_cpu(), server.stats().wakeups);
    let t = Instant::now();
    std::thread::sleep(Duration::from_secs_f64(seconds));
    let wall = t.elapsed().as_secs_f64();
    let (cpu, wakeups) = (self_cpu() - cpu0, server.stats().wakeups - wake0);
    row!(
        "| {name}, {seconds:.0} s idle | {modules} modules | {:.3} % of one core, {:.0} clock wake-ups/s |",
        cpu.as_secs_f64() / wall * 100.0,
        wakeups as f64 / wall
    );
    Ok(())
}

/// The TMCM-1141 manual's timer-interrupt example (3.6.6.4), toggling OUT1
/// in the main loop (the module has no output 3).
const TIMER_INTERRUPT: &str = "  VECT 0, Timer0Irq\n  SGP 0, 3, 1000\n  EI 0\n  EI 255\nLoop:\n  SIO 1, 2, 1\n  WAIT TICKS, 0, 50\n  SIO 1, 2, 0\n  WAIT TICKS, 0, 50\n  JA Loop\nTimer0Irq:\n  GIO 0, 2\n  JC NZ, Out0Off\n  SIO 0, 2, 1\n  RETI\nOut0Off:\n  SIO 0, 2, 0\n  RETI\n";

const FIRST_STEPS: &str = "  ROL 0, 1000\n  WAIT TICKS, 0, 500\n  MST 0\n  ROR 0, 100\n  WAIT TICKS, 0, 500\n  MST 0\n  SAP 4, 0, 100\n  SAP 5, 0, 100\nLoop:\n  MVP ABS, 0, 512000\n  WAIT POS, 0, 0\n  MVP ABS, 0, -512000\n  WAIT POS, 0, 0\n  JA Loop\n";

/// The machine's floor: a blocking echo thread over loopback TCP in this
/// process, with the same frames.
fn echo_baseline(frames: &[[u8; 9]], n: usize) -> Result<(), String> {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    let addr = listener.local_addr().map_err(|e| e.to_string())?;
    let echo = std::thread::spawn(move || {
        let Ok((mut c, _)) = listener.accept() else { return };
        c.set_nodelay(true).ok();
        let mut b = [0u8; 9];
        while c.read_exact(&mut b).is_ok() {
            // Answer like a module would: status 100, same opcode.
            let reply = [2, 1, 100, b[1], b[4], b[5], b[6], b[7], 0];
            if c.write_all(&reply).is_err() {
                break;
            }
        }
    });
    let mut s = std::net::TcpStream::connect(addr).map_err(|e| e.to_string())?;
    s.set_nodelay(true).ok();
    report("baseline: blocking echo thread, loopback TCP", &mut s, frames, n, None)?;
    drop(s);
    let _ = echo.join();
    Ok(())
}

fn us(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}
