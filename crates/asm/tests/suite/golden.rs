//! The golden frames of the firmware manuals (tests/golden/manual_frames.rs):
//! each mnemonic assembles to the frame's seven instruction bytes, and its
//! binary word carries the frame checksum minus the address byte (01).

use crate::common;
#[path = "../../../../tests/golden/manual_frames.rs"]
mod manual_frames;

use common::asm;

fn hex(text: &str) -> Vec<u8> {
    text.split_whitespace().map(|b| u8::from_str_radix(b, 16).unwrap()).collect()
}

/// The binary word of the first instruction of a program.
fn first_word(source: &str) -> Vec<u8> {
    asm(source).to_binary()[..8].to_vec()
}

/// A request frame `[01][7 bytes][checksum]` as a binary word.
fn word_of_frame(frame: &str) -> Vec<u8> {
    let f = hex(frame);
    assert_eq!(f.len(), 9);
    assert_eq!(f[0], 0x01);
    let mut w = f[1..8].to_vec();
    w.push(f[8].wrapping_sub(0x01));
    w
}

/// A program whose first instruction jumps to a label at `address`.
fn with_label_at(first: &str, label: &str, address: usize) -> String {
    let mut s = format!("{first}\n");
    for _ in 1..address {
        s.push_str("STOP\n");
    }
    s.push_str(&format!("{label}: STOP\n"));
    s
}

/// Every request frame of the manual, those it prints wrong as corrected.
#[test]
fn frames_of_the_manual() {
    for g in manual_frames::FRAMES {
        assert_eq!(first_word(g.line), word_of_frame(g.frame), "{} {}: {}", g.module, g.manual, g.line);
    }
    let corrected = |module| manual_frames::frames_of(module).filter(|g| g.printed == manual_frames::Printed::Corrected).count();
    assert_eq!(corrected("tmcm-1141"), 9, "the frames the reference notes correct");
    assert_eq!(corrected("tmcm-351"), 6, "V4.45: MVP ABS, SAP 6, RSAP 6, RETI; rev. 1.03: ROR 2, RSGP 66");
}

/// The manual's "binary form of … assuming the label at address N".
#[test]
fn jumps_to_labels() {
    let table = [
        ("JC GE, Label", "Label", 10, "15 05 00 00 00 00 0A"),
        ("JA Loop", "Loop", 10, "16 00 00 00 00 00 0A"),
        ("CSUB SubW", "SubW", 100, "17 00 00 00 00 00 64"),
        ("VECT 0, Timer0Irq", "Timer0Irq", 50, "25 00 00 00 00 00 32"),
        ("RST Entry", "Entry", 10, "30 00 00 00 00 00 0A"),
        ("DJNZ 42, Loop", "Loop", 1, "31 2A 00 00 00 00 01"),
        ("CALL LT, RunLeft", "RunLeft", 100, "50 06 00 00 00 00 64"),
    ];
    for (first, label, address, bytes) in table {
        let program = asm(&with_label_at(first, label, address));
        assert_eq!(program.symbols[label], address as u32);
        let word = program.to_binary()[..8].to_vec();
        let mut expected = hex(bytes);
        expected.push(expected.iter().fold(0u8, |s, b| s.wrapping_add(*b)));
        assert_eq!(word, expected, "{first}");
    }
    // The same with the label before the jump.
    let program = asm("Loop: MVP ABS, 0, 0\nJA Loop");
    assert_eq!(program.instructions[1].value, 0);
}

#[test]
fn number_spellings_and_symbol_case() {
    let a = asm("SGP 66, 0, 3");
    for same in ["SGP $42, 0, 0x3", "sgp 0x42 0 3", "SGP 0b1000010, 0, 3", "SGP 60 + 6, 0, 9 / 3", "SGP (1 << 6) | 2, 0, 3"] {
        assert_eq!(asm(same).instructions, a.instructions, "{same}");
    }
    assert_eq!(asm("mvp abs, 0, 90000").instructions, asm("MVP ABS, 0, 90000").instructions);
    assert_eq!(asm("wait pos 0 0").instructions, asm("WAIT POS, 0, 0").instructions);
    assert_eq!(asm("SIO 255 2 -1").instructions[0].value, -1);
    assert_eq!(asm("MVP ABS 2, 10000").instructions, asm("MVP ABS, 2, 10000").instructions);
    assert_eq!(asm("SAP 4, 0, 4294967295").instructions[0].value, -1);
    assert_eq!(asm("SAP 4, 0, -2147483648").instructions[0].value, i32::MIN);
    assert_eq!(asm("UF3 1, 2, 3").instructions[0], tmclsim_asm::Instruction::new(67, 1, 2, 3));
    assert_eq!(asm("SAC 1, 2, 3").instructions[0].opcode, 29);
    assert_eq!(asm("#1 0 0 1000").instructions, asm("ROR 0, 1000").instructions);
}
