//! The golden frames of the TMCM-1141 firmware manual: each
//! mnemonic assembles to the frame's seven instruction bytes, and its
//! binary word carries the frame checksum minus the address byte (01).

mod common;

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

#[test]
fn frames_that_are_right_as_printed() {
    let table = [
        ("ROR 0, 1000", "01 01 00 00 00 00 03 E8 ED"),
        ("ROL 0, 1000", "01 02 00 00 00 00 03 E8 EE"),
        ("MST 0", "01 03 00 00 00 00 00 00 04"),
        ("MVP ABS, 0, 90000", "01 04 00 00 00 01 5F 90 F5"),
        ("MVP REL, 0, -10000", "01 04 01 00 FF FF D8 F0 CC"),
        ("MVP COORD, 0, 8", "01 04 02 00 00 00 00 08 0F"),
        ("SAP 4, 0, 1000", "01 05 04 00 00 00 03 E8 F5"),
        ("GAP 1, 0", "01 06 01 00 00 00 00 00 08"),
        ("SGP 66, 0, 3", "01 09 42 00 00 00 00 03 4F"),
        ("GGP 66, 0", "01 0A 42 00 00 00 00 00 4D"),
        ("STGP 42, 2", "01 0B 2A 02 00 00 00 00 38"),
        ("RSGP 42, 2", "01 0C 2A 02 00 00 00 00 39"),
        ("RFS START, 0", "01 0D 00 00 00 00 00 00 0E"),
        ("SIO 0, 2, 1", "01 0E 00 02 00 00 00 01 12"),
        ("GIO 0, 1", "01 0F 00 01 00 00 00 00 11"),
        ("CALC MUL, -5000", "01 13 02 00 FF FF EC 78 78"),
        ("COMP 1000", "01 14 00 00 00 00 03 E8 00"),
        ("JC GE, 10", "01 15 05 00 00 00 00 0A 25"),
        ("JA 10", "01 16 00 00 00 00 00 0A 21"),
        ("CSUB 100", "01 17 00 00 00 00 00 64 7C"),
        ("RSUB", "01 18 00 00 00 00 00 00 19"),
        ("WAIT POS, 0, 0", "01 1B 01 00 00 00 00 00 1D"),
        ("STOP", "01 1C 00 00 00 00 00 00 1D"),
        ("SCO 1, 0, 1000", "01 1E 01 00 00 00 03 E8 0B"),
        ("GCO 1, 0", "01 1F 01 00 00 00 00 00 21"),
        ("ACO 1, 0", "01 27 01 00 00 00 00 00 29"),
        ("CALCX MUL", "01 21 02 00 00 00 00 00 24"),
        ("AAP 0, 0", "01 22 00 00 00 00 00 00 23"),
        ("AGP 42, 2", "01 23 2A 02 00 00 00 00 50"),
        ("CLE ETO", "01 24 01 00 00 00 00 00 26"),
        ("EI 255", "01 19 FF 00 00 00 00 00 19"),
        ("DI 255", "01 1A FF 00 00 00 00 00 1A"),
        ("CALCVV SUB, 65, 42", "01 28 01 41 00 00 00 2A 95"),
        ("CALCVA SUB, 27", "01 29 01 1B 00 00 00 00 46"),
        ("CALCAV SUB, 27", "01 2A 01 1B 00 00 00 00 47"),
        ("CALCVX SUB, 27", "01 2B 01 1B 00 00 00 00 48"),
        ("CALCXV SUB, 27", "01 2C 01 1B 00 00 00 00 49"),
        ("CALCV SUB, 27, 5000", "01 2D 01 1B 00 00 13 88 E5"),
        ("CALL LT, 100", "01 50 06 00 00 00 00 64 BB"),
        ("MVPA ABS, 0", "01 2E 00 00 00 00 00 00 2F"),
        ("ROLA 0", "01 32 00 00 00 00 00 00 33"),
        ("SIV 3", "01 37 00 00 00 00 00 03 3B"),
        ("AIV", "01 39 00 00 00 00 00 00 3A"),
        ("#db 138, 1, 0, 1", "01 8A 01 00 00 00 00 01 8D"),
    ];
    for (mnemonic, frame) in table {
        assert_eq!(first_word(mnemonic), word_of_frame(frame), "{mnemonic}");
    }
}

#[test]
fn frames_the_manual_prints_wrong_as_corrected() {
    let table = [
        ("STAP 6, 0", "01 07 06 00 00 00 00 00 0E"),
        ("RSAP 6, 0", "01 08 06 00 00 00 00 00 0F"),
        ("CCO 3, 0", "01 20 03 00 00 00 00 00 24"),
        ("VECT 0, 50", "01 25 00 00 00 00 00 32 58"),
        ("RETI", "01 26 00 00 00 00 00 00 27"),
        ("RST 10", "01 30 00 00 00 00 00 0A 3B"),
        ("DJNZ 42, 1", "01 31 2A 00 00 00 00 01 5D"),
        ("RORA 0", "01 33 00 00 00 00 00 00 34"),
        ("GIV", "01 38 00 00 00 00 00 00 39"),
    ];
    for (mnemonic, frame) in table {
        assert_eq!(first_word(mnemonic), word_of_frame(frame), "{mnemonic}");
    }
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
