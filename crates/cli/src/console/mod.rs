//! `tmclsim console`: an interactive direct-mode session with any TMCL
//! module (virtual or real): mnemonics with parameter names, history and
//! completion on a terminal, replies with names and units, scripts from
//! standard input.

mod complete;

use crate::client::LinkArgs;
use std::io::{BufRead, IsTerminal};
use std::process::ExitCode;
use std::sync::Arc;
use tmclsim_firmware::Profile;
use tmclsim_host::{line, names, reply};
use tmclsim_protocol::{mnemonic, opcode};

#[derive(clap::Args)]
pub struct ConsoleArgs {
    #[command(flatten)]
    pub link: LinkArgs,
    /// How long to wait for each reply, in milliseconds.
    #[arg(long, value_name = "MS", default_value_t = 1000)]
    pub timeout: u64,
    /// The module's profile, for parameter names and units (default: the
    /// one of the type the module reports with 136).
    #[arg(long)]
    pub module: Option<String>,
}

const HELP: &str = "\
Type a command as the manuals write it; parameter names may stand for
numbers in SAP/GAP/STAP/RSAP/AAP and SGP/GGP/STGP/RSGP/AGP:
  GAP actual_position, 0        GAP 1, 0
  SAP maximum_positioning_speed, 0, 1000
  MVP ABS, 0, 51200             ROR 0, 500        MST 0
  GGP tmcl_tick_timer, 0             GIO 0, 0          #136 1 0 0 (raw: opcode type motor value)
help MNEMONIC shows its operands, help NAME|NUMBER a parameter; quit leaves.
Tab completes mnemonics, symbols and parameter names.";

pub fn run(args: ConsoleArgs) -> Result<ExitCode, String> {
    let mut client = args.link.open(crate::millis(args.timeout))?;
    let profile = crate::client::profile(&mut client, args.module.as_deref())?;
    let link = args.link.link.tcp.as_deref().map_or_else(|| args.link.link.port.clone().unwrap_or_default(), |t| format!("TCP {t}"));
    match &profile {
        Some(p) => println!(
            "{} (firmware V{}.{:02}) at address {} on {link}; help for help, quit to leave",
            p.module.name, p.module.firmware[0], p.module.firmware[1], args.link.address
        ),
        None => println!("a module at address {} on {link}; help for help, quit to leave", args.link.address),
    }
    let mut session = Session { client, profile, address: args.link.address, failures: 0 };
    if std::io::stdin().is_terminal() {
        session.interactive()?;
    } else {
        let mut input = std::io::stdin().lock();
        let mut number = 0;
        while let Some(line) = read_line(&mut input, MAX_LINE).map_err(|e| e.to_string())? {
            number += 1;
            let Some(line) = line else {
                eprintln!("error: line {number} is longer than {MAX_LINE} bytes; it was skipped");
                session.failures += 1;
                continue;
            };
            if !line.trim().is_empty() {
                println!("> {}", line.trim());
            }
            if !session.line(&line)? {
                break;
            }
        }
    }
    Ok(if session.failures == 0 { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// Longest line of a script (a TMCL command takes a few dozen bytes).
pub const MAX_LINE: usize = 4096;

/// Reads one line of at most `max` bytes: `None` at the end of the input,
/// `Some(None)` for a longer line, which is read to its end and dropped
/// without being held in memory.
fn read_line(input: &mut impl BufRead, max: usize) -> std::io::Result<Option<Option<String>>> {
    let mut line = Vec::new();
    let mut too_long = false;
    loop {
        let chunk = input.fill_buf()?;
        if chunk.is_empty() {
            return Ok((too_long || !line.is_empty()).then(|| (!too_long).then(|| String::from_utf8_lossy(&line).into_owned())));
        }
        let (taken, ended) = match chunk.iter().position(|&b| b == b'\n') {
            Some(i) => (i, true),
            None => (chunk.len(), false),
        };
        if !too_long && line.len() + taken <= max {
            line.extend_from_slice(&chunk[..taken]);
        } else {
            too_long = true;
            line = Vec::new();
        }
        input.consume(taken + usize::from(ended));
        if ended {
            return Ok(Some((!too_long).then(|| String::from_utf8_lossy(&line).trim_end_matches('\r').to_string())));
        }
    }
}

struct Session {
    client: crate::client::Client,
    profile: Option<Arc<Profile>>,
    address: u8,
    failures: u32,
}

impl Session {
    fn interactive(&mut self) -> Result<(), String> {
        use rustyline::error::ReadlineError;
        let config = rustyline::Config::builder().auto_add_history(true).max_history_size(1000).map_err(|e| e.to_string())?.build();
        let mut editor =
            rustyline::Editor::<complete::Completion, rustyline::history::FileHistory>::with_config(config).map_err(|e| e.to_string())?;
        editor.set_helper(Some(complete::Completion { profile: self.profile.clone() }));
        // The home directory: HOME, or on Windows (where it is rarely set)
        // the user's profile.
        let home = std::env::var_os("HOME").or_else(|| if cfg!(windows) { std::env::var_os("USERPROFILE") } else { None });
        let history = home.map(|h| std::path::PathBuf::from(h).join(".tmclsim_history"));
        if let Some(h) = &history {
            let _ = editor.load_history(h);
        }
        loop {
            match editor.readline("tmcl> ") {
                Ok(line) => {
                    if !self.line(&line)? {
                        break;
                    }
                }
                Err(ReadlineError::Interrupted | ReadlineError::Eof) => break,
                Err(e) => return Err(e.to_string()),
            }
        }
        if let Some(h) = &history {
            let _ = editor.save_history(h);
        }
        Ok(())
    }

    /// One line; false to leave.
    fn line(&mut self, text: &str) -> Result<bool, String> {
        let text = text.trim();
        let words: Vec<&str> = text.split_whitespace().collect();
        match words.as_slice() {
            [] => {}
            // Comments: `// …`, and `#` followed by a space or nothing
            // (`#136 0 0 0` is a raw command).
            [c, ..] if c.starts_with("//") || *c == "#" => {}
            ["quit" | "exit" | "q"] => return Ok(false),
            ["help" | "?"] => println!("{HELP}"),
            ["help", topic] => println!("{}", self.help(topic)),
            _ => self.command(text)?,
        }
        Ok(true)
    }

    fn command(&mut self, text: &str) -> Result<(), String> {
        let ins = match line::parse(text, self.profile.as_deref()) {
            Ok(ins) => ins,
            Err(e) => {
                self.failures += 1;
                println!("{}^ column {}: {}", " ".repeat(e.column.saturating_sub(1) + 6), e.column, e.message);
                return Ok(());
            }
        };
        if ins.opcode == opcode::FACTORY_DEFAULTS {
            self.client.send_only(ins)?;
            println!("sent (137 sends no reply)");
            return Ok(());
        }
        match self.client.exchange(ins) {
            Ok(raw) => {
                let line = reply::describe(ins, &raw, self.address, self.profile.as_deref());
                if line.starts_with("error") || line.starts_with("status") || line.contains("checksum is wrong") {
                    self.failures += 1;
                }
                println!("{line}");
            }
            Err(e) if e.is_unanswered() => {
                self.failures += 1;
                println!("{e}");
            }
            Err(e) => return Err(e.into()),
        }
        Ok(())
    }

    /// `help MNEMONIC` or `help NAME|NUMBER`.
    fn help(&self, topic: &str) -> String {
        if let Some(op) = (0..=255u8).find(|&o| opcode::boot_name(o).is_some_and(|n| n.eq_ignore_ascii_case(topic))) {
            let operands = if op == opcode::BOOT { " (alone: with its key, 0x81, 0x92, 0xA3B4C5D6)" } else { " [TYPE[, MOTOR[, VALUE]]]" };
            return format!("{} (instruction {op}, the bootloader's): {}{operands}", opcode::name(op), opcode::name(op));
        }
        if let Some(op) = opcode::from_mnemonic(topic) {
            let operands: Vec<String> = mnemonic::layout(op)
                .unwrap_or(&[])
                .iter()
                .map(|o| match o {
                    mnemonic::Operand::Type => "TYPE".to_string(),
                    mnemonic::Operand::TypeSymbol(t) => t.join("|"),
                    mnemonic::Operand::Motor => "MOTOR/BANK".to_string(),
                    mnemonic::Operand::Value => "VALUE".to_string(),
                    mnemonic::Operand::Address => "ADDRESS".to_string(),
                })
                .collect();
            return format!("{} (instruction {op}): {} {}", opcode::name(op), topic.to_ascii_uppercase(), operands.join(", "));
        }
        let Some(profile) = &self.profile else { return format!("'{topic}' is no mnemonic (parameters need a profile)") };
        let mut found = Vec::new();
        for table in [names::Table::Axis, names::Table::Global] {
            for (bank, p) in names::parameters(profile, table) {
                let number = mnemonic::parse_number(topic);
                if number.map_or_else(|| names::key(&p.name) == names::key(topic), |n| n == i64::from(p.number)) {
                    let which = if table == names::Table::Axis { "AP".to_string() } else { format!("GP bank {bank}:") };
                    found.push(format!(
                        "{which} {} {} ({}): access {}, {}…{}, default {}{}",
                        p.number,
                        p.name,
                        names::snake(&p.name),
                        p.access,
                        p.min,
                        p.max,
                        p.default,
                        p.unit.as_ref().map_or(String::new(), |u| format!(", unit {u}"))
                    ));
                }
            }
        }
        if found.is_empty() {
            format!("'{topic}' is neither a mnemonic nor a parameter of the {}", profile.module.name)
        } else {
            found.join("\n")
        }
    }
}
