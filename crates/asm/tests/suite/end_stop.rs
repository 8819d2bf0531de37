//! The STOP after the last instruction (docs/behaviour.md rule 93): a
//! program that does not end in STOP is written as TMCL-IDE writes it, with
//! one more word, `1C 00 00 00 00 00 00 1C`; one that ends in STOP is left
//! as it is. The appended word has no source line, a label after the last
//! line names it, and the disassembly of the binary assembles to the same
//! bytes.

use crate::common;

use common::{asm, asm_1141, errors};
use tmclsim_asm::{NoIncludes, Program, assemble, binary, disassemble};

/// The STOP word as a binary file stores it: opcode 28, type, motor and
/// value 0, and the word's checksum.
const STOP_WORD: [u8; 8] = [0x1C, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1C];

#[test]
fn a_program_ending_in_ja_ends_with_the_stop_word_tmcl_ide_writes() {
    let program = asm("Loop: MVP ABS, 0, 1000\n  WAIT POS, 0, 0\n  MVP ABS, 0, 0\n  WAIT POS, 0, 0\n  JA Loop\n");
    let bin = program.to_binary();
    assert_eq!(bin.len(), 6 * 8, "five instructions and the STOP");
    assert_eq!(bin[32..40], [0x16, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x16], "JA Loop (address 0)");
    assert_eq!(bin[40..], STOP_WORD);
    assert!(program.appended_stop);
    assert_eq!(program.appended_stop_address(), Some(5));
    // No source line for it: the source map and the symbol file end with JA.
    assert_eq!(program.source_map.len(), 5);
    assert_eq!(program.source_of(5), None);
    assert!(program.symbol_file().ends_with("\n@4\tprog.tmc\t5\t3\tJA Loop\n"), "{}", program.symbol_file());
    // A label on no instruction after the last line names the STOP.
    let program = asm("  JA End\nEnd:\n");
    assert_eq!((program.symbols["End"], program.instructions[1]), (1, binary::END_STOP));
}

#[test]
fn a_program_ending_in_stop_gets_no_second_one() {
    for source in ["ROR 0, 100\nWAIT TICKS, 0, 10\nMST 0\nSTOP\n", "ROR 0, 100\n#db 28, 0, 0, 0\n", "ROR 0, 100\n#db 28, 1, 2, 3\n"] {
        let program = asm(source);
        assert!(!program.appended_stop, "{source}");
        assert_eq!(program.appended_stop_address(), None);
        assert_eq!(program.source_map.len(), program.instructions.len(), "{source}");
    }
    let bin = asm("ROR 0, 100\nSTOP\n").to_binary();
    assert_eq!((bin.len(), &bin[8..]), (16, &STOP_WORD[..]));
    // A STOP that is not the last word does not count.
    let program = asm("STOP\nROR 0, 100\n");
    assert_eq!(program.instructions.len(), 3);
    assert_eq!(program.to_binary()[16..], STOP_WORD);
    // Without any instruction, the program is the STOP alone.
    let program = asm("// nothing here\nSpeed = 100\n");
    assert_eq!((program.to_binary(), program.appended_stop), (STOP_WORD.to_vec(), true));
}

#[test]
fn the_appended_stop_disassembles_as_a_stop_and_the_binary_round_trips() {
    let program = asm("Start: ROL 0, 500\n  WAIT TICKS, 0, 100\n  JA Start\n");
    let bin = program.to_binary();
    let words = Program::from_binary(&bin).unwrap();
    let text = disassemble(&words, Some(&program.symbols));
    let last = text.lines().last().unwrap();
    assert!(last.starts_with("    STOP") && last.ends_with("// 3"), "{text}");
    let again = assemble(&text, "back.tmc", &NoIncludes, None).unwrap();
    assert_eq!(again.to_binary(), bin, "{text}");
    assert!(!again.appended_stop, "the disassembly ends in STOP already");
}

#[test]
fn the_appended_stop_must_fit_the_program_memory() {
    // 1024 words fill the TMCM-1141: 1023 and the STOP do, 1024 and the
    // STOP do not; 1024 ending in STOP do.
    assert_eq!(asm_1141(&"MST 0\n".repeat(1023)).instructions.len(), 1024);
    assert_eq!(asm_1141(&format!("{}STOP\n", "MST 0\n".repeat(1023))).instructions.len(), 1024);
    assert_eq!(
        errors(&"MST 0\n".repeat(1024), true),
        ["prog.tmc:1024:1: error: the program has 1024 instructions and does not end in STOP: the STOP appended after its last one \
          makes 1025, and the program memory of the TMCM-1141 holds 1024"]
    );
}
