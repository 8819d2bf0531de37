//! The parameter tables: which axis and global parameters a module has,
//! what access each gives (read, write, stored in the EEPROM, stored on
//! every write) and which values its SAP or SGP takes — the profile's
//! tables asked the way the parameter commands ask them, with the
//! statuses of a refusal.

use tmclsim_profile::{Access, Parameter, Profile};
use tmclsim_protocol::Status;

/// The axis parameter `param` if the module has it with the access `need`
/// asks for; status 3 (wrong type) if not.
pub fn axis_spec(profile: &Profile, param: u8, need: impl Fn(Access) -> bool) -> Result<&Parameter, Status> {
    let spec = profile.axis_parameter(param).ok_or(Status::WrongType)?;
    if need(spec.access) { Ok(spec) } else { Err(Status::WrongType) }
}

/// The global parameter `param` of `bank` if the module has it with the
/// access `need` asks for: status 4 (invalid value) for a bank the module
/// lacks, 3 (wrong type) for a parameter.
pub fn global_spec(profile: &Profile, param: u8, bank: u8, need: impl Fn(Access) -> bool) -> Result<&Parameter, Status> {
    if !profile.has_bank(bank) {
        return Err(Status::InvalidValue);
    }
    let spec = profile.global_parameter(bank, param).ok_or(Status::WrongType)?;
    if need(spec.access) { Ok(spec) } else { Err(Status::WrongType) }
}

/// The parameter takes `value` (SAP, SGP); status 4 if not.
pub fn takes(spec: &Parameter, value: i32) -> Result<(), Status> {
    if spec.accepts(value) { Ok(()) } else { Err(Status::InvalidValue) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn access_and_range_statuses() {
        let profile = Profile::built_in("tmcm-1141").unwrap();
        assert_eq!(axis_spec(&profile, 4, |a| a.write).map(|p| p.number), Ok(4));
        assert_eq!(axis_spec(&profile, 3, |a| a.write).err(), Some(Status::WrongType), "read-only");
        assert_eq!(axis_spec(&profile, 250, |a| a.read).err(), Some(Status::WrongType), "not in the table");
        assert_eq!(global_spec(&profile, 66, 7, |a| a.read).err(), Some(Status::InvalidValue), "no bank 7");
        let max_speed = axis_spec(&profile, 4, |a| a.write).unwrap();
        assert_eq!((takes(max_speed, 2047), takes(max_speed, 2048)), (Ok(()), Err(Status::InvalidValue)));
    }
}
