//! assemble → disassemble → assemble gives the same binary, for random
//! instructions (valid ones and arbitrary bytes), with and without a
//! symbol table (words that do not end in STOP come back with the STOP the
//! assembler appends, docs/behaviour.md rule 93); and the binary and
//! symbol formats read back what they wrote.

use crate::common;

use std::collections::BTreeMap;

use common::Rng;
use tmclsim_asm::binary::{END_STOP, needs_end_stop};
use tmclsim_asm::{Instruction, NoIncludes, Program, assemble, disassemble, render};
use tmclsim_protocol::{mnemonic, opcode};

/// The words as the assembler gives them back: with the STOP it appends
/// when the last word is not one.
fn ended(words: &[Instruction]) -> Vec<Instruction> {
    let mut out = words.to_vec();
    if needs_end_stop(words) {
        out.push(END_STOP);
    }
    out
}

fn reassemble(instructions: &[Instruction], symbols: Option<&BTreeMap<String, u32>>) -> Program {
    let text = disassemble(instructions, symbols);
    assemble(&text, "disassembled.tmc", &NoIncludes, None).unwrap_or_else(|d| panic!("{text}\n{}", render(&d)))
}

/// A random instruction with a mnemonic; fields the mnemonic has no
/// operand for are usually 0, jump targets usually inside the program.
fn random_mnemonic_instruction(rng: &mut Rng, program_len: usize) -> Instruction {
    let opcodes: Vec<u8> = (0..=255u8).filter(|&o| opcode::mnemonic(o).is_some()).collect();
    let code = *rng.pick(&opcodes);
    let slots = mnemonic::layout(code).unwrap_or(&[]);
    let mut ins = Instruction::new(code, 0, 0, 0);
    for slot in slots {
        match slot {
            mnemonic::Operand::Type => ins.kind = rng.byte(),
            mnemonic::Operand::TypeSymbol(table) => ins.kind = rng.below(table.len() as u64 + 1) as u8,
            mnemonic::Operand::Motor => ins.motor = rng.byte(),
            mnemonic::Operand::Value => ins.value = rng.next() as i32 >> rng.below(32),
            mnemonic::Operand::Address => ins.value = rng.below(program_len as u64 + 3) as i32,
        }
    }
    if rng.below(10) == 0 {
        ins.motor = rng.byte();
    }
    if rng.below(10) == 0 {
        ins.kind = rng.byte();
    }
    ins
}

#[test]
fn random_valid_programs_round_trip() {
    let mut rng = Rng(0x5EED_0001);
    for _ in 0..300 {
        let len = rng.below(40) as usize + 1;
        let program: Vec<Instruction> = (0..len).map(|_| random_mnemonic_instruction(&mut rng, len)).collect();
        let again = reassemble(&program, None);
        assert_eq!(again.instructions, ended(&program));
        // With a symbol table naming some addresses (one past the end too).
        let mut symbols = BTreeMap::new();
        for i in 0..rng.below(5) {
            symbols.insert(format!("Sym{i}"), rng.below(len as u64 + 1) as u32);
        }
        let again = reassemble(&program, Some(&symbols));
        assert_eq!(again.instructions, ended(&program));
        assert_eq!(again.symbols.iter().filter(|(n, _)| n.starts_with("Sym")).count(), symbols.len());
        for (name, address) in &symbols {
            assert_eq!(again.symbols[name], *address);
        }
    }
}

#[test]
fn arbitrary_words_round_trip() {
    let mut rng = Rng(0x5EED_0002);
    for _ in 0..300 {
        let len = rng.below(30) as usize;
        let program: Vec<Instruction> = (0..len).map(|_| Instruction::from_bytes(&std::array::from_fn(|_| rng.byte()))).collect();
        assert_eq!(reassemble(&program, None).instructions, ended(&program));
        // Once ended, the disassembly assembles to exactly the same words.
        assert_eq!(reassemble(&ended(&program), None).instructions, ended(&program));
        let binary = tmclsim_asm::binary::encode(&program);
        assert_eq!(Program::from_binary(&binary).unwrap(), program);
    }
}

#[test]
fn unusual_words_use_the_raw_form() {
    let program = [
        Instruction::new(0, 0, 0, 0),
        Instruction::new(opcode::FIRMWARE_VERSION, 1, 0, 0),
        Instruction::new(opcode::RSUB, 0, 0, 7),
        Instruction::new(opcode::CALC, 11, 0, 5),
        Instruction::new(opcode::JA, 0, 3, 0),
    ];
    let text = disassemble(&program, None);
    for line in ["    #db 0, 0, 0, 0", "    #db 136, 1, 0, 0", "    #db 24, 0, 0, 7", "    #db 19, 11, 0, 5", "    #db 22, 0, 3, 0"] {
        assert!(text.contains(line), "{line}\n{text}");
    }
    assert_eq!(reassemble(&program, None).instructions, ended(&program));
}

#[test]
fn symbol_names_that_are_not_labels_are_skipped() {
    let program = [Instruction::new(opcode::JA, 0, 0, 1), Instruction::new(opcode::STOP, 0, 0, 0)];
    let symbols: BTreeMap<String, u32> = [("not a name".to_string(), 1), ("Far".to_string(), 50)].into();
    let text = disassemble(&program, Some(&symbols));
    assert!(text.contains("L1:\n    STOP"), "{text}");
    assert!(!text.contains("Far"), "{text}");
    assert_eq!(reassemble(&program, Some(&symbols)).instructions, program);
}

#[test]
fn binary_and_symbol_files_read_back() {
    let source = "Start: ROL 0, 1000\nWAIT TICKS, 0, 500\nMiddle: MST 0\nJA Start\nEnd:\n";
    let program = assemble(source, "p.tmc", &NoIncludes, None).unwrap();
    let binary = program.to_binary();
    // Four instructions and the STOP appended after JA, which End labels.
    assert_eq!(binary.len(), 40);
    assert_eq!(binary[32..], [0x1C, 0, 0, 0, 0, 0, 0, 0x1C]);
    assert_eq!(Program::from_binary(&binary).unwrap(), program.instructions);
    assert!(program.symbol_file().starts_with("Start 0\nMiddle 2\nEnd 4\n// source map"));
    // The source map ends with the last line: the appended STOP has none.
    assert!(program.symbol_file().ends_with("\n@2\tp.tmc\t3\t9\tMiddle: MST 0\n@3\tp.tmc\t4\t1\tJA Start\n"));
    assert_eq!(Program::parse_symbol_file(&program.symbol_file()).unwrap(), program.symbols);
    let mut bad = binary.clone();
    bad[8 * 3 + 7] = bad[8 * 3 + 7].wrapping_add(1);
    assert_eq!(
        Program::from_binary(&bad).unwrap_err().to_string(),
        "bad checksum at address 3 (byte offset 24): stored 0x17, expected 0x16"
    );
    assert!(Program::from_binary(&binary[..31]).unwrap_err().to_string().starts_with("binary length 31 is not a multiple of 8 bytes"));
    // The disassembly of the binary with the symbol file is the program.
    let symbols = Program::parse_symbol_file(&program.symbol_file()).unwrap();
    let again = reassemble(&Program::from_binary(&binary).unwrap(), Some(&symbols));
    assert_eq!((again.instructions, again.symbols), (program.instructions, program.symbols));
}
