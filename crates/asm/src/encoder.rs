//! The encoder: a mnemonic and its operand expressions into the seven bytes
//! of an [`Instruction`], following the operand layout of
//! `tmclsim_protocol::mnemonic::layout`.
//!
//! Checks here are the ones the protocol itself defines: the operand count,
//! symbolic operands, byte and 32-bit ranges, and whether the instruction
//! has the type (`Command::decode`). What a particular module has is
//! checked in `check.rs`.

use tmclsim_protocol::mnemonic::{CALC_OPS, CONDITIONS, ERROR_FLAGS, MOVE_MODES, Operand, RFS_ACTIONS, WAIT_CONDITIONS, layout};
use tmclsim_protocol::{Command, Instruction, opcode as op};

use crate::diagnostic::{Loc, Reporter, suggestion, unknown_instruction};
use crate::eval::{Evaluator, Expect, Reported};
use crate::expr::Expr;

/// An encoded instruction and the columns of its fields in the source, for
/// the module checks' messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Encoded {
    pub instruction: Instruction,
    pub mnemonic_column: usize,
    pub type_column: usize,
    pub motor_column: usize,
    pub value_column: usize,
}

const SYMBOL_TABLES: &[(&[&str], &str)] = &[
    (MOVE_MODES, "move mode"),
    (RFS_ACTIONS, "RFS action"),
    (CALC_OPS, "calculation"),
    (CONDITIONS, "condition"),
    (WAIT_CONDITIONS, "wait condition"),
    (ERROR_FLAGS, "error flag"),
];

fn table_name(table: &[&str]) -> &'static str {
    SYMBOL_TABLES.iter().find(|(t, _)| *t == table).map_or("symbol", |(_, n)| n)
}

/// What an operand of this instruction is called in messages.
pub fn operand_name(opcode: u8, operand: Operand) -> String {
    match operand {
        Operand::TypeSymbol(table) => table.join("|"),
        Operand::Address => "label".into(),
        Operand::Type => match opcode {
            op::SAP | op::GAP | op::STAP | op::RSAP | op::AAP | op::SGP | op::GGP | op::STGP | op::RSGP | op::AGP => "parameter",
            op::SIO | op::GIO => "port",
            op::SCO | op::GCO | op::CCO | op::ACO => "coordinate",
            op::EI | op::DI | op::VECT => "interrupt",
            op::DJNZ => "user variable",
            _ => "type",
        }
        .into(),
        Operand::Motor => match opcode {
            op::SGP | op::GGP | op::STGP | op::RSGP | op::AGP | op::SIO | op::GIO => "bank",
            op::CALCVV | op::CALCVA | op::CALCAV | op::CALCVX | op::CALCXV | op::CALCV => "user variable",
            _ => "motor",
        }
        .into(),
        Operand::Value => match opcode {
            op::ROR | op::ROL => "velocity",
            op::MVP => "position",
            op::WAIT => "ticks",
            op::CALCVV => "user variable",
            _ => "value",
        }
        .into(),
    }
}

/// `ABS|REL|COORD, motor, position`
pub fn operand_summary(opcode: u8) -> String {
    layout(opcode).unwrap_or(&[]).iter().map(|&o| operand_name(opcode, o)).collect::<Vec<_>>().join(", ")
}

/// A value that does not fit its field of the instruction word.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FieldError {
    /// A byte field (type, motor, a raw word's opcode) outside 0…255.
    Byte {
        /// The field, as messages name it (`motor`, `type`).
        what: String,
        /// The value given.
        value: i64,
    },
    /// A value outside −2^31…2^32−1.
    Word(i64),
}

impl std::fmt::Display for FieldError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FieldError::Byte { what, value } => write!(f, "{what} {value} is out of range 0...255"),
            FieldError::Word(value) => write!(f, "value {value} does not fit in 32 bits (-2147483648...4294967295)"),
        }
    }
}

impl std::error::Error for FieldError {}

/// Fits a value into a byte field.
fn byte(value: i64, what: &str) -> Result<u8, FieldError> {
    u8::try_from(value).map_err(|_| FieldError::Byte { what: what.to_string(), value })
}

/// Fits a value into the 32-bit field: −2^31…2^32−1, the upper half wraps
/// to the negative numbers the wire carries (as `protocol::mnemonic` does).
pub fn word(value: i64) -> Result<i32, FieldError> {
    if (i64::from(i32::MIN)..=i64::from(u32::MAX)).contains(&value) { Ok(value as u32 as i32) } else { Err(FieldError::Word(value)) }
}

/// Encodes an instruction line; reports every problem it finds.
#[allow(clippy::too_many_arguments)]
pub fn encode(
    mnemonic: &str,
    column: usize,
    operands: &[Expr],
    end_column: usize,
    loc: Loc,
    evaluator: &mut Evaluator,
    reporter: &mut Reporter,
) -> Result<Encoded, Reported> {
    let Some(opcode) = op::from_mnemonic(mnemonic) else {
        reporter.error_with(loc, column, |budget| unknown_instruction(mnemonic, operands.is_empty(), budget));
        return Err(Reported);
    };
    let slots = layout(opcode).unwrap_or(&[]);
    let name = op::mnemonic(opcode).unwrap_or(mnemonic);
    if operands.len() != slots.len() {
        let at = operands.get(slots.len()).map_or(end_column, |e| e.column);
        let message = match slots.len() {
            0 => format!("{name} takes no operands, found {}", operands.len()),
            n => {
                format!("{name} takes {n} operand{} ({}), found {}", if n == 1 { "" } else { "s" }, operand_summary(opcode), operands.len())
            }
        };
        reporter.error(loc, at, message);
        return Err(Reported);
    }
    let mut out = Encoded {
        instruction: Instruction::new(opcode, 0, 0, 0),
        mnemonic_column: column,
        type_column: column,
        motor_column: column,
        value_column: column,
    };
    let mut failed = false;
    for (&slot, expr) in slots.iter().zip(operands) {
        let what = operand_name(opcode, slot);
        match operand(opcode, slot, &what, expr, loc, evaluator, reporter) {
            Ok(v) => match slot {
                Operand::Type | Operand::TypeSymbol(_) => {
                    out.instruction.kind = v as u8;
                    out.type_column = expr.column;
                }
                Operand::Motor => {
                    out.instruction.motor = v as u8;
                    out.motor_column = expr.column;
                }
                Operand::Value | Operand::Address => {
                    out.instruction.value = v as i32;
                    out.value_column = expr.column;
                }
            },
            Err(Reported) => failed = true,
        }
    }
    if failed {
        return Err(Reported);
    }
    if Command::decode(out.instruction).is_err() {
        reporter.error(loc, out.type_column, wrong_type_message(opcode, out.instruction.kind));
        return Err(Reported);
    }
    Ok(out)
}

/// Evaluates one operand for its slot; the result fits the field (bytes
/// 0…255, values as the 32-bit word).
#[allow(clippy::too_many_arguments)]
fn operand(
    opcode: u8,
    slot: Operand,
    what: &str,
    expr: &Expr,
    loc: Loc,
    evaluator: &mut Evaluator,
    reporter: &mut Reporter,
) -> Result<i64, Reported> {
    if let (Operand::TypeSymbol(table), Some(word)) = (slot, expr.as_name()) {
        if let Some(i) = table.iter().position(|s| s.eq_ignore_ascii_case(word)) {
            return Ok(i as i64);
        }
        if !evaluator.is_defined(word) {
            reporter.error_with(loc, expr.column, |budget| {
                format!("'{word}' is not a {} ({}){}", table_name(table), table.join(", "), suggestion(word, table.iter().copied(), budget))
            });
            return Err(Reported);
        }
    }
    let misplaced_symbol = expr
        .as_name()
        .filter(|n| slot != Operand::Address && !evaluator.is_defined(n))
        .and_then(|word| symbol_table_of(opcode, word).map(|table| (word, table)));
    if let Some((word, table)) = misplaced_symbol {
        let name = op::mnemonic(opcode).unwrap_or("?");
        let number = if matches!(what, "value" | "position" | "velocity" | "ticks") { "" } else { " number" };
        let message = format!("'{word}' is a {}, not a {what}{number} ({name} takes {})", table_name(table), operand_summary(opcode));
        reporter.error(loc, expr.column, message);
        return Err(Reported);
    }
    let expect = if slot == Operand::Address { Expect::Label } else { Expect::Number };
    let value = evaluator.eval(expr, loc, expect, reporter)?;
    let fitted = match slot {
        Operand::Type | Operand::TypeSymbol(_) | Operand::Motor => byte(value, what).map(i64::from),
        Operand::Value | Operand::Address => word(value).map(i64::from),
    };
    fitted.map_err(|e| {
        reporter.error(loc, expr.column, e.to_string());
        Reported
    })
}

/// The symbol table a word belongs to, preferring this instruction's own.
fn symbol_table_of(opcode: u8, word: &str) -> Option<&'static [&'static str]> {
    let own = layout(opcode).unwrap_or(&[]).iter().filter_map(|o| match o {
        Operand::TypeSymbol(t) => Some(*t),
        _ => None,
    });
    own.chain(SYMBOL_TABLES.iter().map(|(t, _)| *t)).find(|t| t.iter().any(|s| s.eq_ignore_ascii_case(word)))
}

/// "SWAP cannot be used with CALC (valid: ADD, SUB, …)".
fn wrong_type_message(opcode: u8, kind: u8) -> String {
    let name = op::mnemonic(opcode).unwrap_or("?");
    let table = layout(opcode).unwrap_or(&[]).iter().find_map(|o| match o {
        Operand::TypeSymbol(t) => Some(*t),
        _ => None,
    });
    let Some(table) = table else {
        return format!("{name} has no type {kind}");
    };
    let valid: Vec<&str> = table
        .iter()
        .enumerate()
        .filter(|(i, _)| Command::decode(Instruction::new(opcode, *i as u8, 0, 0)).is_ok())
        .map(|(_, s)| *s)
        .collect();
    match table.get(kind as usize) {
        Some(symbol) => format!("{symbol} cannot be used with {name} (valid: {})", valid.join(", ")),
        None => format!("{kind} is not a valid {} for {name} (valid: {})", table_name(table), valid.join(", ")),
    }
}

/// Encodes a raw word (`#db opcode, type, motor, value`).
pub fn encode_raw(
    fields: &[Expr],
    end_column: usize,
    loc: Loc,
    evaluator: &mut Evaluator,
    reporter: &mut Reporter,
) -> Result<Instruction, Reported> {
    if fields.len() != 4 {
        let at = fields.get(4).map_or(end_column, |e| e.column);
        reporter.error(loc, at, format!("a raw word is '#db opcode, type, motor, value' (4 fields), found {}", fields.len()));
        return Err(Reported);
    }
    let mut values = [0i64; 4];
    let mut failed = false;
    for (k, (expr, what)) in fields.iter().zip(["opcode", "type", "motor", "value"]).enumerate() {
        let fitted = evaluator.eval(expr, loc, Expect::Number, reporter).and_then(|v| {
            let r = if k < 3 { byte(v, what).map(i64::from) } else { word(v).map(i64::from) };
            r.map_err(|e| {
                reporter.error(loc, expr.column, e.to_string());
                Reported
            })
        });
        match fitted {
            Ok(v) => values[k] = v,
            Err(Reported) => failed = true,
        }
    }
    if failed {
        return Err(Reported);
    }
    Ok(Instruction::new(values[0] as u8, values[1] as u8, values[2] as u8, values[3] as i32))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The instruction number of a mnemonic, or the diagnostic the
    /// assembler gives for it.
    fn opcode_of(mnemonic: &str, nothing_follows: bool) -> Result<u8, String> {
        let mut unlimited = u64::MAX;
        op::from_mnemonic(mnemonic).ok_or_else(|| unknown_instruction(mnemonic, nothing_follows, &mut unlimited))
    }

    #[test]
    fn names_of_operands() {
        assert_eq!(operand_summary(op::MVP), "ABS|REL|COORD, motor, position");
        assert_eq!(operand_summary(op::SGP), "parameter, bank, value");
        assert_eq!(operand_summary(op::JC), "ZE|NZ|EQ|NE|GT|GE|LT|LE|ETO|EAL|EDV|EPO, label");
        assert_eq!(operand_summary(op::RSUB), "");
    }

    #[test]
    fn mnemonics() {
        assert_eq!(opcode_of("mvp", false), Ok(4));
        assert_eq!(opcode_of("UF7", false), Ok(71));
        assert_eq!(opcode_of("SAC", false), Ok(29));
        assert_eq!(opcode_of("MVPP", false).unwrap_err(), "unknown instruction 'MVPP' (did you mean 'MVP'?)");
        assert!(opcode_of("Start", true).unwrap_err().contains("'Start:'"));
    }

    #[test]
    fn wrong_types() {
        assert_eq!(
            wrong_type_message(op::CALC, 10),
            "SWAP cannot be used with CALC (valid: ADD, SUB, MUL, DIV, MOD, AND, OR, XOR, NOT, LOAD)"
        );
        assert!(wrong_type_message(op::MVP, 7).starts_with("7 is not a valid move mode for MVP"));
    }

    #[test]
    fn words_wrap_like_the_protocol() {
        assert_eq!(word(4294967295), Ok(-1));
        assert_eq!(word(-2147483648), Ok(i32::MIN));
        assert!(word(4294967296).is_err());
        assert!(word(-2147483649).is_err());
    }
}
