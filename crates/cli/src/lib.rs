//! `tmclsim`: serve virtual TMCL modules, talk to real or virtual ones.
//! The command as a library ([`run`]), so that the binary and the Python
//! package's `tmclsim` command are one program.

// The library is the command itself (the binary's and the Python
// package's): its interface is the command line, documented by --help and
// the manual page.
#![allow(missing_docs)]

use clap::{Args, CommandFactory, Parser, Subcommand};
use std::net::SocketAddr;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

mod asm;
mod bench;
mod client;
mod clock;
mod console;
mod debugger;
mod duration;
mod firmware;
mod fleet;
mod ide;
mod platform;
mod plot;
mod progress;
mod run;
mod send;
mod serve;
mod signal;
mod sweep;
mod trace;
mod upload;

/// The version `--version` prints: the package's and the git revision the
/// binary was built from (crates/cli/build.rs).
const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (git ", env!("TMCLSIM_GIT"), ")");

/// Exit statuses, the same for every command (README.md, "Exit status").
const EXIT_STATUSES: [(&str, &str); 4] = [
    ("0", "the command did its work and every check passed; a server (serve, ide, trace record) stopped by SIGINT, SIGTERM or SIGHUP"),
    (
        "1",
        "a check failed: a command the module refused or did not answer (send, upload, console scripts), \
         a world command refused, differences in a recorded session (trace check), failed scenarios (sweep)",
    ),
    (
        "2",
        "the command could not do its work: a usage error, an input file that cannot be read or is invalid \
         (program, world, fleet, trace, EEPROM, setup), a link that cannot be opened or fails",
    ),
    ("101", "an internal error (a panic): a bug in tmclsim"),
];

#[derive(Parser)]
#[command(name = "tmclsim", version = VERSION, about = "Virtual Trinamic TMCL modules and the open TMCL toolchain")]
#[command(after_long_help = exit_status_help())]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Serve a virtual module on TCP and/or a pty until interrupted.
    Serve(ServeArgs),
    /// Send one command to a TMCL module (real or virtual) and print the reply.
    Send(SendArgs),
    /// An interactive direct-mode console to any TMCL module: names, history, completion; scripts from stdin.
    Console(console::ConsoleArgs),
    /// List a module profile: its features, then every parameter with access, range and default.
    Profile(ProfileArgs),
    /// Measure commands per second in-process and round trips over TCP and the pty.
    Bench(BenchArgs),
    /// Assemble TMCL source into a binary and a symbol file.
    Asm(asm::AsmArgs),
    /// Disassemble a binary back into TMCL source.
    Disasm(asm::DisasmArgs),
    /// Run a TMCL program on a virtual module in virtual time.
    Run(run::RunArgs),
    /// Download a program to a module (real or virtual), verify it, start it.
    Upload(upload::UploadArgs),
    /// Change the world of a served module: inputs, switches, loads, faults.
    World(WorldArgs),
    /// Serve a fleet from a second process, drive every module, report.
    FleetBench(fleet::FleetBenchArgs),
    /// The browser IDE against modules on a TMCL link (real or virtual), polled as a host does.
    Ide(ide::IdeArgs),
    /// Run a Python program with its clocks N times as fast as the wall clock, for modules served with --speed N.
    Clock(clock::ClockArgs),
    /// Run a TMCL program against every scenario of a matrix file, here or on a Dask cluster (docs/sweeps.md).
    Sweep(sweep::SweepArgs),
    /// Record a host's session with a module through a proxy; check a recorded session against a virtual module.
    Trace(trace::TraceArgs),
    /// Firmware images for a module's bootloader, to test firmware update tools.
    Firmware(firmware::FirmwareArgs),
    /// Print a shell's completion script for tmclsim on standard output.
    Completions(CompletionsArgs),
    /// Print the manual page of tmclsim (or of one of its commands) as roff on standard output.
    Man(ManArgs),
}

#[derive(Args)]
struct CompletionsArgs {
    /// The shell, e.g. `tmclsim completions bash > ~/.local/share/bash-completion/completions/tmclsim`.
    shell: clap_complete::Shell,
}

#[derive(Args)]
struct ManArgs {
    /// A command whose own page to print, e.g. `serve` or `trace check`;
    /// without it, the page of tmclsim, e.g. `tmclsim man | man -l -`.
    #[arg(value_name = "COMMAND")]
    command: Vec<String>,
}

#[derive(Args)]
pub struct BenchArgs {
    /// Commands for the in-process measurement.
    #[arg(long, default_value_t = 20_000_000)]
    pub in_process: usize,
    /// Round trips per link.
    #[arg(long, default_value_t = 20_000)]
    pub round_trips: usize,
    /// Seconds each idle served-program measurement lasts.
    #[arg(long, default_value_t = 10.0)]
    pub idle_seconds: f64,
}

#[derive(Args)]
pub struct ServeArgs {
    /// Module profile to serve.
    #[arg(long, default_value = "tmcm-1141")]
    pub module: String,
    /// Listen for TCP clients on this address (loopback by default). Without
    /// --tcp, --pty and --serial both are served, TCP on 127.0.0.1:1141 (on Windows,
    /// which has no ptys, TCP only).
    #[arg(long, value_name = "ADDR", value_parser = socket_address)]
    pub tcp: Option<SocketAddr>,
    /// Create a pty and a symlink to it at PATH, opened like a serial port.
    /// Without --tcp, --pty and --serial both are served, the pty at
    /// $TMPDIR/tmclsim-<module>. Unix only (on Windows: --serial COMn).
    #[arg(long, value_name = "PATH")]
    pub pty: Option<PathBuf>,
    /// Answer on an existing serial device (a USB–RS485 adapter, a COM
    /// port, one end of a virtual null-modem pair) as the module's own
    /// UART/RS485 port; repeatable. A device that vanishes is opened again
    /// when it is back. With --serial, only the links named are served.
    #[arg(long, value_name = "DEVICE")]
    pub serial: Vec<String>,
    /// The serial devices' baud rate (default: the module's GP 65 at power-up).
    #[arg(long, value_name = "N", requires = "serial", value_parser = baud)]
    pub baud: Option<u32>,
    /// Keep the EEPROM in FILE across runs (created if missing; written
    /// atomically). Without it the module starts from factory defaults.
    #[arg(long, value_name = "FILE")]
    pub eeprom: Option<PathBuf>,
    /// Module address (GP 66) to start with.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=255))]
    pub address: Option<u8>,
    /// Drop a partial frame after this many milliseconds without a byte.
    #[arg(long, value_name = "MS", default_value_t = 5)]
    pub inter_byte_timeout: u64,
    /// Most TCP clients served at once.
    #[arg(long, value_name = "N", default_value_t = 64)]
    pub max_connections: usize,
    /// Close a TCP connection after this many frames in a row with a wrong
    /// checksum (0: never), docs/behaviour.md rule 90.
    #[arg(long, value_name = "N", default_value_t = tmclsim_server::BAD_FRAME_LIMIT)]
    pub bad_frame_limit: u32,
    /// The world around the module: a TOML file (docs/world.md), or
    /// `stage` (the built-in linear stage, the default) or `free` (no
    /// switches, no end stops).
    #[arg(long, value_name = "FILE", default_value = "stage")]
    pub world: String,
    /// Several modules on one RS485-style link: `PROFILE@ADDRESS,…`, e.g.
    /// `tmcm-1141@1,tmcm-1141@2,tmcm-351@3`. Only the addressed module
    /// answers. Replaces --module and --address.
    #[arg(long, value_name = "SPEC", conflicts_with_all = ["address", "eeprom"])]
    pub bus: Option<String>,
    /// Also offer the modules on a CAN bus behind a virtual serial-line CAN
    /// adapter (SLCAN) on a pty with a symlink at PATH (python-can's
    /// `slcan`, PyTrinamic's `slcan_tmcl`).
    #[arg(long, value_name = "PATH")]
    pub slcan: Option<PathBuf>,
    /// Serve TMCM-1310 modules as EtherCAT slaves on this network
    /// interface (raw Ethernet, EtherType 0x88A4; needs root). With
    /// --slaves N, N slaves form one segment.
    #[arg(long, value_name = "IFACE")]
    pub ethercat: Option<String>,
    /// Number of slaves in the EtherCAT segment.
    #[arg(long, value_name = "N", default_value_t = 1, requires = "ethercat")]
    pub slaves: usize,
    /// Serve a fleet: many modules on many links, from a fleet file (TOML).
    #[arg(long, value_name = "FILE")]
    pub fleet: Option<PathBuf>,
    /// Deliver bytes at each module's baud rate (GP 65), so that host
    /// timeouts behave as on a real RS485 bus.
    #[arg(long)]
    pub wire_timing: bool,
    /// Run the modules' virtual time N times as fast as the wall clock
    /// (0.001…100000; 0.5 is half as fast): ramps, WAIT, timers,
    /// events, reply delays and wire timing all follow it. Host code waits
    /// on its own clock: `tmclsim clock --speed N -- python SCRIPT` puts a
    /// Python program on the same scale (docs/host-software.md).
    #[arg(long, value_name = "N", default_value = "1", value_parser = speed)]
    pub speed: tmclsim_firmware::Speed,
    /// Address of the control socket that changes the world while the
    /// module is served (`tmclsim world`); loopback, any free port by default.
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1:0", value_parser = socket_address)]
    pub control: SocketAddr,
    /// Also write the endpoints (tcp, pty, control, …) to FILE as TOML,
    /// for scripts; removed when the server stops.
    #[arg(long, value_name = "FILE")]
    pub endpoints: Option<PathBuf>,
    /// Print every frame in and out on stderr, decoded (command or status
    /// and value), with the time since start and the link it came on
    /// (the browser IDE's commands: `web`; its polled reads are not logged).
    #[arg(long, short = 'v')]
    pub log_frames: bool,
    /// Allow --control on an address other machines reach; clients must
    /// then send `auth TOKEN` first (the token is printed at start).
    #[arg(long)]
    pub control_public: bool,
    /// Also serve the browser IDE, on ADDR (default 127.0.0.1:8141).
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = tmclsim_web::DEFAULT_ADDR, value_parser = socket_address)]
    pub web: Option<SocketAddr>,
    /// Allow --web on a non-loopback address; every request then needs the token printed at start.
    #[arg(long, requires = "web")]
    pub web_public: bool,
}

#[derive(Args)]
#[command(after_long_help = world_commands())]
pub struct WorldArgs {
    /// The control socket printed by `tmclsim serve`.
    #[arg(long, value_name = "ADDR")]
    pub control: String,
    /// A control command, e.g. `input 0 1`, `load 0 50`, `switch 0 left press`,
    /// `link drop 3`, `show` (`help` lists them all).
    #[arg(required = true, num_args = 1.., value_name = "COMMAND")]
    pub command: Vec<String>,
}

#[derive(Args)]
pub struct SendArgs {
    #[command(flatten)]
    pub link: client::LinkArgs,
    /// How long to wait for the reply, in milliseconds.
    #[arg(long, value_name = "MS", default_value_t = 1000)]
    pub timeout: u64,
    /// The module's profile, for parameter names (default: the one of the
    /// type the module reports with 136, asked only for a name).
    #[arg(long)]
    pub module: Option<String>,
    /// The command: a mnemonic (`GAP 1, 0`, `GAP actual_position, 0`,
    /// `MVP ABS, 0, 51200`) or a raw instruction `#OPCODE TYPE MOTOR VALUE`
    /// (e.g. `#136 0 0 0`).
    #[arg(required = true, num_args = 1.., value_name = "COMMAND")]
    pub command: Vec<String>,
}

#[derive(Args)]
struct ProfileArgs {
    /// Module profile name (tmcm-1141).
    #[arg(default_value = "tmcm-1141")]
    module: String,
}

/// Runs the `tmclsim` command with `args` (the program name first, as
/// `std::env::args_os` gives them) and returns its exit status (README,
/// "Exit status"). The `tmclsim` binary and the Python package's
/// `tmclsim` command both are this function. Usage errors, `--help` and
/// `--version` end the process as a command line tool does.
pub fn run<I, T>(args: I) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let code = run_to_exit_code(args);
    // `ExitCode` keeps its number to itself: find it by comparison.
    (0..=u8::MAX).find(|&n| ExitCode::from(n) == code).unwrap_or(1)
}

fn run_to_exit_code<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    // A panic on any thread ends the process with status 101 after the
    // usual message: a server whose link or clock task died would go on
    // listening and serve nothing.
    let report = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        report(info);
        std::process::exit(101);
    }));
    let cli = Cli::parse_from(args);
    let server = matches!(cli.command, Command::Serve(_) | Command::Bench(_) | Command::FleetBench(_) | Command::Ide(_))
        || matches!(&cli.command, Command::Trace(t) if matches!(t.command, trace::TraceCommand::Record(_)));
    if !server {
        // A command whose output goes to a reader that stops early
        // (`tmclsim profile | head`) ends quietly, as other tools do.
        // Servers keep ignoring the signal: their links report a closed
        // peer as an error of that link only.
        platform::default_sigpipe();
    }
    let result = match cli.command {
        Command::Serve(a) => serve::run(a),
        Command::Send(a) => send::run(a),
        Command::Console(a) => console::run(a),
        Command::Ide(a) => ide::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Clock(a) => clock::run(a),
        Command::Profile(a) => profile(&a.module),
        Command::Bench(a) => bench::run(a),
        Command::Asm(a) => asm::asm(a),
        Command::Disasm(a) => asm::disasm(a),
        Command::Run(a) => run::run(a),
        Command::Upload(a) => upload::run(a),
        Command::World(a) => world(a),
        Command::FleetBench(a) => fleet::bench(a),
        Command::Trace(a) => trace::run(a),
        Command::Firmware(a) => firmware::run(a),
        Command::Completions(a) => completions(a.shell),
        Command::Man(a) => man(&a.command),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("tmclsim: {e}");
            ExitCode::from(2)
        }
    }
}

fn profile(name: &str) -> Result<ExitCode, String> {
    let p = tmclsim_firmware::Profile::built_in(name)?;
    println!(
        "{}: {} axis(es), {} program words, firmware V{}.{:02}",
        p.module.name, p.module.axes, p.module.program_memory, p.module.firmware[0], p.module.firmware[1]
    );
    println!("\nFeatures");
    for (key, value) in p.features.list() {
        println!("  {key:<28} {value}");
    }
    // The default's source: manual (this module's manual), sibling
    // (another module or public Trinamic code, the note names it), assumed.
    let row = |q: &tmclsim_firmware::profile::Parameter| {
        println!(
            "  {:>3}  {:<4} {:>11}…{:<11} {:>11} {:<7}  {}",
            q.number,
            q.access.to_string(),
            q.min,
            q.max,
            q.default,
            q.default_source.as_str(),
            q.name
        );
    };
    println!("\nAxis parameters (default from: manual = this module's manual, sibling = another module or Trinamic code, assumed)");
    p.axis_parameters().for_each(row);
    for bank in 0..4u8 {
        let rows: Vec<_> = p.global_parameters(bank).collect();
        if rows.is_empty() {
            continue;
        }
        println!("\nGlobal parameters, bank {bank}");
        rows.into_iter().for_each(row);
    }
    Ok(ExitCode::SUCCESS)
}

/// The exit statuses as `tmclsim --help` lists them.
fn exit_status_help() -> String {
    let mut text = String::from("Exit status:\n");
    for (code, meaning) in EXIT_STATUSES {
        text += &format!("  {code:<5}{meaning}\n");
    }
    text
}

fn completions(shell: clap_complete::Shell) -> Result<ExitCode, String> {
    clap_complete::generate(shell, &mut Cli::command(), "tmclsim", &mut std::io::stdout());
    Ok(ExitCode::SUCCESS)
}

/// The manual page, made from the same definitions as `--help`.
fn man(path: &[String]) -> Result<ExitCode, String> {
    use std::io::Write;
    let mut cli = Cli::command();
    // Built, the commands know their full names (`tmclsim-trace-check`).
    cli.build();
    let mut page = &cli;
    for (n, name) in path.iter().enumerate() {
        page = page.find_subcommand(name).ok_or_else(|| {
            let names: Vec<&str> = page.get_subcommands().map(clap::Command::get_name).filter(|n| *n != "help").collect();
            let parent = ["tmclsim".to_string()].into_iter().chain(path[..n].iter().cloned()).collect::<Vec<_>>().join(" ");
            if names.is_empty() {
                format!("'{parent}' has no commands")
            } else {
                format!("'{parent}' has no command '{name}'; its commands are {}", names.join(", "))
            }
        })?;
    }
    let title = page.get_display_name().unwrap_or(page.get_name()).to_uppercase();
    // The --help text after the options is the exit statuses, which the
    // page has as a section of its own, before VERSION.
    let page = page.clone().after_long_help(None::<&str>);
    let mut out = Vec::new();
    clap_mangen::Man::new(page).title(title).source(format!("tmclsim {VERSION}")).render(&mut out).map_err(|e| e.to_string())?;
    let mut exit = roff::Roff::new();
    exit.control("SH", ["EXIT STATUS"]);
    for (code, meaning) in EXIT_STATUSES {
        exit.control("TP", []).text([roff::bold(code)]).text([roff::roman(format!("{}.", capitalised(meaning)))]);
    }
    let mut out = String::from_utf8(out).map_err(|e| e.to_string())?;
    let at = out.find("\n.SH VERSION").map_or(out.len(), |i| i + 1);
    out.insert_str(at, &exit.to_roff());
    std::io::stdout().write_all(out.as_bytes()).map_err(|e| format!("standard output: {e}"))?;
    Ok(ExitCode::SUCCESS)
}

fn capitalised(text: &str) -> String {
    let mut chars = text.chars();
    chars.next().map(|c| c.to_uppercase().chain(chars).collect()).unwrap_or_default()
}

/// The world named on the command line: `stage`, `free` or a file.
pub(crate) fn load_world(name: &str, axes: usize) -> Result<tmclsim_firmware::World, String> {
    tmclsim_server::files::world_named(name, axes).map_err(|e| format!("--world {e}"))
}

/// `HOST:PORT` with a host name or an IP address (IPv4 first when a name
/// has both).
/// A `--speed` value: a number from 0.001 to 100000.
pub(crate) fn speed(text: &str) -> Result<tmclsim_firmware::Speed, String> {
    text.parse()
}

/// A serial line's baud rate: what adapters take, 50 baud to 12 Mbaud.
pub(crate) fn check_baud(rate: u32) -> Result<u32, String> {
    if (50..=12_000_000).contains(&rate) {
        Ok(rate)
    } else {
        Err(format!("{rate} baud: a serial line runs at 50…12000000 baud (the modules' rates are 9600…1000000)"))
    }
}

fn baud(text: &str) -> Result<u32, String> {
    check_baud(text.parse().map_err(|_| format!("'{text}' is not a baud rate (a whole number, e.g. 9600 or 115200)"))?)
}

pub(crate) fn socket_address(text: &str) -> Result<SocketAddr, String> {
    use std::net::ToSocketAddrs;
    if let Ok(a) = text.parse() {
        return Ok(a);
    }
    let all: Vec<SocketAddr> =
        text.to_socket_addrs().map_err(|e| format!("'{text}' is not HOST:PORT ({e}); e.g. 127.0.0.1:1141 or localhost:1141"))?.collect();
    all.iter().find(|a| a.is_ipv4()).or(all.first()).copied().ok_or_else(|| format!("'{text}' names no address"))
}

/// `tmclsim world --help`: the control commands, one per line.
fn world_commands() -> String {
    let items: Vec<&str> = tmclsim_firmware::world_command::help_items().collect();
    format!("Commands (any may start with @ADDRESS: the module at that address on a bus; docs/world.md):\n  {}", items.join("\n  "))
}

fn world(args: WorldArgs) -> Result<ExitCode, String> {
    use std::io::{BufRead, Write};
    let mut s = std::net::TcpStream::connect(&args.control).map_err(|e| format!("cannot connect to {}: {e}", args.control))?;
    s.set_read_timeout(Some(Duration::from_secs(5))).ok();
    writeln!(s, "{}", args.command.join(" ")).map_err(|e| e.to_string())?;
    let mut line = Vec::new();
    let not_control = || {
        format!("{} did not answer as a control socket (a TMCL port?): give the address `tmclsim serve` prints as 'control:'", args.control)
    };
    match std::io::BufReader::new(s).read_until(b'\n', &mut line) {
        Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => return Err(not_control()),
        Err(e) => return Err(format!("{}: {e}", args.control)),
        Ok(_) => {}
    }
    let Ok(line) = String::from_utf8(line) else { return Err(not_control()) };
    // The list of commands comes as one line (the socket speaks in
    // lines); it is printed a command per line.
    if line.trim_end().strip_prefix("ok ") == Some(tmclsim_firmware::world_command::HELP) {
        println!("ok\n{}", world_commands());
    } else {
        print!("{line}");
    }
    Ok(if line.starts_with("ok") { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

pub(crate) fn millis(ms: u64) -> Duration {
    Duration::from_millis(ms)
}
