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
    /// The profile of the module the trace was recorded with, or `auto`:
    /// the profile whose module the trace's own 136 reply names.
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
    /// Not comparable readings whose value was the same on both modules:
    /// counted, not listed.
    identical: usize,
}

#[derive(Default)]
struct Report {
    differences: Vec<Group>,
    not_comparable: Vec<Group>,
    index: HashMap<(bool, String), usize>,
    matched: usize,
}

impl Report {
    fn group(&mut self, comparable: bool, label: String, reason: Option<&'static str>) -> &mut Group {
        let groups = if comparable { &mut self.differences } else { &mut self.not_comparable };
        let i = *self.index.entry((comparable, label.clone())).or_insert_with(|| {
            groups.push(Group { label, reason, findings: Vec::new(), identical: 0 });
            groups.len() - 1
        });
        &mut groups[i]
    }

    fn add(&mut self, comparable: bool, label: String, reason: Option<&'static str>, finding: Finding) {
        self.group(comparable, label, reason).findings.push(finding);
    }

    /// A not comparable reading; listed only when the two modules'
    /// replies differ.
    fn not_comparable(&mut self, label: String, reason: &'static str, finding: Finding) {
        let group = self.group(false, label, Some(reason));
        if finding.expected.is_some() && finding.expected == finding.actual {
            group.identical += 1;
        } else {
            group.findings.push(finding);
        }
    }

    /// Findings listed (differing readings).
    fn count(groups: &[Group]) -> usize {
        groups.iter().map(|g| g.findings.len()).sum()
    }

    /// Not comparable readings whose values were the same.
    fn identical(&self) -> usize {
        self.not_comparable.iter().map(|g| g.identical).sum()
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
            // A port by what it is, in the same words on every module (the
            // manuals name the same pin IN0, AIN0 or AIN_0). GIO reads
            // inputs and outputs; SIO sets outputs, pull-ups and ranges.
            let rank = |d: PortDirection| match (ins.opcode, d) {
                (opcode::GIO, PortDirection::Input | PortDirection::Output) => 0,
                (opcode::SIO, PortDirection::Output | PortDirection::Pullup | PortDirection::InputRange) => 0,
                _ => 1,
            };
            let port = profile.ports.iter().filter(|p| p.bank == ins.motor && p.number == ins.kind).min_by_key(|p| rank(p.direction));
            format!("{op} {}, bank {}{}", ins.kind, ins.motor, port.map_or(String::new(), |p| format!(" ({})", p.meaning())))
        }
        None if opcode::mnemonic(ins.opcode).is_some() => format!("{op} type {}, motor {}", ins.kind, ins.motor),
        None => format!("{op} ({}), type {}", ins.opcode, ins.kind),
    }
}

/// A request in words: its mnemonic form, or a control command by name
/// (`get firmware version (136), type 0`).
fn request_text(ins: Instruction) -> String {
    if opcode::mnemonic(ins.opcode).is_some() || opcode::boot_name(ins.opcode).is_some() {
        return mnemonic::format(ins);
    }
    let mut text = format!("{} ({}), type {}", opcode::name(ins.opcode), ins.opcode, ins.kind);
    if ins.motor != 0 {
        let _ = write!(text, ", motor {}", ins.motor);
    }
    if ins.value != 0 {
        let _ = write!(text, ", value {}", ins.value);
    }
    text
}

/// "1 reply", "3 replies", "2 differences".
fn count_of(n: usize, noun: &str) -> String {
    match (n, noun.strip_suffix('y')) {
        (1, _) => format!("1 {noun}"),
        (_, Some(stem)) => format!("{n} {stem}ies"),
        _ => format!("{n} {noun}s"),
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

/// What a trace says of its own module: its first answered 136.
struct Recorded {
    /// The reply's line.
    line: usize,
    /// The type number the reply names (1141).
    type_number: u16,
    /// The reply as it reads (`136: 1141V146`).
    said: String,
}

/// The trace's first 136 reply that names a module (type 0: the version
/// string, type 1: the version number; a bootloader's `1141B106` too).
fn recorded_module(exchanges: &[Exchange]) -> Option<Recorded> {
    exchanges.iter().find_map(|x| {
        let ins = instruction(&x.request.frame);
        let reply = x.reply?;
        if ins.opcode != opcode::FIRMWARE_VERSION {
            return None;
        }
        match ins.kind {
            0 => {
                let text = String::from_utf8_lossy(&reply.frame[1..]).trim_end_matches('\0').to_string();
                let digits: String = text.chars().take_while(char::is_ascii_digit).collect();
                let type_number = digits.parse().ok()?;
                Some(Recorded { line: reply.line, type_number, said: format!("136: {text}") })
            }
            1 => {
                let r = Reply::decode(&reply.frame).filter(|r| r.status == Status::Ok.code())?;
                let v = r.value as u32;
                let type_number = (v >> 16) as u16;
                let said = format!("136 type 1: {type_number} V{}.{:02}", (v >> 8) & 0xFF, v & 0xFF);
                Some(Recorded { line: reply.line, type_number, said })
            }
            _ => None,
        }
    })
}

/// The built-in profile of the module with this type number.
fn profile_named_by(type_number: u16) -> Option<&'static str> {
    Profile::names().into_iter().find(|n| Profile::built_in(n).is_ok_and(|p| p.module.type_number == type_number))
}

/// What the recorded module accepted (status 100) that `profile` lacks: a
/// motor, an axis or a global parameter; each with its first line.
fn lacking(exchanges: &[Exchange], profile: &Profile) -> Vec<(usize, String)> {
    let mut found: Vec<(usize, String)> = Vec::new();
    for x in exchanges {
        let Some(reply) = x.reply.and_then(|r| Reply::decode(&r.frame).map(|d| (r.line, d))) else { continue };
        if reply.1.status != Status::Ok.code() {
            continue;
        }
        let ins = instruction(&x.request.frame);
        let motor = |m: u8| (m >= profile.module.axes).then(|| format!("motor {m}"));
        let what = match table_of(ins.opcode) {
            Some(Table::Axis) => {
                motor(ins.motor).or_else(|| profile.axis_parameter(ins.kind).is_none().then(|| format!("axis parameter {}", ins.kind)))
            }
            Some(Table::Global) => profile
                .global_parameter(ins.motor, ins.kind)
                .is_none()
                .then(|| format!("global parameter {}, bank {}", ins.kind, ins.motor)),
            None if matches!(ins.opcode, opcode::ROR | opcode::ROL | opcode::MST) => motor(ins.motor),
            None if ins.opcode == opcode::MVP && ins.kind < 2 => motor(ins.motor),
            None => None,
        };
        if let Some(what) = what
            && !found.iter().any(|(_, w)| *w == what)
        {
            found.push((reply.0, what));
        }
    }
    found
}

/// The line that says the trace is from another module than the one it
/// is checked as (none when nothing says so).
fn other_module(exchanges: &[Exchange], profile: &Profile) -> Option<String> {
    let checked = &profile.module.name;
    if let Some(r) = recorded_module(exchanges) {
        if r.type_number == profile.module.type_number {
            return None;
        }
        return Some(match profile_named_by(r.type_number) {
            Some(n) => {
                let name = Profile::built_in(n).map_or(n.to_string(), |p| p.module.name.clone());
                format!(
                    "this trace is from a {name} ({} on line {}); checked as {}: give --module {n} (or --module auto)",
                    r.said,
                    r.line,
                    checked.to_lowercase()
                )
            }
            None => format!(
                "this trace is from a module of type {} ({} on line {}), which has no profile here; checked as {}",
                r.type_number,
                r.said,
                r.line,
                checked.to_lowercase()
            ),
        });
    }
    let lacks = lacking(exchanges, profile);
    if lacks.is_empty() {
        return None;
    }
    let fits: Vec<&str> =
        Profile::names().into_iter().filter(|n| Profile::built_in(n).is_ok_and(|p| lacking(exchanges, &p).is_empty())).collect();
    let list: Vec<String> = lacks.iter().take(3).map(|(line, what)| format!("{what} on line {line}")).collect();
    let more = if lacks.len() > 3 { format!(" and {} more", lacks.len() - 3) } else { String::new() };
    let fits = match fits.as_slice() {
        [] => "no profile here has all of it".to_string(),
        fits => format!("it fits {}", fits.join(", ")),
    };
    Some(format!(
        "this trace is not from a {checked}: its module accepted what a {checked} does not have ({}{more}); {fits}",
        list.join(", ")
    ))
}

/// The profile to check with: `--module`, or for `auto` the one the
/// trace's 136 reply names (with the line that says so).
fn chosen_profile(module: &str, exchanges: &[Exchange], name: &str) -> Result<(std::sync::Arc<Profile>, Option<String>), String> {
    if module != "auto" {
        return Ok((Profile::built_in(module)?, None));
    }
    let Some(r) = recorded_module(exchanges) else {
        return Err(format!(
            "{name}: --module auto: the trace holds no reply to 136 (the firmware version) that names its module; give --module NAME (tmclsim profile lists them)"
        ));
    };
    let Some(n) = profile_named_by(r.type_number) else {
        return Err(format!(
            "{name}: --module auto: the trace's {} (line {}) names a module of type {}, which has no profile here; give --module NAME",
            r.said, r.line, r.type_number
        ));
    };
    Ok((Profile::built_in(n)?, Some(format!("module: {n}, from the trace's {} on line {}", r.said, r.line))))
}

pub fn run(args: CheckArgs) -> Result<ExitCode, String> {
    let name = args.file.display().to_string();
    let file = std::fs::File::open(&args.file).map_err(|e| format!("{name}: {e}"))?;
    let entries = trace::read(file, &name)?;
    let Some(last) = entries.last() else {
        return Err(format!("{name}: holds no frames"));
    };
    let (exchanges, orphans, events) = split(&entries);
    let (profile, chosen) = chosen_profile(&args.module, &exchanges, &name)?;
    let world = crate::load_world(&args.world, profile.module.axes as usize)?;
    let mut module = Module::with_world(profile.clone(), Eeprom::new(&profile.module.name), world);
    if let Some(a) = args.address {
        module.set_address(a);
    }
    if let Some(path) = &args.setup {
        crate::run::setup(&mut module, path)?;
    }
    let address = module.address();
    let mut out = String::new();
    // First: a trace from another module than the one it is checked as.
    for line in [chosen, other_module(&exchanges, &profile)].into_iter().flatten() {
        let _ = writeln!(out, "{line}");
    }
    let mut replay = Replay { bus: Bus::single(module), events: Vec::new() };
    let report = replay.run(&exchanges, &orphans, &events, args.time_tolerance * 1_000_000, last.t_ns, &profile);
    let _ = writeln!(
        out,
        "{name}: {} and {} replayed on a virtual {} (address {address}, world {}) over {} s of recorded time",
        count_of(exchanges.len(), "request"),
        count_of(events.len(), "event"),
        profile.module.name,
        args.world,
        seconds(last.t_ns)
    );
    write_groups(&mut out, &report.differences, "difference", args.show);
    let identical = report.identical();
    let differing = Report::count(&report.not_comparable);
    if differing > 0 {
        out.push_str("not comparable (listed, not counted as differences: these values depend on what the virtual module cannot know)\n");
        write_groups(&mut out, &report.not_comparable, "reply", args.show);
    }
    if identical > 0 {
        let _ = writeln!(out, "{} not comparable but the same on both modules (not listed)", count_of(identical, "reply"));
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
    let same = if identical > 0 { format!(" ({identical} of them the same)") } else { String::new() };
    let _ = writeln!(
        out,
        "result: {}, {} not comparable{same}, {} match",
        count_of(differences, "difference"),
        differing + identical,
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
                Verdict::NotComparable(why) => report.not_comparable(label(profile, ins), why, finding(String::new())),
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
    for g in groups.iter().filter(|g| !g.findings.is_empty()) {
        let n = g.findings.len();
        let reason = g.reason.map_or(String::new(), |r| format!("; {r}"));
        let _ = writeln!(out, "{}: {}{reason}", g.label, count_of(n, noun));
        for f in g.findings.iter().take(show) {
            let ins = f.request.map(|r| instruction(&r));
            let at = f.line.map_or("the virtual module".to_string(), |l| format!("line {l}"));
            let what = match f.request.map(|r| Request::decode(&r)) {
                Some(Ok(r)) => format!(": {}", request_text(r.instruction)),
                Some(Err(r)) => format!(": {} (wrong checksum)", request_text(r.instruction)),
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
