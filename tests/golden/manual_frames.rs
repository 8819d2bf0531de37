//! The request frames that the firmware manuals print, in one table for
//! every crate that tests against them (the assembler: each line assembles
//! to the frame's instruction bytes; the firmware: each line encodes to the
//! frame, and the module it was printed for answers it). Rows:
//!
//! - the TMCM-1141 manual V1.46, corrected as the reference notes say;
//! - the TMCM-351 manual V4.45 (rev. 1.06), which prints the eight bytes
//!   before the checksum: the checksum here is computed;
//! - the TMCM-351 manual rev. 1.03 (damaged text, decoded by hand).
//!
//! `Printed::Corrected` marks the frames a manual prints wrong; the row's
//! `printed` note says how. Included by the tests with `#[path]`.

/// How the manual prints a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(dead_code)]
pub enum Printed {
    /// Right as printed.
    AsIs,
    /// Printed wrong; the bytes here are corrected.
    Corrected,
}

/// One printed example.
#[derive(Clone, Copy, Debug)]
#[allow(dead_code)]
pub struct Golden {
    /// The built-in module the manual is for.
    pub module: &'static str,
    /// The manual and where in it.
    pub manual: &'static str,
    /// The command, as a mnemonic line.
    pub line: &'static str,
    /// The request frame to address 1, checksum included.
    pub frame: &'static str,
    /// How the manual prints it.
    pub printed: Printed,
}

const fn row(module: &'static str, manual: &'static str, line: &'static str, frame: &'static str, printed: Printed) -> Golden {
    Golden { module, manual, line, frame, printed }
}

const M1141: &str = "tmcm-1141";
const M351: &str = "tmcm-351";

/// Every printed frame.
#[rustfmt::skip]
pub const FRAMES: &[Golden] = &[
    row(M1141, "V1.46", "ROR 0, 1000", "01 01 00 00 00 00 03 E8 ED", Printed::AsIs),
    row(M1141, "V1.46", "ROL 0, 1000", "01 02 00 00 00 00 03 E8 EE", Printed::AsIs),
    row(M1141, "V1.46", "MST 0", "01 03 00 00 00 00 00 00 04", Printed::AsIs),
    row(M1141, "V1.46", "MVP ABS, 0, 90000", "01 04 00 00 00 01 5F 90 F5", Printed::AsIs),
    row(M1141, "V1.46", "MVP REL, 0, -10000", "01 04 01 00 FF FF D8 F0 CC", Printed::AsIs),
    row(M1141, "V1.46", "MVP COORD, 0, 8", "01 04 02 00 00 00 00 08 0F", Printed::AsIs),
    row(M1141, "V1.46", "SAP 4, 0, 1000", "01 05 04 00 00 00 03 E8 F5", Printed::AsIs),
    row(M1141, "V1.46", "GAP 1, 0", "01 06 01 00 00 00 00 00 08", Printed::AsIs),
    row(M1141, "V1.46", "STAP 6, 0", "01 07 06 00 00 00 00 00 0E", Printed::Corrected),
    row(M1141, "V1.46", "RSAP 6, 0", "01 08 06 00 00 00 00 00 0F", Printed::Corrected),
    row(M1141, "V1.46", "SGP 66, 0, 3", "01 09 42 00 00 00 00 03 4F", Printed::AsIs),
    row(M1141, "V1.46", "GGP 66, 0", "01 0A 42 00 00 00 00 00 4D", Printed::AsIs),
    row(M1141, "V1.46", "STGP 42, 2", "01 0B 2A 02 00 00 00 00 38", Printed::AsIs),
    row(M1141, "V1.46", "RSGP 42, 2", "01 0C 2A 02 00 00 00 00 39", Printed::AsIs),
    row(M1141, "V1.46", "RFS START, 0", "01 0D 00 00 00 00 00 00 0E", Printed::AsIs),
    row(M1141, "V1.46", "SIO 0, 2, 1", "01 0E 00 02 00 00 00 01 12", Printed::AsIs),
    row(M1141, "V1.46", "GIO 0, 1", "01 0F 00 01 00 00 00 00 11", Printed::AsIs),
    row(M1141, "V1.46", "CALC MUL, -5000", "01 13 02 00 FF FF EC 78 78", Printed::AsIs),
    row(M1141, "V1.46", "COMP 1000", "01 14 00 00 00 00 03 E8 00", Printed::AsIs),
    row(M1141, "V1.46", "JC GE, 10", "01 15 05 00 00 00 00 0A 25", Printed::AsIs),
    row(M1141, "V1.46", "JA 10", "01 16 00 00 00 00 00 0A 21", Printed::AsIs),
    row(M1141, "V1.46", "CSUB 100", "01 17 00 00 00 00 00 64 7C", Printed::AsIs),
    row(M1141, "V1.46", "RSUB", "01 18 00 00 00 00 00 00 19", Printed::AsIs),
    row(M1141, "V1.46", "WAIT POS, 0, 0", "01 1B 01 00 00 00 00 00 1D", Printed::AsIs),
    row(M1141, "V1.46", "STOP", "01 1C 00 00 00 00 00 00 1D", Printed::AsIs),
    row(M1141, "V1.46", "SCO 1, 0, 1000", "01 1E 01 00 00 00 03 E8 0B", Printed::AsIs),
    row(M1141, "V1.46", "GCO 1, 0", "01 1F 01 00 00 00 00 00 21", Printed::AsIs),
    row(M1141, "V1.46", "CCO 3, 0", "01 20 03 00 00 00 00 00 24", Printed::Corrected),
    row(M1141, "V1.46", "ACO 1, 0", "01 27 01 00 00 00 00 00 29", Printed::AsIs),
    row(M1141, "V1.46", "CALCX MUL", "01 21 02 00 00 00 00 00 24", Printed::AsIs),
    row(M1141, "V1.46", "AAP 0, 0", "01 22 00 00 00 00 00 00 23", Printed::AsIs),
    row(M1141, "V1.46", "AGP 42, 2", "01 23 2A 02 00 00 00 00 50", Printed::AsIs),
    row(M1141, "V1.46", "CLE ETO", "01 24 01 00 00 00 00 00 26", Printed::AsIs),
    row(M1141, "V1.46", "EI 255", "01 19 FF 00 00 00 00 00 19", Printed::AsIs),
    row(M1141, "V1.46", "DI 255", "01 1A FF 00 00 00 00 00 1A", Printed::AsIs),
    row(M1141, "V1.46", "VECT 0, 50", "01 25 00 00 00 00 00 32 58", Printed::Corrected),
    row(M1141, "V1.46", "RETI", "01 26 00 00 00 00 00 00 27", Printed::Corrected),
    row(M1141, "V1.46", "CALCVV SUB, 65, 42", "01 28 01 41 00 00 00 2A 95", Printed::AsIs),
    row(M1141, "V1.46", "CALCVA SUB, 27", "01 29 01 1B 00 00 00 00 46", Printed::AsIs),
    row(M1141, "V1.46", "CALCAV SUB, 27", "01 2A 01 1B 00 00 00 00 47", Printed::AsIs),
    row(M1141, "V1.46", "CALCVX SUB, 27", "01 2B 01 1B 00 00 00 00 48", Printed::AsIs),
    row(M1141, "V1.46", "CALCXV SUB, 27", "01 2C 01 1B 00 00 00 00 49", Printed::AsIs),
    row(M1141, "V1.46", "CALCV SUB, 27, 5000", "01 2D 01 1B 00 00 13 88 E5", Printed::AsIs),
    row(M1141, "V1.46", "MVPA ABS, 0", "01 2E 00 00 00 00 00 00 2F", Printed::AsIs),
    row(M1141, "V1.46", "RST 10", "01 30 00 00 00 00 00 0A 3B", Printed::Corrected),
    row(M1141, "V1.46", "DJNZ 42, 1", "01 31 2A 00 00 00 00 01 5D", Printed::Corrected),
    row(M1141, "V1.46", "ROLA 0", "01 32 00 00 00 00 00 00 33", Printed::AsIs),
    row(M1141, "V1.46", "RORA 0", "01 33 00 00 00 00 00 00 34", Printed::Corrected),
    row(M1141, "V1.46", "SIV 3", "01 37 00 00 00 00 00 03 3B", Printed::AsIs),
    row(M1141, "V1.46", "GIV", "01 38 00 00 00 00 00 00 39", Printed::Corrected),
    row(M1141, "V1.46", "AIV", "01 39 00 00 00 00 00 00 3A", Printed::AsIs),
    row(M1141, "V1.46", "CALL LT, 100", "01 50 06 00 00 00 00 64 BB", Printed::AsIs),
    row(M1141, "V1.46", "#138 1 0 1", "01 8A 01 00 00 00 00 01 8D", Printed::AsIs),
    row(M351, "V4.45 §4.6.1 p.22", "ROR 2, 350", "01 01 00 02 00 00 01 5E 63", Printed::AsIs),
    row(M351, "V4.45 §4.6.2 p.23", "ROL 0, 1200", "01 02 00 00 00 00 04 B0 B7", Printed::AsIs),
    row(M351, "V4.45 §4.6.3 p.24", "MST 0", "01 03 00 00 00 00 00 00 04", Printed::AsIs),
    row(M351, "V4.45 §4.6.4 p.25", "MVP ABS, 0, 90000", "01 04 00 00 00 01 5F 90 F5", Printed::Corrected), // the mnemonic says 9000, the bytes 90000
    row(M351, "V4.45 §4.6.4 p.25", "MVP REL, 0, -1000", "01 04 01 00 FF FF FC 18 18", Printed::AsIs),
    row(M351, "V4.45 §4.6.4 p.26", "MVP COORD, 0, 8", "01 04 02 00 00 00 00 08 0F", Printed::AsIs),
    row(M351, "V4.45 §4.6.5 p.27", "SAP 6, 0, 128", "01 05 06 00 00 00 00 80 8C", Printed::Corrected), // printed value byte $12; 128 is $80
    row(M351, "V4.45 §4.6.6 p.28", "GAP 6, 1", "01 06 06 01 00 00 00 00 0E", Printed::AsIs),
    row(M351, "V4.45 §4.6.7 p.29", "STAP 4, 0", "01 07 04 00 00 00 00 00 0C", Printed::AsIs),
    row(M351, "V4.45 §4.6.8 p.30", "RSAP 6, 0", "01 08 06 00 00 00 00 00 0F", Printed::Corrected), // printed motor byte $03 ("motor 3"); the module has motors 0…2
    row(M351, "V4.45 §4.6.9 p.31", "SGP 66, 0, 3", "01 09 42 00 00 00 00 03 4F", Printed::AsIs),
    row(M351, "V4.45 §4.6.10 p.32", "GGP 66, 0", "01 0A 42 00 00 00 00 00 4D", Printed::AsIs),
    row(M351, "V4.45 §4.6.11 p.33", "STGP 42, 2", "01 0B 2A 02 00 00 00 00 38", Printed::AsIs),
    row(M351, "V4.45 §4.6.12 p.34", "RSGP 42, 2", "01 0C 2A 02 00 00 00 00 39", Printed::AsIs),
    row(M351, "V4.45 §4.6.13 p.35", "RFS START, 0", "01 0D 00 00 00 00 00 00 0E", Printed::AsIs),
    row(M351, "V4.45 §4.6.14 p.36", "SIO 7, 2, 1", "01 0E 07 02 00 00 00 01 19", Printed::AsIs),
    row(M351, "V4.45 §4.6.15 p.38", "GIO 0, 1", "01 0F 00 01 00 00 00 00 11", Printed::AsIs),
    row(M351, "V4.45 §4.6.16 p.41", "CALC MUL, -5000", "01 13 02 00 FF FF EC 78 78", Printed::AsIs),
    row(M351, "V4.45 §4.6.17 p.42", "COMP 1000", "01 14 00 00 00 00 03 E8 00", Printed::AsIs),
    row(M351, "V4.45 §4.6.18 p.43", "JC GE, 10", "01 15 05 00 00 00 00 0A 25", Printed::AsIs),
    row(M351, "V4.45 §4.6.19 p.44", "JA 20", "01 16 00 00 00 00 00 14 2B", Printed::AsIs),
    row(M351, "V4.45 §4.6.20 p.45", "CSUB 100", "01 17 00 00 00 00 00 64 7C", Printed::AsIs),
    row(M351, "V4.45 §4.6.21 p.46", "RSUB", "01 18 00 00 00 00 00 00 19", Printed::AsIs),
    row(M351, "V4.45 §4.6.22 p.47", "WAIT POS, 0, 0", "01 1B 01 00 00 00 00 00 1D", Printed::AsIs),
    row(M351, "V4.45 §4.6.23 p.48", "STOP", "01 1C 00 00 00 00 00 00 1D", Printed::AsIs),
    row(M351, "V4.45 §4.6.25 p.50", "SCO 1, 0, 1000", "01 1E 01 00 00 00 03 E8 0B", Printed::AsIs),
    row(M351, "V4.45 §4.6.26 p.51", "GCO 1, 0", "01 1F 01 00 00 00 00 00 21", Printed::AsIs),
    row(M351, "V4.45 §4.6.27 p.52", "CCO 3, 0", "01 20 03 00 00 00 00 00 24", Printed::AsIs),
    row(M351, "V4.45 §4.6.28 p.53", "ACO 1, 0", "01 27 01 00 00 00 00 00 29", Printed::AsIs),
    row(M351, "V4.45 §4.6.29 p.54", "CALCX MUL", "01 21 02 00 00 00 00 00 24", Printed::AsIs),
    row(M351, "V4.45 §4.6.30 p.55", "AAP 0, 0", "01 22 00 00 00 00 00 00 23", Printed::AsIs),
    row(M351, "V4.45 §4.6.31 p.56", "AGP 3, 2", "01 23 03 02 00 00 00 00 29", Printed::AsIs),
    row(M351, "V4.45 §4.6.32 p.57", "CLE ETO", "01 24 01 00 00 00 00 00 26", Printed::AsIs),
    row(M351, "V4.45 §4.6.33 p.58", "VECT 3, 500", "01 25 03 00 00 00 01 F4 1E", Printed::AsIs),
    row(M351, "V4.45 §4.6.34 p.60", "EI 255", "01 19 FF 00 00 00 00 00 19", Printed::AsIs),
    row(M351, "V4.45 §4.6.34 p.60", "EI 3", "01 19 03 00 00 00 00 00 1D", Printed::AsIs),
    row(M351, "V4.45 §4.6.35 p.62", "DI 255", "01 1A FF 00 00 00 00 00 1A", Printed::AsIs),
    row(M351, "V4.45 §4.6.35 p.62", "DI 3", "01 1A 03 00 00 00 00 00 1E", Printed::AsIs),
    row(M351, "V4.45 §4.6.36 p.63", "RETI", "01 26 00 00 00 00 00 00 27", Printed::Corrected), // printed value $00000100; RETI has no operand
    row(M351, "rev. 1.03", "ROL 1, 1200", "01 02 00 01 00 00 04 B0 B8", Printed::AsIs),
    row(M351, "rev. 1.03", "MST 1", "01 03 00 01 00 00 00 00 05", Printed::AsIs),
    row(M351, "rev. 1.03", "MVP ABS, 1, 90000", "01 04 00 01 00 01 5F 90 F6", Printed::AsIs),
    row(M351, "rev. 1.03", "MVP REL, 0, -1000", "01 04 01 00 FF FF FC 18 18", Printed::AsIs),
    row(M351, "rev. 1.03", "SAP 6, 1, 200", "01 05 06 01 00 00 00 C8 D5", Printed::AsIs),
    row(M351, "rev. 1.03", "GAP 1, 2", "01 06 01 02 00 00 00 00 0A", Printed::AsIs),
    row(M351, "rev. 1.03", "STAP 4, 1", "01 07 04 01 00 00 00 00 0D", Printed::AsIs),
    row(M351, "rev. 1.03", "RSAP 6, 1", "01 08 06 01 00 00 00 00 10", Printed::AsIs),
    row(M351, "rev. 1.03", "SGP 66, 0, 3", "01 09 42 00 00 00 00 03 4F", Printed::AsIs),
    row(M351, "rev. 1.03", "GGP 66, 0", "01 0A 42 00 00 00 00 00 4D", Printed::AsIs),
    row(M351, "rev. 1.03", "STGP 42, 2", "01 0B 2A 02 00 00 00 00 38", Printed::AsIs),
    row(M351, "rev. 1.03", "RFS START, 1", "01 0D 00 01 00 00 00 00 0F", Printed::AsIs),
    row(M351, "rev. 1.03", "SIO 7, 2, 1", "01 0E 07 02 00 00 00 01 19", Printed::AsIs),
    row(M351, "rev. 1.03", "ROR 2, 350", "01 01 00 02 00 00 01 5E 63", Printed::Corrected), // printed checksum 62
    row(M351, "rev. 1.03", "RSGP 66, 0", "01 0C 42 00 00 00 00 00 4F", Printed::Corrected), // printed as a copy of the RSAP frame
    row(M351, "rev. 1.03", "MVP COORD, $47, 2", "01 04 02 47 00 00 00 02 50", Printed::AsIs),
    row(M351, "rev. 1.03", "MVP COORD, $87, 5", "01 04 02 87 00 00 00 05 93", Printed::AsIs),
];

/// The frames printed for one module.
#[allow(dead_code)]
pub fn frames_of(module: &'static str) -> impl Iterator<Item = &'static Golden> {
    FRAMES.iter().filter(move |g| g.module == module)
}
