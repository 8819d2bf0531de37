//! The source-level debugger of `tmclsim run`: where the program stands
//! (file, line, label, source text), breakpoints on labels, addresses and
//! `file:line`, single steps, stepping over subroutines, advancing virtual
//! time, watches and prints of registers, axis and global parameters and
//! user variables.

use std::collections::BTreeMap;
use std::io::Write;

use tmclsim_asm::{LinePlace, Program, source_map};
use tmclsim_firmware::program::RunMode;
use tmclsim_firmware::{Bus, Module};
use tmclsim_protocol::{mnemonic, opcode, suggest};

/// What the run loop does after the debugger.
pub enum Debug {
    Continue,
    Quit,
}

const HELP: &str = "\
debugger commands (a prefix in brackets may be left out):
  s[tep] [N]          run N instructions (default 1), then stop
  n[ext]              run one instruction; a CALL runs until it returns
  c[ontinue]          run until a breakpoint or the end of the run
  a[dvance] TIME      run for TIME of virtual time (500ms, 5s, 2m), or to a breakpoint
  b[reak] PLACE       stop before PLACE: a label, an address, or FILE:LINE
  d[elete] PLACE      remove a breakpoint; b alone lists them
  p[rint] WHAT        print a value once
  w[atch] WHAT        print a value at every stop where it changed; w alone lists
  u[nwatch] N|all     remove watch N (as w lists them) or all
  l[ist] [PLACE]      source lines around the program counter or PLACE
  i[nspect]           registers, stack, axes, outputs, user variables
  h[elp]              this text
  q[uit]              end the run
WHAT: acc, x, pc, flags, stack, AP N|NAME [MOTOR], GP N|NAME [BANK], var N";

/// A value the debugger can print or watch.
#[derive(Clone, Debug, PartialEq)]
enum Quantity {
    Accumulator,
    X,
    Pc,
    Flags,
    Stack,
    Axis { number: u8, motor: u8 },
    Global { number: u8, bank: u8 },
    Variable(u16),
}

/// The debugger's state between its sessions: watches and their last
/// values.
#[derive(Default)]
pub struct Debugger {
    watches: Vec<(Quantity, Option<String>)>,
}

impl Debugger {
    /// One debugger session on the bus's (first) module: commands until
    /// `continue` or `quit` (or the end of the input). Time moves on the
    /// bus.
    pub fn session(
        &mut self,
        bus: &mut Bus,
        program: &Program,
        lines: &mut impl Iterator<Item = std::io::Result<String>>,
        end: u64,
    ) -> Result<Debug, String> {
        let m = bus.module_mut(0);
        m.pause_program();
        if let Some(pc) = m.program().hit_breakpoint {
            println!("breakpoint at {}", place(program, pc));
        }
        self.report_changes(m);
        println!("debugger: h for help");
        loop {
            prompt(bus.module(0), program);
            let Some(line) = lines.next() else { return Ok(Debug::Quit) };
            let line = line.map_err(|e| e.to_string())?;
            let words: Vec<&str> = line.split_whitespace().collect();
            let Some((command, args)) = words.split_first() else { continue };
            if let Some(end_of_session) = self.command(bus, program, command, args, end) {
                return Ok(end_of_session);
            }
        }
    }

    /// Runs one command line; `Some` when it ends the session.
    fn command(&mut self, bus: &mut Bus, program: &Program, command: &str, args: &[&str], end: u64) -> Option<Debug> {
        let m = bus.module_mut(0);
        match command.to_ascii_lowercase().as_str() {
            "s" | "step" => self.step(bus, args, end),
            "n" | "next" if args.is_empty() => {
                next(bus, end);
                self.report_changes(bus.module(0));
            }
            "c" | "continue" if args.is_empty() => {
                m.start_program();
                return Some(Debug::Continue);
            }
            "a" | "advance" => self.advance(bus, program, args, end),
            "b" | "break" | "d" | "delete" => breakpoints(m, program, command.starts_with(['b', 'B']), args),
            "p" | "print" => match Quantity::parse(args, m) {
                Ok(q) => println!("{} = {}", q.describe(m), q.read(m)),
                Err(e) => println!("{e}"),
            },
            "w" | "watch" if args.is_empty() => self.list(m),
            "w" | "watch" => self.watch(m, args),
            "u" | "unwatch" => self.unwatch(args),
            "l" | "list" => list(m, program, args),
            "i" | "inspect" if args.is_empty() => inspect(m),
            "h" | "help" | "?" => println!("{HELP}"),
            "q" | "quit" => return Some(Debug::Quit),
            "n" | "next" | "c" | "continue" | "i" | "inspect" => println!("{command} takes no arguments"),
            other => {
                let known = [
                    "step", "next", "continue", "advance", "break", "delete", "print", "watch", "unwatch", "list", "inspect", "help",
                    "quit",
                ];
                println!("unknown command '{other}'{}; h lists the commands", suggest::suggestion(other, known));
            }
        }
        None
    }

    /// `step [N]`: N instructions (1), not past the run's end.
    fn step(&mut self, bus: &mut Bus, args: &[&str], end: u64) {
        match count(args) {
            Ok(n) => {
                for _ in 0..n {
                    if !step_one(bus, end) {
                        println!("the run's end (--for) is reached");
                        break;
                    }
                }
                self.report_changes(bus.module(0));
            }
            Err(e) => println!("{e}"),
        }
    }

    /// `advance TIME`: virtual time on, the program running.
    fn advance(&mut self, bus: &mut Bus, program: &Program, args: &[&str], end: u64) {
        match args {
            [time] => match crate::duration::parse_duration(time) {
                Ok(d) => {
                    advance(bus, program, d, end);
                    self.report_changes(bus.module(0));
                }
                Err(e) => println!("{e}"),
            },
            _ => println!("advance takes one time, e.g. advance 5s"),
        }
    }

    /// `watch WHAT`: a quantity shown whenever it changes.
    fn watch(&mut self, m: &Module, args: &[&str]) {
        match Quantity::parse(args, m) {
            Ok(q) => {
                let value = q.read(m);
                println!("watch {}: {} = {value}", self.watches.len() + 1, q.describe(m));
                self.watches.push((q, Some(value)));
            }
            Err(e) => println!("{e}"),
        }
    }

    /// `unwatch N` or `unwatch all`.
    fn unwatch(&mut self, args: &[&str]) {
        match args {
            ["all"] => self.watches.clear(),
            [n] => match n.parse::<usize>() {
                Ok(i) if (1..=self.watches.len()).contains(&i) => {
                    self.watches.remove(i - 1);
                }
                _ => println!("no watch {n}; w lists them"),
            },
            _ => println!("unwatch takes a watch number (w lists them) or all"),
        }
    }

    /// Prints the watches whose value changed since they were last shown.
    fn report_changes(&mut self, m: &Module) {
        for (i, (q, last)) in self.watches.iter_mut().enumerate() {
            let now = q.read(m);
            if last.as_deref() != Some(now.as_str()) {
                println!("watch {}: {} {} → {now}", i + 1, q.describe(m), last.as_deref().unwrap_or("?"));
                *last = Some(now);
            }
        }
    }

    fn list(&mut self, m: &Module) {
        if self.watches.is_empty() {
            println!("no watches; w WHAT adds one (h for help)");
        }
        for (i, (q, last)) in self.watches.iter_mut().enumerate() {
            let now = q.read(m);
            println!("watch {}: {} = {now}", i + 1, q.describe(m));
            *last = Some(now);
        }
    }
}

/// `prog.tmc:6 (1, Loop)`, or `address 1 (Loop)` without a source map.
pub fn place(program: &Program, address: u16) -> String {
    let labels: Vec<&str> = program.symbols.iter().filter(|(_, a)| **a == u32::from(address)).map(|(l, _)| l.as_str()).collect();
    let label = if labels.is_empty() { String::new() } else { format!(", {}", labels.join(", ")) };
    match program.source_of(u32::from(address)) {
        Some(s) => format!("{}:{} ({address}{label})", s.file, s.line),
        None => format!("address {address}{}", if labels.is_empty() { String::new() } else { format!(" ({})", labels.join(", ")) }),
    }
}

/// The prompt: virtual time, the program's place and instruction.
fn prompt(m: &Module, program: &Program) {
    // While a WAIT waits, the counter stands on the WAIT (135 type 1).
    let pc = m.program().counter();
    let waiting = if m.program().wait.is_some() { " (waiting)" } else { "" };
    print!("[{:.3} s] {}  {}{waiting} > ", m.now_ns() as f64 * 1e-9, place(program, pc), text_at(program, pc));
    std::io::stdout().flush().ok();
}

/// The source text of an instruction, or its mnemonic form.
fn text_at(program: &Program, address: u16) -> String {
    match (program.source_of(u32::from(address)), program.instructions.get(address as usize)) {
        (Some(s), _) => s.text.clone(),
        (None, Some(i)) => mnemonic::format(*i),
        (None, None) => "(end of program)".into(),
    }
}

/// Registers, stack, axes, outputs and the user variables that are not 0.
pub fn inspect(m: &Module) {
    let r = m.registers();
    let p = m.program();
    println!("  accumulator {}  X {}  compare {:?}  error flags {:#04x}", r.accumulator, r.x, r.compare, r.errors);
    println!("  stack {:?}  interrupt handler {}", p.stack, if p.handler.is_some() { "active" } else { "none" });
    for a in 0..m.profile().module.axes as usize {
        let axis = m.axis(a);
        println!(
            "  axis {a}: position {} speed {} target {} mode {:?}",
            m.actual_position(a),
            m.actual_speed(a),
            axis.target_word,
            axis.motion.mode
        );
    }
    println!("  outputs {:#b}", m.outputs());
    let vars: Vec<String> = (0..m.profile().module.user_variables as usize)
        .filter_map(|i| {
            let v = m.user_variable_value(i);
            (v != 0).then(|| format!("{i}={v}"))
        })
        .collect();
    if !vars.is_empty() {
        println!("  user variables {}", vars.join(" "));
    }
}

/// A breakpoint place: a label, an address or `FILE:LINE`.
pub fn resolve(at: &str, program: &Program) -> Result<u16, String> {
    if let Some(a) = program.symbols.get(at) {
        return Ok(*a as u16);
    }
    if let Some(n) = mnemonic::parse_number(at) {
        return u16::try_from(n)
            .ok()
            .filter(|a| (*a as usize) < program.instructions.len())
            .ok_or_else(|| format!("address {at} is outside the program (0…{})", program.instructions.len().saturating_sub(1)));
    }
    if let Some(line_place) = LinePlace::parse(at) {
        return source_map::address_of(&program.source_map, &line_place).map(|a| a as u16).map_err(String::from);
    }
    let labels = program.symbols.keys().map(String::as_str);
    Err(format!("'{at}' is neither a label of the program, an address nor FILE:LINE{}", suggest::suggestion(at, labels)))
}

fn count(args: &[&str]) -> Result<u64, String> {
    match args {
        [] => Ok(1),
        [n] => n.parse::<u64>().ok().filter(|n| *n >= 1).ok_or_else(|| format!("step takes a count of 1 or more instructions, not '{n}'")),
        _ => Err("step takes one count, e.g. s 5".into()),
    }
}

/// One instruction of the (first) module, breakpoints aside; false when
/// the run's end came first.
fn step_one(bus: &mut Bus, end: u64) -> bool {
    let bps = bus.module(0).program().breakpoints.clone();
    bus.module_mut(0).set_breakpoints(&[]);
    let done = bus.step_instruction(0, end, 10_000_000);
    bus.module_mut(0).set_breakpoints(&bps);
    done
}

/// One instruction; a CALL runs until it has returned (or a breakpoint
/// or the run's end stops it first).
fn next(bus: &mut Bus, end: u64) {
    let p = bus.module(0).program();
    let (pc, depth) = (p.pc, p.stack.len());
    let is_call = p.memory.get(pc as usize).is_some_and(|i| i.opcode == opcode::CALL);
    if !step_one(bus, end) {
        return println!("the run's end (--for) is reached");
    }
    if !is_call || bus.module(0).program().stack.len() <= depth {
        return;
    }
    loop {
        let p = bus.module(0).program();
        if p.stack.len() <= depth && p.pc == pc + 1 {
            return;
        }
        if p.breakpoints.contains(&p.pc) {
            return println!("breakpoint at address {}", p.pc);
        }
        if p.mode == RunMode::Stop || !step_one(bus, end) {
            return println!("the subroutine did not return before the run's end");
        }
    }
}

/// Runs the program for `d` of virtual time, stopping early at a
/// breakpoint.
fn advance(bus: &mut Bus, program: &Program, d: u64, end: u64) {
    let until = bus.now_ns().saturating_add(d).min(end);
    // The program leaves the breakpoint it stands on, as after continue.
    bus.module_mut(0).start_program();
    while bus.now_ns() < until && bus.module(0).program().mode == RunMode::Run {
        bus.advance_to(bus.now_ns().saturating_add(1_000_000).min(until));
    }
    let p = bus.module(0).program();
    match p.hit_breakpoint {
        Some(pc) if p.mode != RunMode::Run => println!("breakpoint at {}", place(program, pc)),
        _ if p.mode == RunMode::Stop => println!("the program has stopped"),
        _ => {}
    }
    // Time goes on to the end of the advance even when the program stopped.
    if p.hit_breakpoint.is_none() {
        bus.advance_to(until);
    }
    bus.module_mut(0).pause_program();
    if bus.now_ns() >= end {
        println!("the run's end (--for) is reached");
    }
}

fn breakpoints(m: &mut Module, program: &Program, add: bool, args: &[&str]) {
    let mut bps = m.program().breakpoints.clone();
    match args {
        [] => {}
        [at] => match resolve(at, program) {
            Ok(a) => {
                bps.retain(|b| *b != a);
                if add {
                    bps.push(a);
                }
                m.set_breakpoints(&bps);
            }
            Err(e) => return println!("{e}"),
        },
        _ => return println!("one place at a time: a label, an address or FILE:LINE"),
    }
    if bps.is_empty() {
        println!("no breakpoints");
    }
    for b in &bps {
        println!("breakpoint at {}  {}", place(program, *b), text_at(program, *b));
    }
}

/// Source lines around the program counter (or a place): the lines that
/// hold instructions, with their addresses.
fn list(m: &Module, program: &Program, args: &[&str]) {
    let center = match args {
        [] => m.program().counter(),
        [at] => match resolve(at, program) {
            Ok(a) => a,
            Err(e) => return println!("{e}"),
        },
        _ => return println!("list takes at most one place"),
    };
    let by_address: BTreeMap<u32, Vec<&str>> = program.symbols.iter().fold(BTreeMap::new(), |mut map, (l, a)| {
        map.entry(*a).or_insert_with(Vec::new).push(l.as_str());
        map
    });
    let from = center.saturating_sub(4) as usize;
    for a in from..(from + 9).min(program.instructions.len()) {
        let mark = if a == m.program().counter() as usize {
            "=>"
        } else if m.program().breakpoints.contains(&(a as u16)) {
            " *"
        } else {
            "  "
        };
        let source = program.source_of(a as u32);
        let labelled = source.is_some_and(|s| s.text.contains(':'));
        if let (Some(labels), false) = (by_address.get(&(a as u32)), labelled) {
            println!("        {}:", labels.join(":\n        "));
        }
        match source {
            Some(s) => println!("{mark} {a:4}  {:>4}  {}", s.line, s.text),
            None => println!("{mark} {a:4}        {}", mnemonic::format(program.instructions[a])),
        }
    }
}

impl Quantity {
    /// Reads `acc`, `x`, `pc`, `flags`, `stack`, `AP N|NAME [MOTOR]`,
    /// `GP N|NAME [BANK]`, `var N`.
    fn parse(args: &[&str], m: &Module) -> Result<Quantity, String> {
        let profile = m.profile();
        let Some((first, rest)) = args.split_first() else {
            return Err("print or watch what? acc, x, pc, flags, stack, AP N [MOTOR], GP N [BANK] or var N".into());
        };
        let simple = match first.to_ascii_lowercase().as_str() {
            "acc" | "accumulator" => Some(Quantity::Accumulator),
            "x" => Some(Quantity::X),
            "pc" => Some(Quantity::Pc),
            "flags" => Some(Quantity::Flags),
            "stack" => Some(Quantity::Stack),
            _ => None,
        };
        if let Some(q) = simple {
            return if rest.is_empty() { Ok(q) } else { Err(format!("{first} takes nothing more")) };
        }
        // A number, or a name of one or more words; a last number is the
        // motor or bank.
        let split = |rest: &[&str]| -> (Vec<String>, Option<i64>) {
            match rest.split_last() {
                Some((last, words)) if !words.is_empty() && mnemonic::parse_number(last).is_some() => {
                    (words.iter().map(ToString::to_string).collect(), mnemonic::parse_number(last))
                }
                _ => (rest.iter().map(ToString::to_string).collect(), None),
            }
        };
        match first.to_ascii_lowercase().as_str() {
            "ap" => {
                let (name, motor) = split(rest);
                let motor = u8::try_from(motor.unwrap_or(0))
                    .ok()
                    .filter(|mo| *mo < profile.module.axes)
                    .ok_or_else(|| format!("the {} has motors 0…{}", profile.module.name, profile.module.axes.saturating_sub(1)))?;
                let name = name.join(" ");
                let number = match mnemonic::parse_number(&name) {
                    Some(n) => u8::try_from(n).ok().filter(|n| profile.axis_parameter(*n).is_some()),
                    // The manual's name, or the console's (`actual_position`).
                    None => tmclsim_host::names::find(profile, tmclsim_host::names::Table::Axis, &name, None).map(|(_, p)| p.number),
                };
                let names = profile.axis_parameters().map(|p| p.name.as_str());
                let number = number.ok_or_else(|| {
                    format!("the {} has no axis parameter '{name}'{}", profile.module.name, suggest::suggestion(&name, names))
                })?;
                Ok(Quantity::Axis { number, motor })
            }
            "gp" => {
                let (name, bank) = split(rest);
                let name = name.join(" ");
                let number = mnemonic::parse_number(&name);
                let found = match number {
                    Some(n) => (0..=3u8)
                        .flat_map(|b| profile.global_parameters(b).map(move |p| (b, p)))
                        .find(|(b, p)| i64::from(p.number) == n && bank.is_none_or(|x| x == i64::from(*b))),
                    // The manual's name, or the console's (`tmcl_tick_timer`).
                    None => match bank.map(u8::try_from).transpose() {
                        Ok(bank) => tmclsim_host::names::find(profile, tmclsim_host::names::Table::Global, &name, bank),
                        Err(_) => None,
                    },
                };
                let names = (0..=3u8).flat_map(|b| profile.global_parameters(b).map(|p| p.name.as_str()));
                match found {
                    Some((bank, p)) => Ok(Quantity::Global { number: p.number, bank }),
                    None => {
                        Err(format!("the {} has no global parameter '{name}'{}", profile.module.name, suggest::suggestion(&name, names)))
                    }
                }
            }
            "var" | "v" => {
                let count = profile.module.user_variables;
                match rest {
                    [n] => mnemonic::parse_number(n)
                        .and_then(|n| u16::try_from(n).ok())
                        .filter(|n| u32::from(*n) < u32::from(count))
                        .map(Quantity::Variable)
                        .ok_or_else(|| format!("user variables are 0…{}", count.saturating_sub(1))),
                    _ => Err("var takes a user variable number, e.g. var 42".into()),
                }
            }
            other => Err(format!(
                "'{other}' is not a value{}: acc, x, pc, flags, stack, AP N [MOTOR], GP N [BANK] or var N",
                suggest::suggestion(other, ["acc", "pc", "flags", "stack", "AP", "GP", "var"])
            )),
        }
    }

    /// What it is, with the parameter's name.
    fn describe(&self, m: &Module) -> String {
        let profile = m.profile();
        match self {
            Quantity::Accumulator => "accumulator".into(),
            Quantity::X => "X".into(),
            Quantity::Pc => "program counter".into(),
            Quantity::Flags => "flags".into(),
            Quantity::Stack => "stack".into(),
            Quantity::Axis { number, motor } => {
                let name = profile.axis_parameter(*number).map_or("", |p| p.name.as_str());
                format!("AP {number} ({name}) motor {motor}")
            }
            Quantity::Global { number, bank } => {
                let name = profile.global_parameter(*bank, *number).map_or("", |p| p.name.as_str());
                format!("GP {number} ({name}) bank {bank}")
            }
            Quantity::Variable(n) => format!("user variable {n}"),
        }
    }

    /// Its value now, as text. Parameters are read on a copy of the
    /// module, so that reads with side effects (AP 207 clears its flags,
    /// GP 133 draws a random number) leave the program's module alone.
    fn read(&self, m: &Module) -> String {
        let r = m.registers();
        let p = m.program();
        match self {
            Quantity::Accumulator => r.accumulator.to_string(),
            Quantity::X => r.x.to_string(),
            Quantity::Pc => p.counter().to_string(),
            Quantity::Flags => format!("compare {:?}, error flags {:#04x}", r.compare, r.errors),
            Quantity::Stack => format!("{:?}", p.stack),
            Quantity::Axis { number, motor } => {
                let unit = m.profile().axis_parameter(*number).and_then(|p| p.unit.clone());
                match m.clone().get_axis_parameter(*number, *motor) {
                    Ok(v) => unit.map_or(v.to_string(), |u| format!("{v} {u}")),
                    Err(s) => format!("not readable (status {})", s as u8),
                }
            }
            Quantity::Global { number, bank } => {
                let unit = m.profile().global_parameter(*bank, *number).and_then(|p| p.unit.clone());
                match m.clone().get_global_parameter(*number, *bank) {
                    Ok(v) => unit.map_or(v.to_string(), |u| format!("{v} {u}")),
                    Err(s) => format!("not readable (status {})", s as u8),
                }
            }
            Quantity::Variable(n) => m.user_variable_value(*n as usize).to_string(),
        }
    }
}
