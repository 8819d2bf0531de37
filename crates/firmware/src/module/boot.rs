//! The TMCL bootloader as the module runs it (docs/behaviour.md rules
//! 99–103): 242 restarts the firmware into it; while it runs, the module
//! answers only the bootloader's commands, at the bootloader's address;
//! a firmware update's end (BOOT_START_APPL) or a power-up with a valid
//! firmware leaves it. The flash and its page buffer are the bootloader
//! part's (`bootloader.rs`); the firmware in flash is kept with the EEPROM.

use crate::bootloader::{Refused, Session};
use crate::eeprom::Firmware;
use crate::module::Module;
use crate::outcome::{Outcome, Special};
use tmclsim_profile::Bootloader as Facts;
use tmclsim_protocol::frame::version_string_reply;
use tmclsim_protocol::{Instruction, Status, opcode};

impl Module {
    /// The bootloader's answer to a command, when the module has one and
    /// it runs (or the command is 242); `None`: the firmware executes it.
    pub(crate) fn boot_command(&mut self, ins: Instruction) -> Option<Outcome> {
        // Every direct-mode command passes here: the firmware's go on at once.
        if self.boot.is_none() && ins.opcode != opcode::BOOT {
            return None;
        }
        let profile = self.profile.clone();
        let facts = profile.bootloader.as_ref()?;
        if self.boot.is_none() {
            // A 242 without the key is answered and does nothing, as the
            // firmware does (rule 99).
            if (ins.kind, ins.motor, ins.value as u32) != opcode::BOOT_MAGIC {
                return Some(Outcome::ok(ins.value));
            }
            self.enter_bootloader(facts, false);
            return Some(silent());
        }
        let value = ins.value as u32;
        let answer = match ins.opcode {
            opcode::FIRMWARE_VERSION if ins.kind == 0 => {
                let text = <[u8; 8]>::try_from(facts.version_text.as_bytes()).expect("checked when the profile loads");
                return Some(Outcome {
                    status: Status::Ok,
                    value: 0,
                    special: Special::Frame(version_string_reply(self.host_address(), &text)),
                });
            }
            opcode::FIRMWARE_VERSION if ins.kind == 1 => Ok(bootloader_word(&profile.module.type_number, facts)),
            opcode::BOOT_GET_INFO => match ins.kind {
                0 => Ok(facts.page_size),
                1 => Ok(facts.flash_start),
                2 => Ok(facts.flash_size),
                _ => Err(Refused::Type),
            },
            opcode::BOOT_ERASE_ALL => {
                self.session().erase(facts);
                self.persistence.set_firmware(Firmware::Invalid);
                Ok(0)
            }
            opcode::BOOT_WRITE_BUFFER => self.session().write_buffer(u32::from(ins.motor) << 8 | u32::from(ins.kind), value).map(|()| 0),
            opcode::BOOT_WRITE_PAGE => self.session().write_page(facts, value).map(|()| 0),
            opcode::BOOT_GET_CHECKSUM => self.session().checksum_through(facts, value),
            opcode::BOOT_READ_MEMORY => self.session().read_word(facts, value),
            opcode::BOOT_WRITE_LENGTH => self.session().write_length(facts, ins.kind, value).map(|()| {
                // Complete and this module's: the firmware a power-up starts;
                // otherwise the bootloader stays (rule 100).
                let firmware = match self.session().complete_firmware(facts) {
                    Some(version) => Firmware::Installed { version },
                    None => Firmware::Invalid,
                };
                self.persistence.set_firmware(firmware);
                0
            }),
            opcode::BOOT_START_APPL => {
                if self.persistence.eeprom().firmware != Firmware::Invalid {
                    self.resets += 1;
                    self.power_on();
                }
                return Some(silent());
            }
            opcode::BOOT => return Some(silent()),
            _ => return Some(Outcome::error(Status::InvalidCommand, ins.value)),
        };
        Some(match answer {
            Ok(v) => Outcome::ok(v as i32),
            Err(Refused::Value) => Outcome::error(Status::InvalidValue, ins.value),
            Err(Refused::Type) => Outcome::error(Status::WrongType, ins.value),
        })
    }

    fn session(&mut self) -> &mut Session {
        self.boot.as_mut().expect("the bootloader runs")
    }

    /// True while the module runs its bootloader (it answers only the
    /// bootloader's commands, at the bootloader's address).
    pub fn in_bootloader(&self) -> bool {
        self.boot.is_some()
    }

    /// The firmware version the module runs: the factory's, or the one a
    /// firmware update installed (rule 101).
    pub fn firmware_version(&self) -> [u8; 2] {
        match self.persistence.eeprom().firmware {
            Firmware::Installed { version } => version,
            _ => self.profile.module.firmware,
        }
    }
}

fn silent() -> Outcome {
    Outcome { status: Status::Ok, value: 0, special: Special::Silent }
}

/// 136 type 1 in the bootloader: the module number, then the bootloader's
/// version (`1141B106`: 1141, 1, 6).
fn bootloader_word(type_number: &u16, facts: &Facts) -> u32 {
    let digits: Vec<u32> =
        facts.version_text.split('B').nth(1).unwrap_or_default().bytes().filter(u8::is_ascii_digit).map(|b| u32::from(b - b'0')).collect();
    let major = digits.first().copied().unwrap_or(0);
    let minor = digits.iter().skip(1).fold(0, |m, d| m * 10 + d) % 256;
    u32::from(*type_number) << 16 | major << 8 | minor
}
