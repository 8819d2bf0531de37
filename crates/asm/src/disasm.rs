//! The disassembler: instructions back into source text that assembles to
//! the same bytes (words that do not end in STOP come back with the STOP
//! the assembler appends, docs/behaviour.md rule 93; every program the
//! assembler made ends in STOP already).
//!
//! Every jump target inside the program gets a label: the name from the
//! symbol table when one is given, otherwise `L<address>`. Symbolic
//! operands are written by name (`ABS`, `POS`, `GE`, `MUL`). A word that
//! the mnemonic form cannot reproduce exactly — an unknown instruction
//! number, a type the instruction does not have, or a non-zero byte in a
//! field the mnemonic has no operand for — is written as a raw word,
//! `#db opcode, type, motor, value`.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

use tmclsim_protocol::mnemonic::{Operand, format_with, layout, shows_every_field};
use tmclsim_protocol::{Command, Instruction, opcode as op};

/// Column where the `// address` comments start.
const COMMENT_COLUMN: usize = 40;

/// Whether the mnemonic form of the instruction encodes back to exactly
/// these seven bytes.
pub fn has_mnemonic_form(ins: Instruction) -> bool {
    op::mnemonic(ins.opcode).is_some() && layout(ins.opcode).is_some() && Command::decode(ins).is_ok() && shows_every_field(ins)
}

/// The jump target of an instruction written in mnemonic form.
fn jump_target(ins: Instruction) -> Option<i32> {
    let slots = layout(ins.opcode)?;
    (has_mnemonic_form(ins) && slots.contains(&Operand::Address)).then_some(ins.value)
}

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_') && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Labels by address: given symbols (valid names, inside the program or
/// just after it) and generated `L<address>` names for other jump targets.
fn labels(instructions: &[Instruction], symbols: Option<&BTreeMap<String, u32>>) -> BTreeMap<u32, Vec<String>> {
    let end = instructions.len() as u32;
    let mut by_address: BTreeMap<u32, Vec<String>> = BTreeMap::new();
    let mut taken: BTreeSet<String> = BTreeSet::new();
    for (name, &address) in symbols.into_iter().flatten() {
        if is_identifier(name) && address <= end {
            by_address.entry(address).or_default().push(name.clone());
        }
        taken.insert(name.clone());
    }
    for ins in instructions {
        let Some(target) = jump_target(*ins) else { continue };
        let Ok(target) = u32::try_from(target) else { continue };
        if target > end || by_address.contains_key(&target) {
            continue;
        }
        let mut name = format!("L{target}");
        while taken.contains(&name) {
            name.push('_');
        }
        taken.insert(name.clone());
        by_address.insert(target, vec![name]);
    }
    by_address
}

/// Source text for a list of instructions (see the module documentation).
pub fn disassemble(instructions: &[Instruction], symbols: Option<&BTreeMap<String, u32>>) -> String {
    let labels = labels(instructions, symbols);
    let label_of = |address: i32| -> String {
        u32::try_from(address)
            .ok()
            .and_then(|a| labels.get(&a))
            .and_then(|names| names.first())
            .cloned()
            .unwrap_or_else(|| address.to_string())
    };
    let mut out = String::new();
    let _ = writeln!(out, "// TMCL program disassembled by tmclsim-asm: {} instruction(s).", instructions.len());
    let _ = writeln!(out, "// Labels mark jump targets; '#db opcode, type, motor, value' is a raw word.");
    let _ = writeln!(out, "// The comment after each instruction is its address.");
    out.push('\n');
    for (address, ins) in instructions.iter().enumerate() {
        for name in labels.get(&(address as u32)).into_iter().flatten() {
            let _ = writeln!(out, "{name}:");
        }
        let text = if has_mnemonic_form(*ins) {
            format_with(*ins, label_of)
        } else {
            format!("#db {}, {}, {}, {}", ins.opcode, ins.kind, ins.motor, ins.value)
        };
        let line = format!("    {text}");
        let pad = COMMENT_COLUMN.saturating_sub(line.chars().count()).max(1);
        let _ = writeln!(out, "{line}{}// {address}", " ".repeat(pad));
    }
    for name in labels.get(&(instructions.len() as u32)).into_iter().flatten() {
        let _ = writeln!(out, "{name}:");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mnemonic_form_only_when_exact() {
        assert!(has_mnemonic_form(Instruction::new(op::JA, 0, 0, 5)));
        assert!(!has_mnemonic_form(Instruction::new(op::JA, 1, 0, 5)));
        assert!(!has_mnemonic_form(Instruction::new(op::RSUB, 0, 0, 1)));
        assert!(!has_mnemonic_form(Instruction::new(op::MVP, 3, 0, 0)));
        assert!(!has_mnemonic_form(Instruction::new(0, 0, 0, 0)));
        assert!(!has_mnemonic_form(Instruction::new(op::FIRMWARE_VERSION, 0, 0, 0)));
    }

    #[test]
    fn labels_for_targets() {
        let program = [
            Instruction::new(op::MVP, 0, 0, 100),
            Instruction::new(op::JA, 0, 0, 0),
            Instruction::new(op::JC, 5, 0, 2),
            Instruction::new(op::JA, 0, 0, 99),
        ];
        let text = disassemble(&program, None);
        assert!(text.contains("L0:\n    MVP ABS, 0, 100"), "{text}");
        assert!(text.contains("JA L0"), "{text}");
        assert!(text.contains("L2:\n    JC GE, L2"), "{text}");
        assert!(text.contains("JA 99"), "{text}");
        let symbols: BTreeMap<String, u32> = [("Start".to_string(), 0), ("L2".to_string(), 3)].into();
        let text = disassemble(&program, Some(&symbols));
        assert!(text.contains("Start:\n    MVP"), "{text}");
        assert!(text.contains("L2_:\n    JC GE, L2_"), "{text}");
        assert!(text.contains("L2:\n    JA 99"), "{text}");
    }
}
