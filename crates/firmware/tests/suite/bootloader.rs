//! The TMCL bootloader (docs/behaviour.md rules 99–103), driven by frames
//! in the order PyTrinamic's firmware update tool (`tmclfwupload`) sends
//! them: 136, 242, 136 at address 1, BOOT_GET_INFO 0–2, BOOT_ERASE_ALL, the
//! words and pages, BOOT_GET_CHECKSUM of the last address, BOOT_WRITE_LENGTH
//! 0 and 1, BOOT_START_APPL.

use crate::common::{BusOfOne, power_cycle, send, status};
use tmclsim_firmware::bootloader::image;
use tmclsim_firmware::{Eeprom, Firmware, Module};
use tmclsim_protocol::{Instruction, Reply, Request};

/// A frame to `address`; the module's reply, if it sends one.
fn ask(m: &mut Module, address: u8, opcode: u8, kind: u8, motor: u8, value: u32) -> Option<Reply> {
    let frame = Request::new(address, Instruction::new(opcode, kind, motor, value as i32)).encode();
    m.handle_frame(&frame).map(|r| Reply::decode(&r).unwrap())
}

/// A bootloader command to address 1 that must succeed; its value.
fn boot(m: &mut Module, opcode: u8, kind: u8, motor: u8, value: u32) -> u32 {
    let r = ask(m, 1, opcode, kind, motor, value).unwrap_or_else(|| panic!("#{opcode}: no reply"));
    assert_eq!(r.status, 100, "#{opcode} {kind} {motor} {value:#x}");
    r.value as u32
}

/// The 8 characters of a 136 type 0 reply to `address`.
fn version_text(m: &mut Module, address: u8) -> String {
    let frame = Request::new(address, Instruction::new(136, 0, 0, 0)).encode();
    let reply = m.handle_frame(&frame).expect("136 is answered");
    String::from_utf8_lossy(&reply[1..]).into_owned()
}

const MAGIC: (u8, u8, u32) = (0x81, 0x92, 0xA3B4_C5D6);

/// 242 with its key, to the module's address: no reply.
fn enter(m: &mut Module, address: u8) {
    assert!(ask(m, address, 242, MAGIC.0, MAGIC.1, MAGIC.2).is_none(), "242 is not answered");
}

/// What the update tool does after the bootloader answered: erase, write
/// `bytes` word by word and page by page, compare the checksum, write
/// length and checksum. Returns the checksum the module computed.
fn write_image(m: &mut Module, bytes: &[u8]) -> u32 {
    let page = boot(m, 206, 0, 0, 0);
    let start = boot(m, 206, 1, 0, 0);
    boot(m, 200, 0, 0, 0);
    let mut current = start / page * page;
    for (i, word) in bytes.chunks(4).enumerate() {
        let addr = start + 4 * i as u32;
        let this = addr / page * page;
        if this != current {
            boot(m, 202, 0, 0, current);
            current = this;
        }
        let mut w = [0u8; 4];
        w[..word.len()].copy_from_slice(word);
        let index = (addr - this) / 4;
        boot(m, 201, (index % 256) as u8, (index / 256) as u8, u32::from_le_bytes(w));
    }
    boot(m, 202, 0, 0, current);
    let sum = bytes.iter().fold(0u32, |s, &b| s.wrapping_add(u32::from(b)));
    let theirs = boot(m, 203, 0, 0, start + bytes.len() as u32 - 1);
    assert_eq!(theirs, sum, "BOOT_GET_CHECKSUM of the last address");
    boot(m, 208, 0, 0, bytes.len() as u32);
    boot(m, 208, 1, 0, sum);
    theirs
}

fn facts(m: &Module) -> tmclsim_firmware::profile::Bootloader {
    m.profile().bootloader.clone().expect("a bootloader")
}

#[test]
fn boot_restarts_into_the_bootloader_which_answers_at_address_1_as_itself_only() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "SGP 66, 0, 3");
    assert_eq!(version_text(&mut m, 3), "1141V146");
    enter(&mut m, 3);
    assert!(m.in_bootloader());
    // At the bootloader's address, not GP 66's.
    assert!(ask(&mut m, 3, 136, 0, 0, 0).is_none());
    assert_eq!(version_text(&mut m, 1), "1141B106");
    assert_eq!(boot(&mut m, 136, 1, 0, 0), 1141 << 16 | 1 << 8 | 6);
    let f = facts(&m);
    assert_eq!(
        (boot(&mut m, 206, 0, 0, 0), boot(&mut m, 206, 1, 0, 0), boot(&mut m, 206, 2, 0, 0)),
        (f.page_size, f.flash_start, f.flash_size)
    );
    assert_eq!(ask(&mut m, 1, 206, 3, 0, 0).unwrap().status, 3, "no such type");
    // The firmware's commands are not there (status 2, invalid command).
    assert_eq!(status(&mut m, "GAP 1, 0"), 2);
    assert_eq!(status(&mut m, "SAP 4, 0, 100"), 2);
    assert_eq!(ask(&mut m, 1, 255, 0, 0, 1234).unwrap().status, 2);
    // BOOT_START_APPL with the factory firmware untouched: back in it.
    assert!(ask(&mut m, 1, 205, 0, 0, 0).is_none());
    assert!(!m.in_bootloader());
    assert_eq!(version_text(&mut m, 3), "1141V146");
}

#[test]
fn boot_without_its_key_is_answered_and_does_nothing_and_modules_without_a_bootloader_lack_it() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    let r = ask(&mut m, 1, 242, 0x81, 0x92, 0x1234).unwrap();
    assert_eq!(r.status, 100);
    assert!(!m.in_bootloader());
    let mut other = BusOfOne::built_in("tmcm-6110");
    assert_eq!(ask(&mut other, 1, 242, MAGIC.0, MAGIC.1, MAGIC.2).unwrap().status, 2);
}

#[test]
fn a_complete_update_installs_its_version_and_keeps_the_eeprom_and_the_program() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "SAP 4, 0, 777");
    send(&mut m, "STAP 4, 0");
    for line in ["#132 0 0 0", "ROL 0, 500", "STOP", "#133 0 0 0"] {
        assert!(status(&mut m, line) >= 100, "{line}");
    }
    assert_eq!(m.eeprom().program.len(), 2, "the program is stored");
    let program = m.eeprom().program.clone();
    enter(&mut m, 1);
    let f = facts(&m);
    write_image(&mut m, &image(&f, [1, 47]));
    assert_eq!(m.eeprom().firmware, Firmware::Installed { version: [1, 47] }, "kept once length and checksum match");
    assert!(ask(&mut m, 1, 205, 0, 0, 0).is_none(), "BOOT_START_APPL is not answered");
    assert!(!m.in_bootloader());
    assert_eq!(version_text(&mut m, 1), "1141V147");
    assert_eq!(send(&mut m, "#136 1 0 0"), 1141 << 16 | 1 << 8 | 47);
    assert_eq!(send(&mut m, "GAP 4, 0"), 777, "the stored axis parameter");
    assert_eq!(m.eeprom().program, program, "the stored TMCL program");
    // And after a power cycle, and after 137 (factory defaults of the
    // EEPROM, not of the flash).
    let mut again = power_cycle(&m);
    assert_eq!(version_text(&mut again, 1), "1141V147");
    assert!(again.handle_frame(&crate::common::frame("#137 0 0 1234")).is_none());
    assert_eq!(version_text(&mut again, 1), "1141V147");
}

#[test]
fn an_update_interrupted_after_the_erase_leaves_the_bootloader_until_a_complete_one() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "SGP 66, 0, 5");
    enter(&mut m, 5);
    boot(&mut m, 200, 0, 0, 0);
    boot(&mut m, 201, 0, 0, 0xDEAD_BEEF);
    assert_eq!(m.eeprom().firmware, Firmware::Invalid);
    // The power goes: the module comes up in its bootloader, at address 1.
    let mut m = power_cycle(&m);
    assert!(m.in_bootloader());
    assert!(ask(&mut m, 5, 6, 1, 0, 0).is_none(), "nothing answers at GP 66's address");
    assert_eq!(version_text(&mut m, 1), "1141B106");
    // BOOT_START_APPL cannot start what is not there.
    assert!(ask(&mut m, 1, 205, 0, 0, 0).is_none());
    assert!(m.in_bootloader());
    // The update tool's second run: the module is in the bootloader already.
    let f = facts(&m);
    write_image(&mut m, &image(&f, [1, 46]));
    assert!(ask(&mut m, 1, 205, 0, 0, 0).is_none());
    assert!(!m.in_bootloader());
    assert_eq!(version_text(&mut m, 5), "1141V146", "back at its own address");
}

#[test]
fn an_image_of_another_module_or_with_a_wrong_checksum_is_not_started() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    enter(&mut m, 1);
    let f = facts(&m);
    let mut foreign = image(&f, [1, 47]);
    foreign[0x200..0x208].copy_from_slice(b"6110V147");
    write_image(&mut m, &foreign);
    assert_eq!(m.eeprom().firmware, Firmware::Invalid, "no version string of this module");
    assert!(ask(&mut m, 1, 205, 0, 0, 0).is_none());
    assert!(m.in_bootloader());
    let bytes = image(&f, [1, 47]);
    let sum = write_image(&mut m, &bytes);
    boot(&mut m, 208, 1, 0, sum ^ 1);
    assert_eq!(m.eeprom().firmware, Firmware::Invalid, "length and checksum do not match the flash");
    assert!(power_cycle(&m).in_bootloader());
}

#[test]
fn outside_the_flash_or_the_page_is_status_4() {
    let mut m = BusOfOne::built_in("tmcm-1141");
    enter(&mut m, 1);
    let f = facts(&m);
    boot(&mut m, 200, 0, 0, 0);
    let words = f.page_size / 4;
    assert_eq!(ask(&mut m, 1, 201, (words % 256) as u8, (words / 256) as u8, 0).unwrap().status, 4);
    assert_eq!(ask(&mut m, 1, 202, 0, 0, f.flash_start - f.page_size).unwrap().status, 4);
    assert_eq!(ask(&mut m, 1, 202, 0, 0, f.flash_start + 2).unwrap().status, 4);
    assert_eq!(ask(&mut m, 1, 203, 0, 0, f.flash_start + f.flash_size).unwrap().status, 4);
    assert_eq!(ask(&mut m, 1, 208, 0, 0, f.flash_size + 1).unwrap().status, 4);
    assert_eq!(ask(&mut m, 1, 208, 2, 0, 1).unwrap().status, 3);
}

#[test]
fn the_tmcm_351_takes_an_image_with_its_three_digit_version_string() {
    let mut m = BusOfOne::built_in("tmcm-351");
    assert_eq!(version_text(&mut m, 1), "351V.445");
    enter(&mut m, 1);
    assert_eq!(version_text(&mut m, 1), "351B1.02");
    let f = facts(&m);
    let bytes = image(&f, [4, 46]);
    assert_eq!(&bytes[0x200..0x208], b"351V4.46", "the form update tools look for");
    write_image(&mut m, &bytes);
    assert!(ask(&mut m, 1, 205, 0, 0, 0).is_none());
    assert_eq!(version_text(&mut m, 1), "351V.446", "in the manual's form");
    assert_eq!(send(&mut m, "#136 1 0 0"), 351 << 16 | 4 << 8 | 46);
}

#[test]
fn the_firmware_state_is_kept_in_the_eeprom_image() {
    let mut e = Eeprom::new("TMCM-1141");
    assert!(!e.to_json().contains("firmware"), "the factory firmware is not written");
    e.firmware = Firmware::Installed { version: [1, 47] };
    assert_eq!(Eeprom::from_json(&e.to_json()).unwrap().firmware, e.firmware);
    e.firmware = Firmware::Invalid;
    assert!(e.to_json().contains("\"invalid\""));
    assert_eq!(Eeprom::from_json(&e.to_json()).unwrap().firmware, Firmware::Invalid);
    assert!(Module::with_eeprom(tmclsim_firmware::Profile::built_in("tmcm-1141").unwrap(), e).in_bootloader());
}

#[test]
fn every_sixpoint_and_eight_point_module_updates_through_its_bootloader() {
    use tmclsim_profile::MotionController;
    for name in tmclsim_firmware::Profile::names() {
        let profile = tmclsim_firmware::Profile::built_in(name).unwrap();
        if !matches!(profile.features.motion_controller, MotionController::Sixpoint | MotionController::Eightpoint) {
            continue;
        }
        let digits = profile.module.type_number.to_string();
        let [major, minor] = profile.module.firmware;
        // What the module stores: A1 with STAP where it has STAP (the
        // eight-point modules have none), a user variable with STGP.
        let stap = profile.has_opcode(7);
        let mut m = BusOfOne::built_in(name);
        if stap {
            send(&mut m, "SAP 15, 0, 4321");
            send(&mut m, "STAP 15, 0");
        }
        send(&mut m, "SGP 3, 2, 1234");
        send(&mut m, "STGP 3, 2");
        assert_eq!(version_text(&mut m, 1), format!("{digits}V{major}{minor:02}"), "{name}");
        enter(&mut m, 1);
        assert_eq!(version_text(&mut m, 1), format!("{digits}B100"), "{name}: the bootloader's text");
        let f = facts(&m);
        write_image(&mut m, &image(&f, [major, minor + 1]));
        assert!(ask(&mut m, 1, 205, 0, 0, 0).is_none(), "{name}: BOOT_START_APPL");
        assert_eq!(version_text(&mut m, 1), format!("{digits}V{major}{:02}", minor + 1), "{name}: the new version");
        if stap {
            assert_eq!(send(&mut m, "GAP 15, 0"), 4321, "{name}: the stored A1 is kept");
        }
        assert_eq!(send(&mut m, "GGP 3, 2"), 1234, "{name}: the stored user variable is kept");
    }
}
