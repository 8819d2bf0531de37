//! `tmclsim run`: a TMCL program on a virtual module in virtual time, with
//! a trace, a plot, breakpoints and an interactive debugger.

use crate::asm::assemble;
use crate::debugger::{Debug, Debugger, inspect};
use crate::duration::parse_duration;
use std::fs::File;
use std::io::{BufRead, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;
use tmclsim_asm::Program;
use tmclsim_firmware::program::RunMode;
use tmclsim_firmware::{Bus, Module, Profile};
use tmclsim_protocol::mnemonic;

#[derive(clap::Args)]
pub struct RunArgs {
    /// TMCL source file.
    pub source: PathBuf,
    /// Module profile to run on.
    #[arg(long, default_value = "tmcm-1141")]
    pub module: String,
    /// Virtual time to run: 500ms, 10s, 5m, 1h (a plain number is seconds).
    #[arg(long = "for", value_name = "DURATION", default_value = "10s", value_parser = parse_duration)]
    pub duration: u64,
    /// Write every executed instruction to a CSV file (time, PC,
    /// instruction, accumulator, X, position and speed per axis).
    #[arg(long, value_name = "FILE.csv")]
    pub trace: Option<PathBuf>,
    /// Plot the motion into a PNG or SVG file (by its extension): per
    /// axis position and velocity, and load, current and outputs where
    /// they change.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Write the motion sampled at a fixed step (see --sample) to a CSV
    /// file: time, per axis position, target, speed, load, current, and
    /// the outputs.
    #[arg(long, value_name = "FILE.csv")]
    pub samples: Option<PathBuf>,
    /// The step of virtual time between two samples of the plot and the
    /// CSV (default: the run in 2000 steps, at least 1ms).
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    pub sample: Option<u64>,
    /// The plot starts at this virtual time (default: 0).
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    pub from: Option<u64>,
    /// The plot ends at this virtual time (default: the end of the run).
    #[arg(long, value_name = "DURATION", value_parser = parse_duration)]
    pub to: Option<u64>,
    /// Stop at a label, an address or FILE:LINE and enter the debugger
    /// (repeatable).
    #[arg(long = "break", value_name = "LABEL|ADDR|FILE:LINE")]
    pub breakpoints: Vec<String>,
    /// Start in the interactive debugger (step, continue, inspect).
    #[arg(long)]
    pub debug: bool,
    /// The world: a TOML file (docs/world.md), `stage` (default) or `free`.
    #[arg(long, value_name = "FILE", default_value = "stage")]
    pub world: String,
    /// Direct-mode commands to give the module before the program starts,
    /// one per line (`SAP 4, 0, 1000`, parameter names allowed, `//`
    /// comments), e.g. the parameter set a sweep wrote beside a failure
    /// (docs/behaviour.md rule 87).
    #[arg(long, value_name = "FILE")]
    pub setup: Option<std::path::PathBuf>,
}

/// Gives the module the commands of a setup file; a command the module
/// refuses is an error naming its line.
pub(crate) fn setup(module: &mut Module, path: &std::path::Path) -> Result<(), String> {
    use tmclsim_server::files::{MAX_CONFIG_BYTES, read_text_limited};
    let text = read_text_limited(path, MAX_CONFIG_BYTES, "a setup file")?;
    let profile = module.profile().clone();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split("//").next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = format!("{}:{}", path.display(), n + 1);
        let ins = tmclsim_host::line::parse(line, Some(&profile)).map_err(|e| format!("{at}:{}: {}", e.column, e.message))?;
        let frame = tmclsim_protocol::Request::new(module.address(), ins).encode();
        match module.handle_frame(&frame).and_then(|r| tmclsim_protocol::Reply::decode(&r)) {
            Some(r) if r.status >= 100 => {}
            Some(r) => {
                return Err(format!(
                    "{at}: '{line}' answered status {} ({})",
                    r.status,
                    tmclsim_protocol::Status::from_code(r.status).map_or("unknown", |s| s.describe())
                ));
            }
            None => return Err(format!("{at}: '{line}' got no reply")),
        }
    }
    Ok(())
}

pub fn run(args: RunArgs) -> Result<ExitCode, String> {
    let (program, profile) = assemble(&args.source, &args.module)?;
    let (mut module, breakpoints) = prepare(&args, &program, &profile)?;
    let mut trace = args.trace.as_deref().map(|path| open_trace(&mut module, path)).transpose()?;
    check_outputs(&args)?;
    let outputs = profile.ports.iter().filter(|p| p.direction == tmclsim_firmware::profile::PortDirection::Output).count() as u32;
    let mut samples =
        (args.plot.is_some() || args.samples.is_some()).then(|| crate::plot::Samples::new(profile.module.axes as usize, outputs));
    module.start_program();
    // The run drives a bus of one in stepped time, as every front end does.
    let mut bus = Bus::single(module);
    let started = Instant::now();
    drive(&mut bus, &args, &program, breakpoints.is_empty(), &mut trace, &mut samples)?;
    let module = bus.module_mut(0);
    if let Some(mut w) = trace {
        write_trace(&mut w, module)?;
        w.flush().map_err(|e| e.to_string())?;
    }
    let wall = started.elapsed();
    summary(module, &program, wall);
    write_outputs(&args, samples.as_ref())?;
    Ok(ExitCode::SUCCESS)
}

/// The module of the run: in its world, with the program loaded, the setup
/// given and the breakpoints set (which are returned as well).
fn prepare(args: &RunArgs, program: &Program, profile: &Arc<Profile>) -> Result<(Module, Vec<u16>), String> {
    let world = crate::load_world(&args.world, profile.module.axes as usize)?;
    let mut module = Module::with_world(profile.clone(), tmclsim_firmware::Eeprom::new(&profile.module.name), world);
    module.load_program(&program.instructions).map_err(|s| format!("the program does not fit the module: {s}"))?;
    if let Some(path) = &args.setup {
        setup(&mut module, path)?;
    }
    let mut breakpoints = Vec::new();
    for b in &args.breakpoints {
        breakpoints.push(crate::debugger::resolve(b, program).map_err(|e| format!("--break {e}"))?);
    }
    module.set_breakpoints(&breakpoints);
    Ok((module, breakpoints))
}

/// Turns the module's trace on and starts the trace CSV with its header.
fn open_trace(module: &mut Module, path: &Path) -> Result<BufWriter<File>, String> {
    module.set_trace(true);
    let f = File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut w = BufWriter::new(f);
    let mut header = "time_s,pc,instruction,accumulator,x,failed_status".to_string();
    for m in 0..module.profile().module.axes {
        header.push_str(&format!(",position_{m},speed_{m}"));
    }
    writeln!(w, "{header}").map_err(|e| e.to_string())?;
    Ok(w)
}

/// The plot's format and the sampling step, before the run.
fn check_outputs(args: &RunArgs) -> Result<(), String> {
    if let Some(path) = &args.plot
        && !path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("png") || e.eq_ignore_ascii_case("svg"))
    {
        return Err(format!("{}: the plot is written as .png or .svg", path.display()));
    }
    if args.sample == Some(0) {
        return Err("--sample: the step is more than 0".into());
    }
    Ok(())
}

/// Runs the bus to the end of the run in slices: a plot gets 2000 samples,
/// a trace is written as it comes, the debugger takes over at breakpoints
/// (or from the start with `--debug`).
fn drive(
    bus: &mut Bus,
    args: &RunArgs,
    program: &Program,
    no_breakpoints: bool,
    trace: &mut Option<BufWriter<File>>,
    samples: &mut Option<crate::plot::Samples>,
) -> Result<(), String> {
    let end = args.duration;
    let slice = match args.sample {
        Some(step) => step,
        None if no_breakpoints => (end / 2000).max(1_000_000),
        None => 1_000_000,
    };
    if let Some(s) = samples {
        s.take(bus.module(0));
    }
    let mut debugging = args.debug;
    let mut debugger = Debugger::default();
    let stdin = std::io::stdin();
    let mut lines = stdin.lock().lines();
    // A bar for long runs; none while a debugger may talk on the terminal.
    let mut progress =
        (no_breakpoints && !args.debug).then(|| crate::progress::Progress::new(end / 1_000_000, "{bar:40} {pos}/{len} ms of virtual time"));
    while bus.now_ns() < end {
        if let Some(p) = &mut progress {
            p.set(bus.now_ns() / 1_000_000);
        }
        // A breakpoint stops the program (step mode); after `continue` the
        // program runs on past the breakpoint it stood on.
        let at_breakpoint = bus.module(0).program().hit_breakpoint.is_some() && bus.module(0).program().mode != RunMode::Run;
        if debugging || at_breakpoint {
            let answer = debugger.session(bus, program, &mut lines, end)?;
            match answer {
                Debug::Continue => debugging = false,
                Debug::Quit => break,
            }
            continue;
        }
        let next = bus.now_ns().saturating_add(slice).min(end);
        bus.advance_to(next);
        if let Some(w) = trace {
            write_trace(w, bus.module_mut(0))?;
        }
        if let Some(s) = samples {
            s.take(bus.module(0));
        }
        let p = bus.module(0).program();
        if p.mode != RunMode::Run && p.hit_breakpoint.is_none() && trace.is_none() && samples.is_none() {
            // Stopped for good: the rest is motion only.
            bus.advance_to(end);
        }
    }
    if let Some(p) = progress {
        p.finish();
    }
    Ok(())
}

/// Writes the samples' CSV and the plot, where asked for.
fn write_outputs(args: &RunArgs, samples: Option<&crate::plot::Samples>) -> Result<(), String> {
    if let (Some(path), Some(s)) = (&args.samples, samples) {
        s.write_csv(path)?;
        println!("samples: {} ({} rows)", path.display(), s.len());
    }
    if let (Some(path), Some(s)) = (&args.plot, samples) {
        let seconds = |ns: u64| ns as f64 * 1e-9;
        s.write_plot(path, args.from.map(seconds), args.to.map(seconds))?;
        println!("plot: {}", path.display());
    }
    Ok(())
}

fn write_trace(w: &mut impl Write, module: &mut Module) -> Result<(), String> {
    for r in module.take_trace() {
        let mut line = format!(
            "{:.6},{},{},{},{},{}",
            r.time_ns as f64 * 1e-9,
            r.pc,
            mnemonic::format(r.instruction).replace(',', ""),
            r.registers.accumulator,
            r.registers.x,
            r.failed.map_or(String::new(), |s| s.to_string())
        );
        for (p, v) in &r.axes {
            line.push_str(&format!(",{p},{v}"));
        }
        writeln!(w, "{line}").map_err(|e| e.to_string())?;
    }
    Ok(())
}

fn summary(m: &Module, program: &tmclsim_asm::Program, wall: std::time::Duration) {
    let p = m.program();
    let t = m.now_ns() as f64 * 1e-9;
    println!(
        "ran {:.3} s of virtual time in {:.3} s ({:.0}× real time); {} instructions",
        t,
        wall.as_secs_f64(),
        t / wall.as_secs_f64().max(1e-9),
        p.executed
    );
    let at = crate::debugger::place(program, p.counter());
    println!("program: {:?} at {at}{}", p.mode, if p.wait.is_some() { ", waiting" } else { "" });
    inspect(m);
}
