//! TMCL instruction numbers and their mnemonics.

/// 1 ROR: rotate right at a velocity.
pub const ROR: u8 = 1;
/// 2 ROL: rotate left at a velocity.
pub const ROL: u8 = 2;
/// 3 MST: motor stop.
pub const MST: u8 = 3;
/// 4 MVP: move to position (absolute, relative or to a coordinate).
pub const MVP: u8 = 4;
/// 5 SAP: set axis parameter.
pub const SAP: u8 = 5;
/// 6 GAP: get axis parameter.
pub const GAP: u8 = 6;
/// 7 STAP: store axis parameter in the EEPROM.
pub const STAP: u8 = 7;
/// 8 RSAP: restore axis parameter from the EEPROM.
pub const RSAP: u8 = 8;
/// 9 SGP: set global parameter.
pub const SGP: u8 = 9;
/// 10 GGP: get global parameter.
pub const GGP: u8 = 10;
/// 11 STGP: store global parameter in the EEPROM.
pub const STGP: u8 = 11;
/// 12 RSGP: restore global parameter from the EEPROM.
pub const RSGP: u8 = 12;
/// 13 RFS: reference search (start, stop, status).
pub const RFS: u8 = 13;
/// 14 SIO: set output.
pub const SIO: u8 = 14;
/// 15 GIO: get input or output.
pub const GIO: u8 = 15;
/// 19 CALC: calculate with the accumulator and a value.
pub const CALC: u8 = 19;
/// 20 COMP: compare the accumulator with a value.
pub const COMP: u8 = 20;
/// 21 JC: jump on a condition.
pub const JC: u8 = 21;
/// 22 JA: jump always.
pub const JA: u8 = 22;
/// 23 CSUB: call subroutine.
pub const CSUB: u8 = 23;
/// 24 RSUB: return from subroutine.
pub const RSUB: u8 = 24;
/// 25 EI: enable interrupt.
pub const EI: u8 = 25;
/// 26 DI: disable interrupt.
pub const DI: u8 = 26;
/// 27 WAIT: wait for an event or a number of ticks.
pub const WAIT: u8 = 27;
/// 28 STOP: stop the program.
pub const STOP: u8 = 28;
/// 29 SAC: SPI bus access.
pub const SAC: u8 = 29;
/// 30 SCO: set coordinate.
pub const SCO: u8 = 30;
/// 31 GCO: get coordinate.
pub const GCO: u8 = 31;
/// 32 CCO: capture coordinate (the actual position).
pub const CCO: u8 = 32;
/// 33 CALCX: calculate with the accumulator and the X register.
pub const CALCX: u8 = 33;
/// 34 AAP: accumulator to axis parameter.
pub const AAP: u8 = 34;
/// 35 AGP: accumulator to global parameter.
pub const AGP: u8 = 35;
/// 36 CLE: clear error flags.
pub const CLE: u8 = 36;
/// 37 VECT: set an interrupt vector.
pub const VECT: u8 = 37;
/// 38 RETI: return from interrupt.
pub const RETI: u8 = 38;
/// 39 ACO: accumulator to coordinate.
pub const ACO: u8 = 39;
/// 40 CALCVV: calculate with two user variables.
pub const CALCVV: u8 = 40;
/// 41 CALCVA: calculate with a user variable and the accumulator.
pub const CALCVA: u8 = 41;
/// 42 CALCAV: calculate with the accumulator and a user variable.
pub const CALCAV: u8 = 42;
/// 43 CALCVX: calculate with a user variable and the X register.
pub const CALCVX: u8 = 43;
/// 44 CALCXV: calculate with the X register and a user variable.
pub const CALCXV: u8 = 44;
/// 45 CALCV: calculate with a user variable and a value.
pub const CALCV: u8 = 45;
/// 46 MVPA: move to the position in the accumulator.
pub const MVPA: u8 = 46;
/// 48 RST: restart the program at an address.
pub const RST: u8 = 48;
/// 49 DJNZ: decrement a user variable, jump if not zero.
pub const DJNZ: u8 = 49;
/// 50 ROLA: rotate left at the velocity in the accumulator.
pub const ROLA: u8 = 50;
/// 51 RORA: rotate right at the velocity in the accumulator.
pub const RORA: u8 = 51;
/// 55 SIV: set indexed variable.
pub const SIV: u8 = 55;
/// 56 GIV: get indexed variable.
pub const GIV: u8 = 56;
/// 57 AIV: accumulator to indexed variable.
pub const AIV: u8 = 57;
/// 64 UF0: the first user function (UF0…UF7 are 64…71).
pub const UF0: u8 = 64;
/// 71 UF7: the last user function.
pub const UF7: u8 = 71;
/// 80 CALL: call subroutine on a condition.
pub const CALL: u8 = 80;
/// 128, stop application: stop the TMCL program.
pub const STOP_APPLICATION: u8 = 128;
/// 129, run application: run the TMCL program (from where it is, or from an address).
pub const RUN_APPLICATION: u8 = 129;
/// 130, step application: execute one instruction of the TMCL program.
pub const STEP_APPLICATION: u8 = 130;
/// 131, reset application: stop the TMCL program and set it to address 0.
pub const RESET_APPLICATION: u8 = 131;
/// 132, enter download mode: the following words are stored in program memory, not executed.
pub const ENTER_DOWNLOAD: u8 = 132;
/// 133, exit download mode.
pub const EXIT_DOWNLOAD: u8 = 133;
/// 134, read program memory: one word of the TMCL program.
pub const READ_MEMORY: u8 = 134;
/// 135, get application status: the program's state and address (types 0
/// and 1), the accumulator (2) or the X register (3).
pub const APPLICATION_STATUS: u8 = 135;
/// 136, get firmware version: type 0 as text, type 1 as a number.
pub const FIRMWARE_VERSION: u8 = 136;
/// 137, restore factory settings: the EEPROM back to the defaults (sends no reply).
pub const FACTORY_DEFAULTS: u8 = 137;
/// 138, request target position reached event: a message when a move reaches its target.
pub const TARGET_REACHED_EVENT: u8 = 138;
/// 139, enter ASCII mode: commands as text lines from then on.
pub const ASCII_MODE: u8 = 139;
/// 255, software reset: the module restarts.
pub const RESET: u8 = 255;

/// 200, the bootloader's BOOT_ERASE_ALL: erases the firmware.
pub const BOOT_ERASE_ALL: u8 = 200;
/// 201, BOOT_WRITE_BUFFER: a 32-bit word into the page buffer (word index:
/// type low byte, motor high byte).
pub const BOOT_WRITE_BUFFER: u8 = 201;
/// 202, BOOT_WRITE_PAGE: the page buffer into the flash page at the value.
pub const BOOT_WRITE_PAGE: u8 = 202;
/// 203, BOOT_GET_CHECKSUM: the byte sum of the flash from the firmware's
/// start through the address in the value.
pub const BOOT_GET_CHECKSUM: u8 = 203;
/// 204, BOOT_READ_MEMORY: the flash word at the address in the value.
pub const BOOT_READ_MEMORY: u8 = 204;
/// 205, BOOT_START_APPL: starts the firmware (no reply).
pub const BOOT_START_APPL: u8 = 205;
/// 206, BOOT_GET_INFO: page size (type 0), firmware start (1), flash size (2).
pub const BOOT_GET_INFO: u8 = 206;
/// 208, BOOT_WRITE_LENGTH: the firmware's length (type 0) or checksum (1).
pub const BOOT_WRITE_LENGTH: u8 = 208;
/// 242, BOOT: the firmware restarts into its bootloader (no reply), when
/// type, motor and value are [`BOOT_MAGIC`].
pub const BOOT: u8 = 242;
/// The type, motor and value 242 must carry.
pub const BOOT_MAGIC: (u8, u8, u32) = (0x81, 0x92, 0xA3B4_C5D6);

/// The bootloader's commands and 242 by their names (`BOOT_ERASE_ALL`).
pub fn boot_name(opcode: u8) -> Option<&'static str> {
    Some(match opcode {
        BOOT_ERASE_ALL => "BOOT_ERASE_ALL",
        BOOT_WRITE_BUFFER => "BOOT_WRITE_BUFFER",
        BOOT_WRITE_PAGE => "BOOT_WRITE_PAGE",
        BOOT_GET_CHECKSUM => "BOOT_GET_CHECKSUM",
        BOOT_READ_MEMORY => "BOOT_READ_MEMORY",
        BOOT_START_APPL => "BOOT_START_APPL",
        BOOT_GET_INFO => "BOOT_GET_INFO",
        BOOT_WRITE_LENGTH => "BOOT_WRITE_LENGTH",
        BOOT => "BOOT",
        _ => return None,
    })
}

/// Mnemonic of an instruction number; control commands have none.
pub fn mnemonic(opcode: u8) -> Option<&'static str> {
    Some(match opcode {
        ROR => "ROR",
        ROL => "ROL",
        MST => "MST",
        MVP => "MVP",
        SAP => "SAP",
        GAP => "GAP",
        STAP => "STAP",
        RSAP => "RSAP",
        SGP => "SGP",
        GGP => "GGP",
        STGP => "STGP",
        RSGP => "RSGP",
        RFS => "RFS",
        SIO => "SIO",
        GIO => "GIO",
        CALC => "CALC",
        COMP => "COMP",
        JC => "JC",
        JA => "JA",
        CSUB => "CSUB",
        RSUB => "RSUB",
        EI => "EI",
        DI => "DI",
        WAIT => "WAIT",
        STOP => "STOP",
        SAC => "SAC",
        SCO => "SCO",
        GCO => "GCO",
        CCO => "CCO",
        CALCX => "CALCX",
        AAP => "AAP",
        AGP => "AGP",
        CLE => "CLE",
        VECT => "VECT",
        RETI => "RETI",
        ACO => "ACO",
        CALCVV => "CALCVV",
        CALCVA => "CALCVA",
        CALCAV => "CALCAV",
        CALCVX => "CALCVX",
        CALCXV => "CALCXV",
        CALCV => "CALCV",
        MVPA => "MVPA",
        RST => "RST",
        DJNZ => "DJNZ",
        ROLA => "ROLA",
        RORA => "RORA",
        SIV => "SIV",
        GIV => "GIV",
        AIV => "AIV",
        64 => "UF0",
        65 => "UF1",
        66 => "UF2",
        67 => "UF3",
        68 => "UF4",
        69 => "UF5",
        70 => "UF6",
        71 => "UF7",
        CALL => "CALL",
        _ => return None,
    })
}

/// Instruction number of a mnemonic (case-insensitive).
pub fn from_mnemonic(name: &str) -> Option<u8> {
    (0..=255u8).find(|&op| mnemonic(op).is_some_and(|m| m.eq_ignore_ascii_case(name)))
}

/// A readable name for any instruction number, control commands included.
pub fn name(opcode: u8) -> &'static str {
    if let Some(m) = mnemonic(opcode).or_else(|| boot_name(opcode)) {
        return m;
    }
    match opcode {
        STOP_APPLICATION => "stop application",
        RUN_APPLICATION => "run application",
        STEP_APPLICATION => "step application",
        RESET_APPLICATION => "reset application",
        ENTER_DOWNLOAD => "enter download mode",
        EXIT_DOWNLOAD => "exit download mode",
        READ_MEMORY => "read program memory",
        APPLICATION_STATUS => "get application status",
        FIRMWARE_VERSION => "get firmware version",
        FACTORY_DEFAULTS => "restore factory settings",
        TARGET_REACHED_EVENT => "request target position reached event",
        ASCII_MODE => "enter ASCII mode",
        RESET => "software reset",
        _ => "unknown",
    }
}

/// Control commands (128…139, 255): direct mode only, never stored in a
/// program, executed even while downloading.
pub const fn is_control(opcode: u8) -> bool {
    matches!(opcode, 128..=139 | 255)
}
