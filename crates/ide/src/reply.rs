//! A reply as the console shows it: the status in words, and the value
//! with the parameter's name and unit.

use crate::names::{Table, table_of};
use tmclsim_profile::Profile;
use tmclsim_protocol::{FRAME_LEN, Instruction, Reply, Status, opcode};

/// One line (or two) for the reply to `ins`.
pub fn describe(ins: Instruction, raw: &[u8; FRAME_LEN], address: u8, profile: Option<&Profile>) -> String {
    if ins.opcode == opcode::FIRMWARE_VERSION && ins.kind == 0 {
        return format!("version {}", String::from_utf8_lossy(&raw[1..]));
    }
    // 134 answers with the stored instruction in place of the address.
    let failed = raw[1] == address && raw[2] < 100 && raw[3] == opcode::READ_MEMORY;
    if ins.opcode == opcode::READ_MEMORY && !failed {
        let stored = Instruction::from_bytes(raw[1..8].try_into().expect("seven bytes"));
        return format!("memory {}: {}", ins.value, tmclsim_protocol::mnemonic::format(stored));
    }
    let Some(r) = Reply::decode(raw) else {
        return "the reply's checksum is wrong".into();
    };
    let status = Status::from_code(r.status);
    if r.status < 100 {
        let text = status.map_or(format!("status {} (unknown)", r.status), |s| format!("error {s}"));
        return match hint(ins, r.status, profile) {
            Some(h) => format!("{text}: {h}"),
            None => text,
        };
    }
    let parameter = profile.and_then(|p| parameter(p, ins));
    if ins.opcode == opcode::FIRMWARE_VERSION {
        let v = r.value as u32;
        return format!("module type {}, firmware V{}.{:02}", v >> 16, (v >> 8) & 0xFF, v & 0xFF);
    }
    let reads = matches!(ins.opcode, opcode::GAP | opcode::GGP | opcode::GIO | opcode::GCO | opcode::RFS | opcode::APPLICATION_STATUS);
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

/// The name and unit of the parameter the instruction addresses.
fn parameter(profile: &Profile, ins: Instruction) -> Option<(String, Option<String>)> {
    let p = match table_of(ins.opcode)? {
        Table::Axis => profile.axis_parameter(ins.kind)?,
        Table::Global => profile.global_parameter(ins.motor, ins.kind)?,
    };
    Some((format!("{} ({})", p.label(), p.number), p.unit.clone()))
}

/// Why a command failed, where the profile tells.
fn hint(ins: Instruction, status: u8, profile: Option<&Profile>) -> Option<String> {
    let profile = profile?;
    let name = &profile.module.name;
    match (table_of(ins.opcode), status) {
        (Some(Table::Axis), 4) if ins.motor >= profile.module.axes => Some(format!("the {name} has motors 0…{}", profile.module.axes - 1)),
        (Some(Table::Axis), 3) if profile.axis_parameter(ins.kind).is_none() => {
            Some(format!("the {name} has no axis parameter {}", ins.kind))
        }
        (Some(Table::Global), 3) if profile.global_parameter(ins.motor, ins.kind).is_none() => {
            Some(format!("the {name} has no global parameter {} in bank {}", ins.kind, ins.motor))
        }
        (Some(Table::Axis), 4) => profile.axis_parameter(ins.kind).map(|p| format!("{} takes {}…{}", p.label(), p.min, p.max)),
        (Some(Table::Global), 4) => {
            profile.global_parameter(ins.motor, ins.kind).map(|p| format!("{} takes {}…{}", p.label(), p.min, p.max))
        }
        _ => None,
    }
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
}
