//! How a slave names itself to a master (SII EEPROM, objects 0x1008 and
//! 0x1018): from its module's profile, `[features.ethercat]`.

use tmclsim_firmware::Profile;

/// How a slave names itself: SII EEPROM and objects 0x1008 and 0x1018.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Identity {
    /// The device name: the module's name.
    pub name: String,
    /// The EtherCAT vendor id.
    pub vendor_id: u32,
    /// The product code.
    pub product_code: u32,
    /// The firmware version: major in the high word, minor in the low.
    pub revision: u32,
    /// The order code (`TMCM-1310`).
    pub order_code: String,
    /// The device group the ESI file sorts the slave into.
    pub group: String,
}

impl Identity {
    /// The identity of a module whose profile makes it an EtherCAT slave;
    /// `None` for any other module.
    pub fn of(profile: &Profile) -> Option<Identity> {
        let e = profile.features.ethercat.as_ref()?;
        let [major, minor] = profile.module.firmware;
        Some(Identity {
            name: profile.module.name.clone(),
            vendor_id: e.vendor_id,
            product_code: e.product_code,
            revision: u32::from(major) << 16 | u32::from(minor),
            order_code: e.order_code.clone(),
            group: e.group.clone(),
        })
    }

    /// [`Identity::of`], or an error naming a module that is no EtherCAT
    /// slave.
    pub fn required(profile: &Profile) -> Result<Identity, NotASlave> {
        Identity::of(profile).ok_or_else(|| NotASlave { module: profile.module.name.clone() })
    }
}

/// A module whose profile has no `[features.ethercat]`: it cannot be an
/// EtherCAT slave.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NotASlave {
    /// The module's name (`TMCM-1141`).
    pub module: String,
}

impl std::fmt::Display for NotASlave {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} is no EtherCAT slave (its profile has no [features.ethercat])", self.module)
    }
}

impl std::error::Error for NotASlave {}

/// For callers whose errors are text (the command line).
impl From<NotASlave> for String {
    fn from(e: NotASlave) -> String {
        e.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_1310_names_itself_from_its_profile() {
        let id = Identity::of(&Profile::built_in("tmcm-1310").unwrap()).unwrap();
        assert_eq!((id.name.as_str(), id.vendor_id, id.product_code, id.revision), ("TMCM-1310", 0x286, 1310, 0x0001_000E));
        assert_eq!(Identity::of(&Profile::built_in("tmcm-1141").unwrap()), None, "no EtherCAT on the TMCM-1141");
    }
}
