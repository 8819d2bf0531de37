//! The module behind the JavaScript binding, in plain Rust: one virtual
//! module on a bus of its own, in stepped virtual time (the wall clock is
//! never read), with the assembler. The binding (`bindings.rs`) only turns
//! these values into JavaScript ones, so everything here is tested natively.

use tmclsim_asm::{Diagnostic, NoIncludes};
use tmclsim_firmware::bus::Bus;
use tmclsim_firmware::program::RunMode;
use tmclsim_firmware::world_command::{Addressed, HELP};
use tmclsim_firmware::{Eeprom, Module, Profile, World};
use tmclsim_ide::reply::Shape;
use tmclsim_protocol::{FRAME_LEN, Instruction, Reply, Request, Status, mnemonic, opcode};

/// How many 138 events are kept until they are taken; older ones are
/// dropped.
pub const MAX_EVENTS: usize = 1024;

/// How long `step` lets virtual time run at most for one instruction (a
/// WAIT in progress ends first).
const STEP_LIMIT_NS: u64 = 10_000_000_000;

/// A slice of virtual time while a WAIT of `step` is looked at.
const STEP_SLICE_NS: u64 = 10_000_000;

/// Why a call failed: a message and, for a line that does not parse, the
/// 1-based column.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    pub message: String,
    pub column: Option<usize>,
}

impl Failure {
    pub fn new(message: impl Into<String>) -> Failure {
        Failure { message: message.into(), column: None }
    }
}

impl From<String> for Failure {
    fn from(message: String) -> Failure {
        Failure::new(message)
    }
}

impl From<&str> for Failure {
    fn from(message: &str) -> Failure {
        Failure::new(message)
    }
}

impl From<tmclsim_profile::ProfileError> for Failure {
    fn from(e: tmclsim_profile::ProfileError) -> Failure {
        Failure::new(e.to_string())
    }
}

/// The module's answer to a command line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Answer {
    pub status: u8,
    pub value: i32,
    /// The version string (136 type 0), the stored word (134), or what an
    /// error status means.
    pub text: Option<String>,
}

/// One program word of an assembled program.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Word {
    pub instruction: Instruction,
    /// The word as a mnemonic line.
    pub text: String,
    /// The source line it came from (1-based; 0 when unknown).
    pub line: u32,
}

/// What the assembler made of a source: the words, or what is wrong.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Assembled {
    pub words: Vec<Word>,
    pub diagnostics: Vec<Diagnostic>,
}

impl Assembled {
    pub fn ok(&self) -> bool {
        self.diagnostics.is_empty()
    }
}

/// The program's registers and where it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct State {
    /// The program counter as the module reports it (GP 130).
    pub pc: u16,
    pub mode: RunMode,
    pub accumulator: i32,
    pub x: i32,
    /// Instructions executed since power-up.
    pub executed: u64,
}

/// The name of a run mode as GP 128 counts them.
pub fn mode_name(mode: RunMode) -> &'static str {
    match mode {
        RunMode::Stop => "stop",
        RunMode::Run => "run",
        RunMode::Step => "step",
        RunMode::Reset => "reset",
    }
}

/// Seconds (a float) to nanoseconds of virtual time: finite, not negative,
/// and within the 2^64 ns virtual time counts.
pub fn seconds_to_ns(seconds: f64) -> Result<u64, Failure> {
    if !(seconds.is_finite() && seconds >= 0.0) {
        return Err(format!("time moves forward only: a duration is a finite number of seconds ≥ 0, not {seconds}").into());
    }
    let ns = (seconds * 1e9).round();
    if ns >= u64::MAX as f64 {
        return Err(format!("{seconds} s is too long: virtual time ends after about 584 years").into());
    }
    Ok(ns as u64)
}

/// The world a module is made in: `stage` (the default), `free`, or the
/// TOML text of a world file (docs/world.md).
pub fn world_from(spec: Option<&str>, axes: usize) -> Result<World, Failure> {
    let Some(spec) = spec else { return Ok(World::stage(axes)) };
    if let Some(world) = World::built_in(spec.trim(), axes) {
        return Ok(world);
    }
    if spec.contains('\n') || spec.contains('=') {
        return World::from_toml(spec, axes).map_err(|e| format!("world: {e}").into());
    }
    Err(format!("no built-in world '{spec}': stage (the default), free, or the TOML text of a world").into())
}

/// One virtual module in stepped time.
#[derive(Clone, Debug)]
pub struct Sim {
    bus: Bus,
    events: Vec<[u8; FRAME_LEN]>,
}

impl Sim {
    /// A module of a built-in profile (`tmcm-1141`, the `tmcm-` prefix
    /// optional) fresh from the factory, in a world (see [`world_from`]).
    pub fn new(profile: &str, world: Option<&str>) -> Result<Sim, Failure> {
        let profile = Profile::built_in(profile)?;
        let world = world_from(world, profile.module.axes as usize)?;
        let eeprom = Eeprom::new(&profile.module.name);
        let mut bus = Bus::single(Module::with_world(profile, eeprom, world));
        bus.set_stepped(true);
        Ok(Sim { bus, events: Vec::new() })
    }

    /// The built-in profiles' names.
    pub fn profiles() -> Vec<&'static str> {
        Profile::names()
    }

    pub fn module(&self) -> &Module {
        self.bus.module(0)
    }

    /// The profile's module name (`TMCM-1141`).
    pub fn profile(&self) -> String {
        self.module().profile().module.name.clone()
    }

    /// The address the module answers to now.
    pub fn address(&self) -> u8 {
        self.module().address()
    }

    /// Keeps the 138 events the module sent (the newest [`MAX_EVENTS`]).
    fn collect_events(&mut self) {
        let effects = self.bus.take_effects();
        self.events.extend(effects.events.into_iter().map(|(_, frame)| frame));
        let extra = self.events.len().saturating_sub(MAX_EVENTS);
        self.events.drain(..extra);
    }

    /// The 138 events since the last call, oldest first.
    pub fn take_events(&mut self) -> Vec<[u8; FRAME_LEN]> {
        self.collect_events();
        std::mem::take(&mut self.events)
    }

    /// Nine bytes on the link, as from a host: the replies (nine bytes, or
    /// none when the frame is not for the module).
    pub fn frame(&mut self, bytes: &[u8]) -> Result<Vec<u8>, Failure> {
        let frame: &[u8; FRAME_LEN] = bytes.try_into().map_err(|_| format!("a TMCL frame is {FRAME_LEN} bytes, not {}", bytes.len()))?;
        let answer = self.bus.handle_frame(frame);
        self.collect_events();
        Ok(answer.replies.concat())
    }

    /// A mnemonic line (`SAP 4, 0, 1000`, `#136 0 0 0`) sent to the module
    /// as a frame to its address.
    pub fn command(&mut self, line: &str) -> Result<Answer, Failure> {
        let ins = mnemonic::parse_line(line).map_err(|e| Failure { message: e.message, column: Some(e.column) })?;
        let address = self.address();
        let replies = self.frame(&Request::new(address, ins).encode())?;
        let raw: &[u8; FRAME_LEN] = replies
            .get(..FRAME_LEN)
            .and_then(|r| r.try_into().ok())
            .ok_or_else(|| Failure::new("the module did not answer (in ASCII mode it reads text only)"))?;
        Ok(answer_of(ins, raw, address))
    }

    /// Moves virtual time on.
    pub fn advance(&mut self, seconds: f64) -> Result<(), Failure> {
        let ns = seconds_to_ns(seconds)?;
        if self.bus.now_ns().checked_add(ns).is_none() {
            return Err(format!("advancing {seconds} s passes the end of virtual time (about 584 years)").into());
        }
        self.bus.advance(ns);
        self.collect_events();
        Ok(())
    }

    /// Virtual time in seconds since the module was made.
    pub fn time(&self) -> f64 {
        self.bus.now_ns() as f64 * 1e-9
    }

    /// Assembles a source for this module (the shipped include files are
    /// found; others are not).
    pub fn assemble(&self, source: &str) -> Assembled {
        let profile = self.module().profile().clone();
        match tmclsim_asm::assemble(source, "program.tmc", &NoIncludes, Some(&profile)) {
            Ok(program) => {
                let line = |a: usize| program.source_map.get(a).map_or(0, |s| s.line);
                let words = program
                    .instructions
                    .iter()
                    .enumerate()
                    .map(|(a, &instruction)| Word { instruction, text: mnemonic::format(instruction), line: line(a) })
                    .collect();
                Assembled { words, diagnostics: Vec::new() }
            }
            Err(diagnostics) => Assembled { words: Vec::new(), diagnostics },
        }
    }

    /// Assembles a source and loads it as a download (132…133) would: into
    /// program memory and the EEPROM, the program stopped at address 0.
    pub fn download(&mut self, source: &str) -> Assembled {
        let mut assembled = self.assemble(source);
        if !assembled.ok() {
            return assembled;
        }
        let words: Vec<Instruction> = assembled.words.iter().map(|w| w.instruction).collect();
        self.bus.catch_up();
        let m = self.bus.module_mut(0);
        if m.load_program(&words).is_err() {
            let message = format!(
                "the program has {} words; the {} holds {}",
                words.len(),
                m.profile().module.name,
                m.profile().module.program_memory
            );
            assembled.diagnostics.push(Diagnostic::new("program.tmc", 0, 0, message));
            return assembled;
        }
        m.execute(Instruction::new(opcode::RESET_APPLICATION, 0, 0, 0));
        self.collect_events();
        assembled
    }

    /// Runs the program: on from where it is, or afresh from `start`
    /// (129 type 1).
    pub fn run(&mut self, start: Option<u32>) -> Result<(), Failure> {
        self.bus.catch_up();
        match start {
            None => {
                self.bus.module_mut(0).start_program();
                Ok(())
            }
            Some(address) => {
                let value = i32::try_from(address).map_err(|_| format!("{address} is not a program address"))?;
                self.control(Instruction::new(opcode::RUN_APPLICATION, 1, 0, value))
            }
        }
    }

    /// Stops the program (128).
    pub fn stop(&mut self) -> Result<(), Failure> {
        self.bus.catch_up();
        self.control(Instruction::new(opcode::STOP_APPLICATION, 0, 0, 0))
    }

    /// Runs one more instruction (a WAIT in progress first ends, virtual
    /// time moving as needed, at most 10 s), then pauses. False when the
    /// 10 s passed first.
    pub fn step(&mut self) -> bool {
        let end = self.bus.now_ns().saturating_add(STEP_LIMIT_NS);
        let done = self.bus.step_instruction(0, end, STEP_SLICE_NS);
        self.collect_events();
        done
    }

    /// The program's registers and counter.
    pub fn state(&self) -> State {
        let m = self.module();
        let program = m.program();
        let registers = m.registers();
        State { pc: program.counter(), mode: program.mode, accumulator: registers.accumulator, x: registers.x, executed: program.executed }
    }

    /// Reads as an observer makes them (docs/behaviour.md rule 86): the
    /// model's replies, `None` for what is not a read; nothing changes.
    pub fn observe(&mut self, all: &[Instruction]) -> Vec<Option<[u8; FRAME_LEN]>> {
        self.bus.observe(0, all)
    }

    /// The program's breakpoints: the firmware stops on them.
    pub fn set_breakpoints(&mut self, addresses: &[u16]) {
        self.bus.module_mut(0).set_breakpoints(addresses);
    }

    /// A world command (docs/world.md): its answer, or what is wrong.
    pub fn world(&mut self, line: &str) -> Result<String, Failure> {
        match line.split_whitespace().next() {
            None | Some("help") => Ok(HELP.to_string()),
            Some("link") => Err("link faults belong to a served link; this module has none".into()),
            Some(_) => {
                let Addressed { address, command } = Addressed::parse(line).map_err(String::from)?;
                let answer = self.bus.apply_world(address, &command).map_err(String::from)?;
                self.collect_events();
                Ok(answer)
            }
        }
    }

    /// A program control command the module runs directly.
    fn control(&mut self, ins: Instruction) -> Result<(), Failure> {
        let outcome = self.bus.module_mut(0).execute(ins);
        self.collect_events();
        if outcome.status.is_error() {
            return Err(format!("{}: {}", mnemonic::format(ins), outcome.status.describe()).into());
        }
        Ok(())
    }
}

/// The reply `raw` to `ins` from the module at `address`.
fn answer_of(ins: Instruction, raw: &[u8; FRAME_LEN], address: u8) -> Answer {
    let ok = Status::Ok.code();
    match tmclsim_ide::reply::shape(ins, address, raw) {
        // The host address and eight characters, no checksum.
        Shape::Version => return Answer { status: ok, value: 0, text: Some(String::from_utf8_lossy(&raw[1..]).into_owned()) },
        // The stored word in place of the module address.
        Shape::Memory => {
            let stored = Instruction::from_bytes(raw[1..8].try_into().expect("seven bytes"));
            return Answer { status: ok, value: stored.value, text: Some(mnemonic::format(stored)) };
        }
        Shape::Normal => {}
    }
    let reply = Reply::decode(raw);
    match reply {
        Some(r) => {
            let text = (r.status < 100).then(|| Status::text(r.status).into_owned());
            Answer { status: r.status, value: r.value, text }
        }
        None => Answer { status: 0, value: 0, text: Some("the reply's checksum is wrong".into()) },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sim() -> Sim {
        Sim::new("tmcm-1141", None).unwrap()
    }

    fn value(s: &mut Sim, line: &str) -> i32 {
        let a = s.command(line).unwrap();
        assert_eq!(a.status, 100, "{line}: {a:?}");
        a.value
    }

    #[test]
    fn an_unknown_profile_names_the_known_ones() {
        let e = Sim::new("tmcm-9999", None).unwrap_err();
        assert!(e.message.contains("tmcm-9999") && e.message.contains("tmcm-1141"), "{e:?}");
        assert!(Sim::profiles().contains(&"tmcm-1141"));
        let s = Sim::new("1141", None).unwrap();
        assert_eq!((s.profile().as_str(), s.address()), ("TMCM-1141", 1));
    }

    #[test]
    fn worlds_by_name_or_toml() {
        assert!(Sim::new("tmcm-1141", Some("free")).is_ok());
        assert!(Sim::new("tmcm-1141", Some("stage")).is_ok());
        assert!(Sim::new("tmcm-1141", Some("moon")).unwrap_err().message.contains("no built-in world 'moon'"));
    }

    #[test]
    fn frames_in_replies_out() {
        let mut s = sim();
        let reply = s.frame(&[1, 6, 1, 0, 0, 0, 0, 0, 8]).unwrap();
        assert_eq!(reply.len(), 9);
        let r = Reply::decode(reply.as_slice().try_into().unwrap()).unwrap();
        assert_eq!((r.host, r.module, r.status, r.opcode), (2, 1, 100, 6));
        let bad = s.frame(&[1, 6, 1, 0, 0, 0, 0, 0, 9]).unwrap();
        assert_eq!(bad[2], 1, "wrong checksum");
        assert!(s.frame(&Request::new(7, Instruction::new(6, 1, 0, 0)).encode()).unwrap().is_empty());
        assert_eq!(s.frame(&[1; 8]).unwrap_err().message, "a TMCL frame is 9 bytes, not 8");
    }

    #[test]
    fn commands_set_and_get() {
        let mut s = sim();
        assert_eq!(value(&mut s, "SAP 4, 0, 1000"), 1000);
        assert_eq!(value(&mut s, "GAP 4, 0"), 1000);
        let wrong = s.command("GAP 250, 0").unwrap();
        assert_eq!((wrong.status, wrong.text.as_deref()), (3, Some("wrong type")));
        assert_eq!(s.command("#136 0 0 0").unwrap().text.as_deref(), Some("1141V146"));
        let e = s.command("SAP 4, 0, x").unwrap_err();
        assert_eq!(e.column, Some(11), "{e:?}");
    }

    #[test]
    fn time_moves_only_when_advanced() {
        let mut s = sim();
        value(&mut s, "ROR 0, 500");
        assert_eq!(value(&mut s, "GAP 1, 0"), 0);
        s.advance(1.0).unwrap();
        assert_eq!(s.time(), 1.0);
        assert!(value(&mut s, "GAP 1, 0") > 0);
        for bad in [-1.0, f64::NAN, f64::INFINITY, 1e12] {
            assert!(s.advance(bad).is_err(), "{bad}");
        }
        assert_eq!(s.time(), 1.0);
    }

    #[test]
    fn a_move_reaches_its_target() {
        let mut s = sim();
        value(&mut s, "MVP ABS, 0, 51200");
        s.advance(0.01).unwrap();
        assert_eq!(value(&mut s, "GAP 8, 0"), 0);
        s.advance(10.0).unwrap();
        assert_eq!((value(&mut s, "GAP 8, 0"), value(&mut s, "GAP 1, 0")), (1, 51200));
    }

    #[test]
    fn a_downloaded_program_runs_and_steps() {
        let mut s = sim();
        let a = s.download("CALC LOAD, 5\nCALC ADD, 2\nSTOP\n");
        assert!(a.ok(), "{:?}", a.diagnostics);
        assert_eq!(a.words.len(), 3);
        assert_eq!((a.words[1].text.as_str(), a.words[1].line), ("CALC ADD, 2", 2));
        assert!(s.step());
        assert_eq!((s.state().pc, s.state().accumulator, s.state().mode), (1, 5, RunMode::Step));
        s.run(None).unwrap();
        s.advance(0.01).unwrap();
        let st = s.state();
        assert_eq!((st.accumulator, st.mode, st.executed), (7, RunMode::Stop, 3));
        assert_eq!(s.time(), s.module().now_ns() as f64 * 1e-9, "step and run keep one clock");
        s.run(Some(1)).unwrap();
        s.advance(0.01).unwrap();
        assert_eq!(s.state().accumulator, 9);
        assert!(s.run(Some(5000)).is_err());
        s.stop().unwrap();
        // Downloaded words are what 134 reads back.
        assert_eq!(s.command("#134 0 0 1").unwrap().text.as_deref(), Some("CALC ADD, 2"));
    }

    #[test]
    fn source_errors_are_diagnostics() {
        let s = sim();
        let a = s.assemble("CALC LOAD, 5\n  FOO 1\n");
        assert!(!a.ok());
        let d = &a.diagnostics[0];
        assert_eq!((d.line, d.column), (2, 3), "{d:?}");
        let big = "STOP\n".repeat(3000);
        let mut s = sim();
        let a = s.download(&big);
        assert!(!a.ok() && a.diagnostics[0].message.contains("holds 1024"), "{:?}", a.diagnostics);
    }

    #[test]
    fn world_commands_apply_or_say_why_not() {
        let mut s = sim();
        s.world("input 0 1").unwrap();
        assert_eq!(value(&mut s, "GIO 0, 0"), 1);
        assert!(s.world("help").unwrap().contains("input N"));
        assert!(s.world("link drop 1").is_err());
        assert!(s.world("fly 0").is_err());
    }

    #[test]
    fn target_reached_events_are_kept() {
        let mut s = sim();
        value(&mut s, "#138 0 0 1");
        value(&mut s, "MVP ABS, 0, 1000");
        s.advance(5.0).unwrap();
        let events = s.take_events();
        assert_eq!(events.len(), 1);
        assert_eq!(events[0][2], 128);
        assert!(s.take_events().is_empty());
    }
}
