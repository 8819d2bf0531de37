//! A console line into an instruction: a mnemonic line as `tmclsim send`
//! takes it, where the type operand of SAP/GAP/STAP/RSAP/AAP and
//! SGP/GGP/STGP/RSGP/AGP may also be a parameter's name.

use crate::names::{Table, find, parameters, snake, table_of};
use tmclsim_profile::Profile;
use tmclsim_protocol::mnemonic::{self, ParseError};
use tmclsim_protocol::{Instruction, opcode, suggest};

/// A parameter command's type operand that is a word, not a number: its
/// table, column, the word, and the number after it (the bank of a global
/// parameter).
struct NameOperand<'a> {
    table: Table,
    column: usize,
    word: &'a str,
    next: Option<i64>,
}

fn name_operand(line: &str) -> Option<NameOperand<'_>> {
    match mnemonic::tokens(line).as_slice() {
        [(_, head), (column, word), rest @ ..] if mnemonic::parse_number(word).is_none() => {
            let table = opcode::from_mnemonic(head).and_then(table_of)?;
            Some(NameOperand { table, column: *column, word, next: rest.first().and_then(|(_, b)| mnemonic::parse_number(b)) })
        }
        _ => None,
    }
}

/// Whether the line names a parameter (SAP, GGP, … with a word for its
/// type): it needs a profile to be parsed.
pub fn names_a_parameter(line: &str) -> bool {
    name_operand(line).is_some()
}

/// Parses a line; parameter names are looked up in `profile` when there
/// is one.
pub fn parse(line: &str, profile: Option<&Profile>) -> Result<Instruction, ParseError> {
    let (Some(NameOperand { table, column, word, next: bank }), Some(profile)) = (name_operand(line), profile) else {
        return mnemonic::parse_line(line);
    };
    let bank = match table {
        Table::Global => bank.and_then(|b| u8::try_from(b).ok()),
        Table::Axis => None,
    };
    let Some((_, p)) = find(profile, table, word, bank) else {
        let names: Vec<String> = parameters(profile, table).iter().map(|(_, p)| snake(p.label())).collect();
        let what = if table == Table::Axis { "axis" } else { "global" };
        let in_bank = bank.map_or(String::new(), |b| format!(" in bank {b}"));
        return Err(ParseError {
            column: column + 1,
            message: format!(
                "the {} has no {what} parameter '{word}'{in_bank}{}",
                profile.module.name,
                suggest::suggestion(word, names.iter().map(String::as_str))
            ),
        });
    };
    let replaced = format!("{}{}{}", &line[..column], p.number, &line[column + word.len()..]);
    mnemonic::parse_line(&replaced).map_err(|mut e| {
        // Columns after the name refer to the line as typed.
        if e.column > column + 1 {
            e.column = (e.column + word.len()).saturating_sub(p.number.to_string().len());
        }
        e
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_stand_for_numbers() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let p = Some(p.as_ref());
        assert_eq!(parse("GAP actual_position, 0", p), Ok(Instruction::new(6, 1, 0, 0)));
        assert_eq!(parse("sap maximum_positioning_speed 0 1000", p), Ok(Instruction::new(5, 4, 0, 1000)));
        assert_eq!(parse("GGP tmcl_tick_timer, 0", p), Ok(Instruction::new(10, 132, 0, 0)));
        assert_eq!(parse("MVP ABS, 0, 51200", p), Ok(Instruction::new(4, 0, 0, 51200)));
        assert_eq!(parse("GAP 141, 0", p), Ok(Instruction::new(6, 141, 0, 0)));
        let e = parse("GAP actual_postion, 0", p).unwrap_err();
        assert_eq!(e.column, 5);
        assert_eq!(e.message, "the TMCM-1141 has no axis parameter 'actual_postion' (did you mean 'actual_position'?)");
        let e = parse("GAP actual_position, 0, 7", p).unwrap_err();
        assert_eq!((e.column, e.message.as_str()), (25, "GAP takes 2 operand(s), found 3"));
        // Without a profile, numbers only.
        assert!(parse("GAP actual_position, 0", None).unwrap_err().message.contains("not a number"));
    }
}
