//! Replies in a host's words: how a reply frame is to be read (a normal
//! reply, the version text of 136 type 0, the stored word of 134), the
//! status in words, the value with the parameter's name and unit, and why
//! a parameter access failed.

use crate::names::{Table, table_of};
use tmclsim_profile::Profile;
use tmclsim_protocol::{FRAME_LEN, Instruction, Reply, Status, checksum, opcode};

/// How a reply frame is laid out (docs/behaviour.md rules 4 and 16).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// `[host][module][status][opcode][value][checksum]`.
    Normal,
    /// 136 type 0: the host address and eight characters, no checksum.
    Version,
    /// 134: the host address, the stored word's opcode, type, motor and
    /// value, the checksum.
    Memory,
}

/// How to read `raw`, the reply to `ins` sent to `address`. A 134 that
/// failed (address outside memory: 4; code protection: 5) answers with a
/// normal reply: the module address, an error status (below 100), opcode
/// 134 and a valid checksum. A stored word that reads exactly so (opcode
/// `address`, type below 100, motor 134) cannot be told apart and is taken
/// for the error.
pub fn shape(ins: Instruction, address: u8, raw: &[u8; FRAME_LEN]) -> Shape {
    match ins.opcode {
        opcode::FIRMWARE_VERSION if ins.kind == 0 => Shape::Version,
        opcode::READ_MEMORY if !is_memory_error(raw, address) => Shape::Memory,
        _ => Shape::Normal,
    }
}

/// Whether `raw`, the reply to a 134 sent to `address`, is the error reply
/// rather than a stored word (see [`shape`]).
fn is_memory_error(raw: &[u8; FRAME_LEN], address: u8) -> bool {
    raw[1] == address && raw[2] < 100 && raw[3] == opcode::READ_MEMORY && checksum(&raw[..8]) == raw[8]
}

/// The word a 134 sent to `address` read, or the error status it answered.
pub fn memory_word(raw: &[u8; FRAME_LEN], address: u8) -> Result<Instruction, u8> {
    if is_memory_error(raw, address) {
        return Err(raw[2]);
    }
    Ok(Instruction::from_bytes(raw[1..8].try_into().expect("seven bytes")))
}

/// One line (or two) for the reply to `ins`.
pub fn describe(ins: Instruction, raw: &[u8; FRAME_LEN], address: u8, profile: Option<&Profile>) -> String {
    describe_in(ins, raw, address, profile, None)
}

/// [`describe`], with the parameter's value in `unit` rather than the
/// profile's (a sixPoint module's speed in the unit its unit mode selects).
pub fn describe_in(ins: Instruction, raw: &[u8; FRAME_LEN], address: u8, profile: Option<&Profile>, unit: Option<&str>) -> String {
    match shape(ins, address, raw) {
        Shape::Version => return format!("version {}", String::from_utf8_lossy(&raw[1..])),
        Shape::Memory => {
            let stored = Instruction::from_bytes(raw[1..8].try_into().expect("seven bytes"));
            return format!("memory {}: {}", ins.value, tmclsim_protocol::mnemonic::format(stored));
        }
        Shape::Normal => {}
    }
    let Some(r) = Reply::decode(raw) else {
        return "the reply's checksum is wrong".into();
    };
    let status = Status::from_code(r.status);
    if r.status < 100 {
        let text = status.map_or(format!("status {} (unknown)", r.status), |s| format!("error {s}"));
        return match status.zip(profile).and_then(|(s, p)| hint(ins, s, p)) {
            Some(h) => format!("{text}: {h}"),
            None => text,
        };
    }
    let parameter = profile.and_then(|p| parameter(p, ins)).map(|(name, u)| (name, unit.map(str::to_string).or(u)));
    if ins.opcode == opcode::FIRMWARE_VERSION {
        let v = r.value as u32;
        return format!("module type {}, firmware V{}.{:02}", v >> 16, (v >> 8) & 0xFF, v & 0xFF);
    }
    let reads = matches!(
        ins.opcode,
        opcode::GAP
            | opcode::GGP
            | opcode::GIO
            | opcode::GCO
            | opcode::RFS
            | opcode::APPLICATION_STATUS
            | opcode::BOOT_GET_INFO
            | opcode::BOOT_GET_CHECKSUM
            | opcode::BOOT_READ_MEMORY
    );
    match (reads, parameter) {
        (true, Some((name, unit))) => format!("{name} = {}{}", r.value, unit.map_or(String::new(), |u| format!(" {u}"))),
        (false, Some((name, unit))) if matches!(ins.opcode, opcode::SAP | opcode::SGP) => {
            format!("ok: {name} = {}{}", ins.value, unit.map_or(String::new(), |u| format!(" {u}")))
        }
        (false, Some((name, _))) => format!("ok: {name}"),
        (true, None) => format!("value {}", r.value),
        (false, None) => "ok".into(),
    }
}

/// The parameter the instruction addresses.
fn spec(profile: &Profile, ins: Instruction) -> Option<&tmclsim_profile::Parameter> {
    match table_of(ins.opcode)? {
        Table::Axis => profile.axis_parameter(ins.kind),
        Table::Global => profile.global_parameter(ins.motor, ins.kind),
    }
}

/// The name and unit of the parameter the instruction addresses.
fn parameter(profile: &Profile, ins: Instruction) -> Option<(String, Option<String>)> {
    let p = spec(profile, ins)?;
    Some((format!("{} ({})", p.label(), p.number), p.unit.clone()))
}

/// Why a parameter command failed with `status`, where the profile tells
/// (docs/behaviour.md rule 6): no such motor or bank, no such parameter,
/// a parameter without the access the command needs, a value outside the
/// parameter's range.
pub fn hint(ins: Instruction, status: Status, profile: &Profile) -> Option<String> {
    let table = table_of(ins.opcode)?;
    let name = &profile.module.name;
    let spec = spec(profile, ins);
    let writes = matches!(ins.opcode, opcode::SAP | opcode::SGP | opcode::AAP | opcode::AGP);
    let reads = matches!(ins.opcode, opcode::GAP | opcode::GGP);
    match (status, table, spec) {
        (Status::InvalidValue, Table::Axis, _) if ins.motor >= profile.module.axes => Some(match profile.module.axes {
            1 => format!("the {name} has only motor 0, not motor {}", ins.motor),
            n => format!("the {name} has motors 0…{}, not motor {}", n - 1, ins.motor),
        }),
        (Status::InvalidValue, Table::Global, _) if !profile.has_bank(ins.motor) => Some(format!("the {name} has no bank {}", ins.motor)),
        (Status::WrongType, Table::Axis, None) => Some(format!("the {name} has no axis parameter {}", ins.kind)),
        (Status::WrongType, Table::Global, None) => Some(format!("the {name} has no global parameter {} in bank {}", ins.kind, ins.motor)),
        (Status::WrongType, _, Some(p)) if writes && !p.access.write => Some(format!("{} is read-only (access {})", p.label(), p.access)),
        (Status::WrongType, _, Some(p)) if reads && !p.access.read => Some(format!("{} cannot be read (access {})", p.label(), p.access)),
        (Status::InvalidValue, _, Some(p)) if writes => Some(format!("{} takes {}", p.label(), p.range_text())),
        _ => None,
    }
}

/// A failed command in words, for an exception's message: the command,
/// the parameter's name, the status with its code, and the [`hint`]:
/// `SAP 4, 0, 99999 (Maximum positioning speed): invalid value (status 4);
/// Maximum positioning speed takes 1…2047`.
pub fn explain(ins: Instruction, status: Status, profile: Option<&Profile>) -> String {
    let mut text = tmclsim_protocol::mnemonic::format(ins);
    if let Some(p) = profile.and_then(|p| spec(p, ins)) {
        text.push_str(&format!(" ({})", p.label()));
    }
    text.push_str(&format!(": {} (status {})", status.describe(), status.code()));
    if let Some(h) = profile.and_then(|p| hint(ins, status, p)) {
        text.push_str(&format!("; {h}"));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reply(status: u8, opcode: u8, value: i32) -> [u8; FRAME_LEN] {
        let mut f = [2, 1, status, opcode, 0, 0, 0, 0, 0];
        f[4..8].copy_from_slice(&value.to_be_bytes());
        f[8] = f[..8].iter().fold(0u8, |s, b| s.wrapping_add(*b));
        f
    }

    #[test]
    fn values_with_names_and_units_errors_with_reasons() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let p = Some(p.as_ref());
        let gap1 = Instruction::new(opcode::GAP, 1, 0, 0);
        assert_eq!(describe(gap1, &reply(100, 6, 51200), 1, p), "Actual position (1) = 51200 µsteps");
        assert_eq!(describe(gap1, &reply(100, 6, 51200), 1, None), "value 51200");
        let gap141 = Instruction::new(opcode::GAP, 141, 0, 0);
        assert_eq!(describe(gap141, &reply(3, 6, 0), 1, p), "error 3 (wrong type): the TMCM-1141 has no axis parameter 141");
        let sap = Instruction::new(opcode::SAP, 4, 0, 99_999);
        assert!(describe(sap, &reply(4, 5, 99_999), 1, p).starts_with("error 4 (invalid value): Maximum positioning speed takes 1…2047"));
        let version = Instruction::new(opcode::FIRMWARE_VERSION, 1, 0, 0);
        assert_eq!(describe(version, &reply(100, 136, (1141 << 16) | (1 << 8) | 46), 1, p), "module type 1141, firmware V1.46");
        let mut bad = reply(100, 6, 1);
        bad[8] ^= 1;
        assert_eq!(describe(gap1, &bad, 1, p), "the reply's checksum is wrong");
    }

    #[test]
    fn a_134_reply_is_a_stored_word_unless_it_is_an_error_reply() {
        let read = Instruction::new(opcode::READ_MEMORY, 0, 0, 7);
        // Rule 16: the stored word (MVP ABS, 0, 51200) where a normal
        // reply has module address, status, opcode and value.
        let mut word = [2, opcode::MVP, 0, 0, 0, 0, 0xC8, 0x00, 0];
        word[8] = checksum(&word[..8]);
        assert_eq!(shape(read, 1, &word), Shape::Memory);
        assert_eq!(memory_word(&word, 1), Ok(Instruction::new(opcode::MVP, 0, 0, 51200)));
        assert_eq!(describe(read, &word, 1, None), "memory 7: MVP ABS, 0, 51200");
        // Outside memory: status 4; code protection (rule 30): status 5,
        // as normal replies with opcode 134.
        for status in [Status::InvalidValue, Status::EepromLocked] {
            let raw = reply(status.code(), opcode::READ_MEMORY, 7);
            assert_eq!(shape(read, 1, &raw), Shape::Normal);
            assert_eq!(memory_word(&raw, 1), Err(status.code()));
            assert_eq!(describe(read, &raw, 1, None), format!("error {status}"));
        }
        // The same bytes from another address, or with a wrong checksum,
        // are no error reply of this module.
        let raw = reply(4, opcode::READ_MEMORY, 7);
        assert_eq!(shape(read, 2, &raw), Shape::Memory);
        let mut bad = raw;
        bad[8] ^= 1;
        assert_eq!(shape(read, 1, &bad), Shape::Memory);
        // Only 134 has the special reply; 136 type 0 answers text.
        assert_eq!(shape(Instruction::new(opcode::GAP, 1, 0, 0), 1, &word), Shape::Normal);
        assert_eq!(shape(Instruction::new(opcode::FIRMWARE_VERSION, 0, 0, 0), 1, b"\x021141V146"), Shape::Version);
    }

    #[test]
    fn failed_parameter_commands_explained_by_rule_6() {
        let p = Profile::built_in("tmcm-1141").unwrap();
        let p = Some(p.as_ref());
        let explain = |line: &str, status| explain(tmclsim_protocol::mnemonic::parse_line(line).unwrap(), status, p);
        assert_eq!(
            explain("SAP 4, 0, 99999", Status::InvalidValue),
            "SAP 4, 0, 99999 (Maximum positioning speed): invalid value (status 4); Maximum positioning speed takes 1…2047"
        );
        assert_eq!(explain("GAP 250, 0", Status::WrongType), "GAP 250, 0: wrong type (status 3); the TMCM-1141 has no axis parameter 250");
        assert_eq!(
            explain("SAP 3, 0, 5", Status::WrongType),
            "SAP 3, 0, 5 (Actual speed): wrong type (status 3); Actual speed is read-only (access R)"
        );
        assert!(explain("GAP 1, 3", Status::InvalidValue).ends_with("; the TMCM-1141 has only motor 0, not motor 3"));
        assert!(explain("GGP 0, 1", Status::InvalidValue).ends_with("; the TMCM-1141 has no bank 1"));
        assert_eq!(explain("GGP 132, 0", Status::EepromLocked), "GGP 132, 0 (TMCL tick timer): configuration EEPROM locked (status 5)");
        // Without a profile: the command and the status.
        assert_eq!(
            super::explain(Instruction::new(opcode::GAP, 1, 0, 0), Status::InvalidValue, None),
            "GAP 1, 0: invalid value (status 4)"
        );
        let p351 = Profile::built_in("tmcm-351").unwrap();
        assert_eq!(
            describe(Instruction::new(opcode::GAP, 1, 3, 0), &reply(4, 6, 0), 1, Some(&p351)),
            "error 4 (invalid value): the TMCM-351 has motors 0…2, not motor 3"
        );
    }
}
