//! Mnemonic text of single instructions: the operand layout of every
//! mnemonic, its symbolic operands, and a one-line parser and formatter.
//!
//! The parser accepts what a person types for one direct-mode command
//! (`MVP ABS, 0, 90000`, `SAP 4 0 1000`, `GAP 1,0`, `$47` and `0x47`
//! numbers) and the lenient spellings the manuals print (`MVP ABS 2, 10000`,
//! `JC NZ Label` needs a number here, labels are the assembler's). A raw
//! instruction is written as `#136 1 0 0` (opcode, type, motor, value).

use crate::frame::Instruction;
use crate::opcode as op;

/// Which field of the instruction an operand fills.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Operand {
    /// The type byte as a number (parameter, port, coordinate, interrupt…).
    Type,
    /// The type byte given by a symbol from this table (or a number).
    TypeSymbol(&'static [&'static str]),
    /// The motor/bank byte.
    Motor,
    /// The 32-bit value.
    Value,
    /// The 32-bit value holding a program address (a label in source).
    Address,
}

/// MVP and MVPA modes, by type number.
pub const MOVE_MODES: &[&str] = &["ABS", "REL", "COORD"];
/// RFS actions, by type number.
pub const RFS_ACTIONS: &[&str] = &["START", "STOP", "STATUS"];
/// CALC-family operations, by type number.
pub const CALC_OPS: &[&str] = &["ADD", "SUB", "MUL", "DIV", "MOD", "AND", "OR", "XOR", "NOT", "LOAD", "SWAP", "COMP"];
/// JC and CALL conditions, by type number.
pub const CONDITIONS: &[&str] = &["ZE", "NZ", "EQ", "NE", "GT", "GE", "LT", "LE", "ETO", "EAL", "EDV", "EPO"];
/// WAIT conditions, by type number.
pub const WAIT_CONDITIONS: &[&str] = &["TICKS", "POS", "REFSW", "LIMSW", "RFS"];
/// CLE flags, by type number.
pub const ERROR_FLAGS: &[&str] = &["ALL", "ETO", "EAL", "EDV", "EPO", "ESD"];

/// Operands of a mnemonic in source order; `None` for instruction numbers
/// without mnemonic (control commands).
pub fn layout(opcode: u8) -> Option<&'static [Operand]> {
    use Operand::*;
    const MODE: Operand = TypeSymbol(MOVE_MODES);
    const CALC: Operand = TypeSymbol(CALC_OPS);
    const COND: Operand = TypeSymbol(CONDITIONS);
    Some(match opcode {
        op::ROR | op::ROL => &[Motor, Value],
        op::MST | op::ROLA | op::RORA => &[Motor],
        op::MVP => &[MODE, Motor, Value],
        op::MVPA => &[MODE, Motor],
        op::SAP | op::SGP | op::SIO | op::SCO | op::SAC => &[Type, Motor, Value],
        op::GAP | op::STAP | op::RSAP | op::GGP | op::STGP | op::RSGP | op::GIO | op::GCO | op::CCO | op::ACO | op::AAP | op::AGP => {
            &[Type, Motor]
        }
        op::RFS => &[TypeSymbol(RFS_ACTIONS), Motor],
        op::CALC => &[CALC, Value],
        op::COMP | op::SIV => &[Value],
        op::JC | op::CALL => &[COND, Address],
        op::JA | op::CSUB | op::RST => &[Address],
        op::RSUB | op::STOP | op::RETI | op::GIV | op::AIV => &[],
        op::EI | op::DI => &[Type],
        op::WAIT => &[TypeSymbol(WAIT_CONDITIONS), Motor, Value],
        op::CALCX => &[CALC],
        op::CLE => &[TypeSymbol(ERROR_FLAGS)],
        op::VECT => &[Type, Address],
        op::CALCVV | op::CALCV => &[CALC, Motor, Value],
        op::CALCVA | op::CALCAV | op::CALCVX | op::CALCXV => &[CALC, Motor],
        op::DJNZ => &[Type, Address],
        op::UF0..=op::UF7 => &[Type, Motor, Value],
        _ => return None,
    })
}

/// A parse error with the byte column (1-based) where it was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    /// Where, from 1.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for ParseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "column {}: {}", self.column, self.message)
    }
}

impl std::error::Error for ParseError {}

impl From<ParseError> for String {
    fn from(e: ParseError) -> String {
        e.to_string()
    }
}

/// Parses a number as TMCL sources write it: decimal, negative, `$47`,
/// `0x47`, `0b101`.
pub fn parse_number(text: &str) -> Option<i64> {
    let (neg, t) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text.strip_prefix('+').unwrap_or(text)),
    };
    let v = if let Some(h) = t.strip_prefix('$').or_else(|| t.strip_prefix("0x")).or_else(|| t.strip_prefix("0X")) {
        i64::from_str_radix(h, 16).ok()?
    } else if let Some(b) = t.strip_prefix("0b").or_else(|| t.strip_prefix("0B")) {
        i64::from_str_radix(b, 2).ok()?
    } else if !t.is_empty() && t.bytes().all(|c| c.is_ascii_digit()) {
        t.parse().ok()?
    } else {
        return None;
    };
    Some(if neg { -v } else { v })
}

/// Splits operand text at commas and blanks, keeping the column of each
/// token.
pub fn tokens(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in text.char_indices() {
        let sep = c == ',' || c.is_whitespace();
        match (sep, start) {
            (true, Some(s)) => {
                out.push((s, &text[s..i]));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, &text[s..]));
    }
    out
}

fn symbol_index(table: &[&str], name: &str) -> Option<u8> {
    table.iter().position(|s| s.eq_ignore_ascii_case(name)).map(|p| p as u8)
}

/// Parses one instruction with numeric operands (no labels, no constants).
pub fn parse_line(line: &str) -> Result<Instruction, ParseError> {
    let toks = tokens(line);
    let err = |column: usize, message: String| ParseError { column: column + 1, message };
    let Some(&(c0, head)) = toks.first() else {
        return Err(err(0, "empty command".into()));
    };
    if let Some(raw) = head.strip_prefix('#') {
        // Raw form: #opcode type motor value
        let mut fields = vec![(c0 + 1, raw)];
        fields.extend(toks[1..].iter().copied());
        if fields.len() != 4 {
            return Err(err(c0, "a raw instruction is #opcode type motor value".into()));
        }
        let mut n = [0i64; 4];
        for (k, (c, t)) in fields.iter().enumerate() {
            n[k] = parse_number(t).ok_or_else(|| err(*c, format!("'{t}' is not a number")))?;
        }
        let byte = |k: usize| -> Result<u8, ParseError> {
            u8::try_from(n[k]).map_err(|_| err(fields[k].0, format!("{} does not fit in a byte", n[k])))
        };
        return Ok(Instruction::new(
            byte(0)?,
            byte(1)?,
            byte(2)?,
            to_i32(n[3]).ok_or_else(|| err(fields[3].0, "value out of 32-bit range".into()))?,
        ));
    }
    if let Some(opcode) = (0..=255u8).find(|&o| op::boot_name(o).is_some_and(|n| n.eq_ignore_ascii_case(head))) {
        return boot_line(opcode, &toks[1..]).map_err(|(c, m)| err(c, m));
    }
    let opcode = op::from_mnemonic(head).ok_or_else(|| {
        let hint = crate::suggest::suggestion(head, (0..=255u8).filter_map(op::mnemonic));
        err(c0, format!("unknown command '{head}'{hint}"))
    })?;
    let layout = layout(opcode).expect("every mnemonic has a layout");
    let operands = &toks[1..];
    if operands.len() != layout.len() {
        let end = line.trim_end().len();
        let at = operands.get(layout.len()).map_or(end, |t| t.0);
        return Err(err(at, format!("{head} takes {} operand(s), found {}", layout.len(), operands.len())));
    }
    let mut ins = Instruction::new(opcode, 0, 0, 0);
    for (&(col, text), &kind) in operands.iter().zip(layout) {
        let number = || parse_number(text).ok_or_else(|| err(col, format!("'{text}' is not a number")));
        let byte = |v: i64| u8::try_from(v).map_err(|_| err(col, format!("{v} is out of range 0…255")));
        match kind {
            Operand::Type => ins.kind = byte(number()?)?,
            Operand::TypeSymbol(table) => {
                ins.kind = match symbol_index(table, text) {
                    Some(k) => k,
                    None => byte(number().map_err(|_| err(col, format!("'{text}' is not one of {}", table.join(" "))))?)?,
                }
            }
            Operand::Motor => ins.motor = byte(number()?)?,
            Operand::Value | Operand::Address => {
                ins.value = to_i32(number()?).ok_or_else(|| err(col, format!("'{text}' is out of 32-bit range")))?;
            }
        }
    }
    Ok(ins)
}

/// Values from −2^31 to 2^32−1 are accepted; the upper half wraps to the
/// negative numbers the wire carries.
fn to_i32(v: i64) -> Option<i32> {
    if (i64::from(i32::MIN)..=i64::from(u32::MAX)).contains(&v) { Some(v as u32 as i32) } else { None }
}

/// Whether the operands of the instruction's mnemonic cover every non-zero
/// field (a field the mnemonic has no operand for must be zero).
pub fn shows_every_field(ins: Instruction) -> bool {
    let layout = layout(ins.opcode).unwrap_or(&[]);
    let shows = |f: fn(&Operand) -> bool| layout.iter().any(f);
    (ins.kind == 0 || shows(|o| matches!(o, Operand::Type | Operand::TypeSymbol(_))))
        && (ins.motor == 0 || shows(|o| matches!(o, Operand::Motor)))
        && (ins.value == 0 || shows(|o| matches!(o, Operand::Value | Operand::Address)))
}

/// Formats an instruction as source text. `label` names jump targets;
/// pass `|a| a.to_string()` for plain addresses.
pub fn format_with(ins: Instruction, label: impl Fn(i32) -> String) -> String {
    if let Some(name) = op::boot_name(ins.opcode) {
        let (kind, motor, value) = op::BOOT_MAGIC;
        if ins.opcode == op::BOOT && (ins.kind, ins.motor, ins.value as u32) == (kind, motor, value) {
            return name.to_string();
        }
        return format!("{name} {}, {}, {}", ins.kind, ins.motor, ins.value as u32);
    }
    let Some(name) = op::mnemonic(ins.opcode) else {
        return format!("#{} {} {} {}", ins.opcode, ins.kind, ins.motor, ins.value);
    };
    let layout = layout(ins.opcode).unwrap_or(&[]);
    if !shows_every_field(ins) {
        // The text would not give the same instruction back.
        return format!("#{} {} {} {}", ins.opcode, ins.kind, ins.motor, ins.value);
    }
    let parts: Vec<String> = layout
        .iter()
        .map(|k| match k {
            Operand::Type => ins.kind.to_string(),
            Operand::TypeSymbol(table) => table.get(ins.kind as usize).map_or(ins.kind.to_string(), ToString::to_string),
            Operand::Motor => ins.motor.to_string(),
            Operand::Value => ins.value.to_string(),
            Operand::Address => label(ins.value),
        })
        .collect();
    if parts.is_empty() { name.to_string() } else { format!("{name} {}", parts.join(", ")) }
}

/// A bootloader command by name (`BOOT_GET_INFO 1`, `BOOT_WRITE_BUFFER 3,
/// 0, 0x12345678`): type, motor and value, each 0 when left out; `BOOT`
/// alone carries the key that 242 needs.
fn boot_line(opcode: u8, operands: &[(usize, &str)]) -> Result<Instruction, (usize, String)> {
    if operands.len() > 3 {
        return Err((operands[3].0, format!("{} takes type, motor and value at most", op::name(opcode))));
    }
    if opcode == op::BOOT && operands.is_empty() {
        let (kind, motor, value) = op::BOOT_MAGIC;
        return Ok(Instruction::new(opcode, kind, motor, value as i32));
    }
    let mut n = [0i64; 3];
    for (k, &(c, t)) in operands.iter().enumerate() {
        n[k] = parse_number(t).ok_or_else(|| (c, format!("'{t}' is not a number")))?;
    }
    let byte = |k: usize| u8::try_from(n[k]).map_err(|_| (operands[k].0, format!("{} does not fit in a byte", n[k])));
    let value = to_i32(n[2]).ok_or_else(|| (operands[2].0, "value out of 32-bit range".to_string()))?;
    Ok(Instruction::new(opcode, byte(0)?, byte(1)?, value))
}

/// An instruction as a source line (`MVP ABS, 0, 51200`), addresses as
/// numbers.
pub fn format(ins: Instruction) -> String {
    format_with(ins, |a| a.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bootloader_commands_by_name() {
        assert_eq!(parse_line("BOOT").unwrap(), Instruction::new(242, 0x81, 0x92, 0xA3B4_C5D6_u32 as i32));
        assert_eq!(parse_line("boot_get_info 1").unwrap(), Instruction::new(206, 1, 0, 0));
        assert_eq!(parse_line("BOOT_WRITE_BUFFER 3, 1, 0xDEADBEEF").unwrap(), Instruction::new(201, 3, 1, 0xDEAD_BEEF_u32 as i32));
        assert_eq!(parse_line("BOOT_ERASE_ALL").unwrap(), Instruction::new(200, 0, 0, 0));
        assert_eq!(parse_line("BOOT_GET_INFO 1 2 3 4").unwrap_err().column, 21);
        assert_eq!(op::name(203), "BOOT_GET_CHECKSUM");
        for line in ["BOOT", "BOOT_WRITE_BUFFER 3, 1, 3735928559", "BOOT_GET_INFO 2, 0, 0"] {
            assert_eq!(format(parse_line(line).unwrap()), line);
        }
    }

    fn bytes(line: &str) -> [u8; 9] {
        crate::Request::new(1, parse_line(line).unwrap()).encode()
    }

    #[test]
    fn a_mistyped_command_gets_a_suggestion() {
        let e = parse_line("GAPP 1, 0").unwrap_err();
        assert_eq!((e.column, e.message.as_str()), (1, "unknown command 'GAPP' (did you mean 'GAP'?)"));
        assert_eq!(parse_line("frobnicate 1").unwrap_err().message, "unknown command 'frobnicate'");
    }

    #[test]
    fn manual_frames_from_mnemonics() {
        assert_eq!(bytes("MVP ABS, 0, 90000"), [0x01, 0x04, 0x00, 0x00, 0x00, 0x01, 0x5F, 0x90, 0xF5]);
        assert_eq!(bytes("MVP ABS 0, 90000"), bytes("MVP ABS, 0, 90000"));
        assert_eq!(bytes("CALC MUL, -5000"), [0x01, 0x13, 0x02, 0x00, 0xFF, 0xFF, 0xEC, 0x78, 0x78]);
        assert_eq!(bytes("CALCVV SUB, 65, 42"), [0x01, 0x28, 0x01, 0x41, 0x00, 0x00, 0x00, 0x2A, 0x95]);
        assert_eq!(bytes("EI 255"), [0x01, 0x19, 0xFF, 0x00, 0x00, 0x00, 0x00, 0x00, 0x19]);
        assert_eq!(bytes("SGP $42, 0, 0x3"), [0x01, 0x09, 0x42, 0x00, 0x00, 0x00, 0x00, 0x03, 0x4F]);
        assert_eq!(bytes("#138 1 0 1"), [0x01, 0x8A, 0x01, 0x00, 0x00, 0x00, 0x00, 0x01, 0x8D]);
    }

    #[test]
    fn formatting_is_lossless() {
        assert_eq!(format(Instruction::new(3, 0, 1, 0)), "MST 1");
        // MST shows no type and no value: a word with them is written raw.
        assert_eq!(format(Instruction::new(3, 61, 0, 0)), "#3 61 0 0");
        assert_eq!(format(Instruction::new(28, 0, 0, 5)), "#28 0 0 5");
        for ins in [Instruction::new(3, 61, 0, 0), Instruction::new(19, 0, 4, 7), Instruction::new(27, 1, 0, -3)] {
            assert_eq!(parse_line(&format(ins)), Ok(ins));
        }
    }

    #[test]
    fn errors_name_the_column() {
        let e = parse_line("SAP 4, 0, x12").unwrap_err();
        assert_eq!(e.column, 11);
        let e = parse_line("FOO 1").unwrap_err();
        assert_eq!(e.column, 1);
        let e = parse_line("MVP UP, 0, 1").unwrap_err();
        assert_eq!(e.column, 5);
        assert!(e.message.contains("ABS REL COORD"));
        assert!(parse_line("GAP 1").is_err());
        assert!(parse_line("SAP 256, 0, 1").is_err());
    }

    #[test]
    fn format_round_trips() {
        for line in ["MVP ABS, 0, 90000", "WAIT POS, 0, 0", "CALCX MUL", "RSUB", "CLE ETO", "#136 0 0 0"] {
            assert_eq!(format(parse_line(line).unwrap()), line);
        }
    }
}
