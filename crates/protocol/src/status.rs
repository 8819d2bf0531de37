//! TMCL reply status codes (TMCM-1141 manual, table 4).

/// The status byte of a TMCL reply.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Status {
    /// 1: the frame's checksum is wrong.
    WrongChecksum = 1,
    /// 2: the opcode is unknown or not available on this module.
    InvalidCommand = 2,
    /// 3: the type (or parameter number) is out of range or not accessible.
    WrongType = 3,
    /// 4: the value (or motor/bank number) is out of range.
    InvalidValue = 4,
    /// 5: the configuration EEPROM is locked.
    EepromLocked = 5,
    /// 6: the command is not available (in this mode).
    NotAvailable = 6,
    /// 100: successfully executed.
    Ok = 100,
    /// 101: command loaded into the TMCL program memory.
    Loaded = 101,
    /// 128: unsolicited "target position reached" event (command 138).
    Event = 128,
}

impl Status {
    /// The status byte.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The status of a byte, when TMCL defines it.
    pub fn from_code(code: u8) -> Option<Status> {
        Some(match code {
            1 => Status::WrongChecksum,
            2 => Status::InvalidCommand,
            3 => Status::WrongType,
            4 => Status::InvalidValue,
            5 => Status::EepromLocked,
            6 => Status::NotAvailable,
            100 => Status::Ok,
            101 => Status::Loaded,
            128 => Status::Event,
            _ => return None,
        })
    }

    /// True for the codes below 100, which report an error.
    pub const fn is_error(self) -> bool {
        (self as u8) < 100
    }

    /// Any status code in words: the status's own, or "unknown status N"
    /// for a code TMCL does not define.
    pub fn text(code: u8) -> std::borrow::Cow<'static, str> {
        match Status::from_code(code) {
            Some(s) => s.describe().into(),
            None => format!("unknown status {code}").into(),
        }
    }

    /// The status in words (`wrong checksum`).
    pub const fn describe(self) -> &'static str {
        match self {
            Status::WrongChecksum => "wrong checksum",
            Status::InvalidCommand => "invalid command",
            Status::WrongType => "wrong type",
            Status::InvalidValue => "invalid value",
            Status::EepromLocked => "configuration EEPROM locked",
            Status::NotAvailable => "command not available",
            Status::Ok => "ok",
            Status::Loaded => "command loaded into program memory",
            Status::Event => "target position reached",
        }
    }
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({})", self.code(), self.describe())
    }
}

#[cfg(test)]
mod tests {
    use super::Status;

    #[test]
    fn every_code_has_its_words_and_an_undefined_one_says_so() {
        // The reply status codes of the firmware manuals (TMCM-1141 V1.46,
        // reply format), and one TMCL does not define.
        let words: Vec<String> = [1, 2, 3, 4, 5, 6, 100, 101, 128, 7].iter().map(|&c| Status::text(c).into_owned()).collect();
        assert_eq!(
            words,
            [
                "wrong checksum",
                "invalid command",
                "wrong type",
                "invalid value",
                "configuration EEPROM locked",
                "command not available",
                "ok",
                "command loaded into program memory",
                "target position reached",
                "unknown status 7",
            ]
        );
    }
}
