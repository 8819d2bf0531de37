//! Completion for the console's line editor: mnemonics first, then the
//! symbols and parameter names the mnemonic takes.

use rustyline::completion::{Completer, Pair};
use rustyline::highlight::Highlighter;
use rustyline::hint::Hinter;
use rustyline::validate::Validator;
use std::sync::Arc;
use tmclsim_firmware::Profile;
use tmclsim_host::names::{parameters, snake, table_of};
use tmclsim_protocol::mnemonic::{self, Operand};
use tmclsim_protocol::opcode;

/// The console's own commands, completed beside the mnemonics.
pub const CONSOLE_COMMANDS: &[&str] = &["help", "quit"];

pub struct Completion {
    pub profile: Option<Arc<Profile>>,
}

impl Completion {
    /// The words that complete `line` up to `pos`: where the word starts,
    /// and the candidates.
    pub fn candidates(&self, line: &str, pos: usize) -> (usize, Vec<String>) {
        let before = &line[..pos];
        let start = before.rfind(|c: char| c == ',' || c.is_whitespace()).map_or(0, |i| i + 1);
        let word = &before[start..];
        let words = mnemonic::tokens(&before[..start]);
        let mut out: Vec<String> = match words.first() {
            None => {
                // The bootloader's commands by name too (docs/behaviour.md rule 99).
                let mnemonics = (0..=255u8).filter_map(|op| opcode::mnemonic(op).or_else(|| opcode::boot_name(op))).map(str::to_string);
                let upper = word.chars().next().is_none_or(|c| c.is_ascii_uppercase());
                let commands = CONSOLE_COMMANDS.iter().map(ToString::to_string);
                mnemonics.map(|m| if upper { m } else { m.to_ascii_lowercase() }).chain(commands).collect()
            }
            Some((_, head)) if *head == "help" => self.parameter_names(None),
            Some((_, head)) => {
                let Some(op) = opcode::from_mnemonic(head) else { return (start, Vec::new()) };
                match mnemonic::layout(op).and_then(|l| l.get(words.len() - 1)) {
                    Some(Operand::TypeSymbol(table)) => table.iter().map(ToString::to_string).collect(),
                    Some(Operand::Type) if table_of(op).is_some() => self.parameter_names(Some(op)),
                    _ => Vec::new(),
                }
            }
        };
        out.retain(|c| c.to_ascii_lowercase().starts_with(&word.to_ascii_lowercase()));
        out.sort();
        out.dedup();
        (start, out)
    }

    fn parameter_names(&self, op: Option<u8>) -> Vec<String> {
        let Some(profile) = &self.profile else { return Vec::new() };
        let tables = match op.and_then(table_of) {
            Some(t) => vec![t],
            None => vec![tmclsim_host::names::Table::Axis, tmclsim_host::names::Table::Global],
        };
        tables.into_iter().flat_map(|t| parameters(profile, t).into_iter().map(|(_, p)| snake(&p.name))).collect()
    }
}

impl Completer for Completion {
    type Candidate = Pair;

    fn complete(&self, line: &str, pos: usize, _: &rustyline::Context<'_>) -> rustyline::Result<(usize, Vec<Pair>)> {
        let (start, words) = self.candidates(line, pos);
        Ok((start, words.into_iter().map(|w| Pair { display: w.clone(), replacement: w }).collect()))
    }
}

impl Hinter for Completion {
    type Hint = String;
}

impl Highlighter for Completion {}

impl Validator for Completion {}

impl rustyline::Helper for Completion {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mnemonics_symbols_and_parameter_names() {
        let c = Completion { profile: Some(Profile::built_in("tmcm-1141").unwrap()) };
        assert_eq!(c.candidates("GA", 2), (0, vec!["GAP".to_string()]));
        assert_eq!(c.candidates("mv", 2), (0, vec!["mvp".to_string(), "mvpa".to_string()]));
        assert_eq!(c.candidates("MVP ", 4).1, vec!["ABS", "COORD", "REL"]);
        assert_eq!(c.candidates("GAP actual_p", 12), (4, vec!["actual_position".to_string()]));
        assert!(c.candidates("GGP tmcl_t", 10).1.contains(&"tmcl_tick_timer".to_string()));
        assert!(!c.candidates("GAP tmcl_t", 10).1.contains(&"tmcl_tick_timer".to_string()), "axis names only");
        assert_eq!(c.candidates("GAP 1, ", 7).1, Vec::<String>::new());
        assert_eq!(c.candidates("he", 2).1, vec!["help"]);
        assert_eq!(c.candidates("BOOT_GET_", 9).1, vec!["BOOT_GET_CHECKSUM", "BOOT_GET_INFO"]);
    }
}
