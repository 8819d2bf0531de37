//! `tmclsim trace check`: a trace's requests replayed on a fresh virtual
//! module in virtual time, and every recorded reply compared with the
//! virtual module's (docs/host-software.md, "Validate tmclsim against your
//! module").
//!
//! Time: the virtual module starts when the recording started. A request
//! is carried out halfway between its recorded time and its reply's (the
//! module acted somewhere in between). A read whose answer may change
//! with time alone (`trace::windowed`) is answered at both ends of its
//! window instead (on a copy of the bus for the late end): from before its
//! request to after its reply, by `--time-tolerance` plus half the longest
//! round trip of a command before it (a motion may have started that much
//! earlier or later than at its command's midpoint). `trace::compare`
//! takes either end, or for a value that moves with the motor anything
//! between them. 138 events are compared in order, byte for byte, and in
//! time within twice that reach.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use tmclsim_firmware::profile::PortDirection;
use tmclsim_firmware::{Bus, Eeprom, Module, Profile};
use tmclsim_host::hex;
use tmclsim_host::names::{Table, table_of};
use tmclsim_host::trace::{self, Dir, Entry, Verdict, seconds};
use tmclsim_protocol::{FRAME_LEN, Instruction, Reply, Request, Status, mnemonic, opcode};

#[derive(clap::Args)]
pub struct CheckArgs {
    /// The trace: JSON Lines, one frame per line (docs/host-software.md).
    pub file: PathBuf,
    /// The profile of the module the trace was recorded with.
    #[arg(long, default_value = "tmcm-1141")]
    pub module: String,
    /// The virtual module's address (GP 66), for a trace whose module
    /// answers to another than the factory's.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=255))]
    pub address: Option<u8>,
    /// The world around the virtual module: `stage` (as `tmclsim serve`
    /// has it), `free` or a world file (docs/world.md).
    #[arg(long, value_name = "FILE", default_value = "stage")]
    pub world: String,
    /// Direct-mode commands for the virtual module before the replay, one
    /// per line as for `tmclsim run --setup` (e.g. what the recorded module
    /// keeps in its EEPROM).
    #[arg(long, value_name = "FILE")]
    pub setup: Option<PathBuf>,
    /// How far a read's time window reaches beyond its request and its
    /// reply, in milliseconds, on top of half the longest round trip of a
    /// command before it; 138 events may be off by twice as much (see
    /// docs/host-software.md).
    #[arg(long, value_name = "MS", default_value_t = 5, value_parser = clap::value_parser!(u64).range(0..=60_000))]
    pub time_tolerance: u64,
    /// Findings shown per group; the others are counted.
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub show: usize,
}

/// Steps of virtual time (from one deadline of the module to the next)
/// between two requests, beyond which the module is moved in one step.
const MAX_STEPS: usize = 10_000;

/// A request and the frames the recorded module sent until the next one.
struct Exchange<'a> {
    request: &'a Entry,
    reply: Option<&'a Entry>,
    /// Further frames that are not 138 events.
    extra: Vec<&'a Entry>,
}

/// The trace in exchanges, the module's frames before the first request,
/// and its 138 events.
fn split(entries: &[Entry]) -> (Vec<Exchange<'_>>, Vec<&Entry>, Vec<&Entry>) {
    let (mut exchanges, mut orphans, mut events) = (Vec::new(), Vec::new(), Vec::new());
    for e in entries {
        match e.dir {
            Dir::Host => exchanges.push(Exchange { request: e, reply: None, extra: Vec::new() }),
            Dir::Module if e.is_event() => events.push(e),
            Dir::Module => match exchanges.last_mut() {
                Some(x) if x.reply.is_none() => x.reply = Some(e),
                Some(x) => x.extra.push(e),
                None => orphans.push(e),
            },
        }
    }
    (exchanges, orphans, events)
}

/// One difference, or one reply that is not comparable.
struct Finding {
    /// The line to look at (the reply's, else the request's); none for a
    /// frame only the virtual module sent.
    line: Option<usize>,
    /// The request's line, when `line` is its reply's.
    request_line: Option<usize>,
    t_ns: u64,
    request: Option<[u8; FRAME_LEN]>,
    expected: Option<[u8; FRAME_LEN]>,
    actual: Option<[u8; FRAME_LEN]>,
    note: String,
}

impl Finding {
    /// A module frame that answers no request.
    fn unrequested(
        line: Option<usize>,
        t_ns: u64,
        expected: Option<[u8; FRAME_LEN]>,
        actual: Option<[u8; FRAME_LEN]>,
        note: String,
    ) -> Finding {
        Finding { line, request_line: None, t_ns, request: None, expected, actual, note }
    }
}

struct Group {
    label: String,
    reason: Option<&'static str>,
    findings: Vec<Finding>,
}

#[derive(Default)]
struct Report {
    differences: Vec<Group>,
    not_comparable: Vec<Group>,
    index: HashMap<(bool, String), usize>,
    matched: usize,
}

impl Report {
    fn add(&mut self, comparable: bool, label: String, reason: Option<&'static str>, finding: Finding) {
        let groups = if comparable { &mut self.differences } else { &mut self.not_comparable };
        let i = *self.index.entry((comparable, label.clone())).or_insert_with(|| {
            groups.push(Group { label, reason, findings: Vec::new() });
            groups.len() - 1
        });
        groups[i].findings.push(finding);
    }

    fn count(groups: &[Group]) -> usize {
        groups.iter().map(|g| g.findings.len()).sum()
    }
}

/// The virtual module on its bus, and the 138 events it sent with their
/// virtual times.
struct Replay {
    bus: Bus,
    events: Vec<(u64, [u8; FRAME_LEN])>,
}

impl Replay {
    fn collect(&mut self) {
        let now = self.bus.now_ns();
        self.events.extend(self.bus.take_effects().events.into_iter().map(|(_, e)| (now, e)));
    }

    /// Moves the bus to `t`, from deadline to deadline so that events get
    /// their own times.
    fn advance_to(&mut self, t: u64) {
        for _ in 0..MAX_STEPS {
            match self.bus.next_deadline() {
                Some(d) if d > self.bus.now_ns() && d <= t => {
                    self.bus.advance_to(d);
                    self.collect();
                }
                _ => break,
            }
        }
        self.bus.advance_to(t);
        self.collect();
    }
}

/// The instruction of a request frame, whatever its checksum.
fn instruction(frame: &[u8; FRAME_LEN]) -> Instruction {
    Request::decode(frame).unwrap_or_else(|r| r).instruction
}

/// What a group is about: `GAP 1 (Actual position), motor 0`.
fn label(profile: &Profile, ins: Instruction) -> String {
    let op = opcode::name(ins.opcode);
    let named = |p: Option<&tmclsim_firmware::profile::Parameter>| p.map_or(String::new(), |p| format!(" ({})", p.name));
    match table_of(ins.opcode) {
        Some(Table::Axis) => format!("{op} {}{}, motor {}", ins.kind, named(profile.axis_parameter(ins.kind)), ins.motor),
        Some(Table::Global) => format!("{op} {}{}, bank {}", ins.kind, named(profile.global_parameter(ins.motor, ins.kind)), ins.motor),
        None if matches!(ins.opcode, opcode::GIO | opcode::SIO) => {
            let port = profile
                .ports
                .iter()
                .filter(|p| p.bank == ins.motor && p.number == ins.kind)
                .min_by_key(|p| p.direction == PortDirection::Pullup);
            format!("{op} {}, bank {}{}", ins.kind, ins.motor, port.map_or(String::new(), |p| format!(" ({})", p.name)))
        }
        None if opcode::mnemonic(ins.opcode).is_some() => format!("{op} type {}, motor {}", ins.kind, ins.motor),
        None => format!("{op} ({}), type {}", ins.opcode, ins.kind),
    }
}

/// A reply in words.
fn describe(ins: Option<Instruction>, frame: &[u8; FRAME_LEN]) -> String {
    if ins.is_some_and(|i| i.opcode == opcode::FIRMWARE_VERSION && i.kind == 0) {
        return format!("version string '{}'", String::from_utf8_lossy(&frame[1..]).trim_end_matches('\0'));
    }
    match Reply::decode(frame) {
        Some(r) => {
            let status = Status::from_code(r.status).map_or_else(|| format!("{} (unknown)", r.status), |s| s.to_string());
            format!("status {status}, value {}", r.value)
        }
        None => "wrong checksum".into(),
    }
}

pub fn run(args: CheckArgs) -> Result<ExitCode, String> {
    let name = args.file.display().to_string();
    let file = std::fs::File::open(&args.file).map_err(|e| format!("{name}: {e}"))?;
    let entries = trace::read(file, &name)?;
    let Some(last) = entries.last() else {
        return Err(format!("{name}: holds no frames"));
    };
    let profile = Profile::built_in(&args.module)?;
    let world = crate::load_world(&args.world, profile.module.axes as usize)?;
    let mut module = Module::with_world(profile.clone(), Eeprom::new(&profile.module.name), world);
    if let Some(a) = args.address {
        module.set_address(a);
    }
    if let Some(path) = &args.setup {
        crate::run::setup(&mut module, path)?;
    }
    let address = module.address();
    let (exchanges, orphans, events) = split(&entries);
    let mut replay = Replay { bus: Bus::single(module), events: Vec::new() };
    let report = replay.run(&exchanges, &orphans, &events, args.time_tolerance * 1_000_000, last.t_ns, &profile);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{name}: {} request(s) and {} event(s) replayed on a virtual {} (address {address}, world {}) over {} s of recorded time",
        exchanges.len(),
        events.len(),
        profile.module.name,
        args.world,
        seconds(last.t_ns)
    );
    write_groups(&mut out, &report.differences, "difference", args.show);
    if !report.not_comparable.is_empty() {
        out.push_str("not comparable (listed, not counted as differences: these values depend on what the virtual module cannot know)\n");
        write_groups(&mut out, &report.not_comparable, "reply", args.show);
    }
    let differences = Report::count(&report.differences);
    if differences > 0
        && args.address.is_none()
        && let Some(first) = exchanges.first().map(|x| x.request.frame[0]).filter(|a| *a != 0 && *a != address)
    {
        let _ = writeln!(
            out,
            "note: the trace's first request goes to address {first}; the virtual module answers to {address}: give --address {first}"
        );
    }
    let _ = writeln!(
        out,
        "result: {differences} difference{}, {} not comparable, {} match",
        if differences == 1 { "" } else { "s" },
        Report::count(&report.not_comparable),
        report.matched
    );
    print!("{out}");
    Ok(if differences == 0 { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

impl Replay {
    /// Replays the exchanges and compares every reply and event;
    /// `tolerance` in nanoseconds, `last_t` the time of the trace's last
    /// frame.
    fn run(
        &mut self,
        exchanges: &[Exchange],
        orphans: &[&Entry],
        events: &[&Entry],
        tolerance: u64,
        last_t: u64,
        profile: &Profile,
    ) -> Report {
        let mut report = Report::default();
        let unrequested = "module frames without a request".to_string();
        for x in orphans {
            let note = "the recorded module sent it before any request".to_string();
            report.add(true, unrequested.clone(), None, Finding::unrequested(Some(x.line), x.t_ns, Some(x.frame), None, note));
        }
        // Half the longest time between a request and its reply so far,
        // of the commands that were not windowed reads: how far from its
        // midpoint the module may have carried out a command that started
        // a motion.
        let mut half_trip = 0u64;
        for x in exchanges {
            let frame = x.request.frame;
            let ins = instruction(&frame);
            let (a, b) = (x.request.t_ns, x.reply.map_or(x.request.t_ns, |r| r.t_ns));
            let (early, late, extra) = if trace::windowed(ins) {
                let reach = tolerance + half_trip;
                self.advance_to(a.saturating_sub(reach).max(self.bus.now_ns()));
                let mut copy = self.bus.clone();
                copy.advance_to(b + reach);
                let late = copy.handle_frame(&frame).replies.first().copied();
                let answer = self.bus.handle_frame(&frame);
                (answer.replies.first().copied(), late, answer.replies.get(1..).unwrap_or_default().to_vec())
            } else {
                half_trip = half_trip.max((b - a) / 2);
                self.advance_to(a + (b - a) / 2);
                let answer = self.bus.handle_frame(&frame);
                let first = answer.replies.first().copied();
                (first, first, answer.replies.get(1..).unwrap_or_default().to_vec())
            };
            self.collect();
            let finding = |note: String| Finding {
                line: Some(x.reply.map_or(x.request.line, |r| r.line)),
                request_line: x.reply.map(|_| x.request.line),
                t_ns: a,
                request: Some(frame),
                expected: x.reply.map(|r| r.frame),
                actual: early,
                note,
            };
            match trace::compare(ins, x.reply.map(|r| &r.frame), early.as_ref(), late.as_ref()) {
                Verdict::Match => report.matched += 1,
                Verdict::Differs(note) => report.add(true, label(profile, ins), None, finding(note)),
                Verdict::NotComparable(why) => report.add(false, label(profile, ins), Some(why), finding(String::new())),
            }
            for e in &x.extra {
                let note = format!("the recorded module sent it after its reply to line {}", x.request.line);
                report.add(true, unrequested.clone(), None, Finding::unrequested(Some(e.line), e.t_ns, Some(e.frame), None, note));
            }
            for r in extra {
                let note = format!("the virtual module sent it after its reply to line {}", x.request.line);
                report.add(
                    true,
                    unrequested.clone(),
                    None,
                    Finding { request: Some(frame), ..Finding::unrequested(None, a, None, Some(r), note) },
                );
            }
        }
        let event_tolerance = 2 * (tolerance + half_trip);
        let end = last_t + event_tolerance;
        self.advance_to(end);
        compare_events(events, &self.events, end, event_tolerance, &mut report);
        report
    }
}

/// The recorded 138 events against the virtual module's (those up to
/// `end`), in order.
fn compare_events(recorded: &[&Entry], virtual_events: &[(u64, [u8; FRAME_LEN])], end: u64, tolerance: u64, report: &mut Report) {
    let virtual_events: Vec<_> = virtual_events.iter().filter(|(t, _)| *t <= end).collect();
    let label = || "138 events (target position reached)".to_string();
    for i in 0..recorded.len().max(virtual_events.len()) {
        match (recorded.get(i), virtual_events.get(i)) {
            (Some(r), Some((t, v))) => {
                let off = t.abs_diff(r.t_ns);
                if r.frame == *v && off <= tolerance {
                    report.matched += 1;
                    continue;
                }
                let note = if off > tolerance {
                    format!(
                        "the virtual event came at {} s, {} ms {}",
                        seconds(*t),
                        off / 1_000_000,
                        if *t > r.t_ns { "later" } else { "earlier" }
                    )
                } else {
                    String::new()
                };
                let f = Finding::unrequested(Some(r.line), r.t_ns, Some(r.frame), Some(*v), note);
                report.add(true, label(), None, f);
            }
            (Some(r), None) => {
                let note = "the virtual module sent no such event".to_string();
                let f = Finding::unrequested(Some(r.line), r.t_ns, Some(r.frame), None, note);
                report.add(true, label(), None, f);
            }
            (None, Some((t, v))) => {
                let note = "the virtual module sent this event; the recorded module did not".to_string();
                let f = Finding::unrequested(None, *t, None, Some(*v), note);
                report.add(true, label(), None, f);
            }
            (None, None) => {}
        }
    }
}

fn write_groups(out: &mut String, groups: &[Group], noun: &str, show: usize) {
    for g in groups {
        let n = g.findings.len();
        let reason = g.reason.map_or(String::new(), |r| format!("; {r}"));
        let _ = writeln!(out, "{}: {n} {noun}{}{reason}", g.label, if n == 1 { "" } else { "s" });
        for f in g.findings.iter().take(show) {
            let ins = f.request.map(|r| instruction(&r));
            let at = f.line.map_or("the virtual module".to_string(), |l| format!("line {l}"));
            let what = match f.request.map(|r| Request::decode(&r)) {
                Some(Ok(r)) => format!(": {}", mnemonic::format(r.instruction)),
                Some(Err(r)) => format!(": {} (wrong checksum)", mnemonic::format(r.instruction)),
                None => String::new(),
            };
            let when = match f.request_line {
                Some(r) => format!("request on line {r} at {} s", seconds(f.t_ns)),
                None => format!("{} s", seconds(f.t_ns)),
            };
            let _ = writeln!(out, "  {at} ({when}){what}");
            if let Some(r) = &f.request {
                let _ = writeln!(out, "    request   {}", hex(r));
            }
            for (side, frame) in [("expected", &f.expected), ("actual  ", &f.actual)] {
                let _ = match frame {
                    Some(fr) => writeln!(out, "    {side}  {}  {}", hex(fr), describe(ins, fr)),
                    None if f.request.is_some() => writeln!(out, "    {side}  no reply"),
                    None => writeln!(out, "    {side}  no frame"),
                };
            }
            if !f.note.is_empty() {
                let _ = writeln!(out, "    {}", f.note);
            }
        }
        if n > show {
            let _ = writeln!(out, "  … and {} more", n - show);
        }
    }
}
