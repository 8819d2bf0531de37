//! The slave's SII EEPROM: identity, mailbox configuration and the
//! categories a master reads to configure it (strings, general, FMMU,
//! SyncManagers, PDOs). Word addressed, little endian.

use crate::identity::Identity;

/// Process RAM layout (tmcm-1310.md): outputs at 0x1000 (8 bytes), inputs
/// at 0x1078 (48 bytes); the standard mailboxes behind them, the bootstrap
/// mailboxes as the manual gives them.
pub const OUTPUTS: u16 = 0x1000;
pub const OUTPUTS_LEN: u16 = 8;
pub const INPUTS: u16 = 0x1078;
pub const INPUTS_LEN: u16 = 48;
pub const MAILBOX_OUT: u16 = 0x1100;
pub const MAILBOX_IN: u16 = 0x1180;
pub const MAILBOX_LEN: u16 = 128;
pub const BOOT_MAILBOX_OUT: u16 = 4096;
pub const BOOT_MAILBOX_OUT_LEN: u16 = 268;
pub const BOOT_MAILBOX_IN: u16 = 4364;
pub const BOOT_MAILBOX_IN_LEN: u16 = 40;

/// SyncManager control bytes: mailbox write, mailbox read, buffered
/// write (outputs), buffered read (inputs).
pub const SM_CONTROL: [u8; 4] = [0x26, 0x22, 0x64, 0x20];
/// (start, length) of SyncManagers 0…3.
pub const SM_LAYOUT: [(u16, u16); 4] =
    [(MAILBOX_OUT, MAILBOX_LEN), (MAILBOX_IN, MAILBOX_LEN), (OUTPUTS, OUTPUTS_LEN), (INPUTS, INPUTS_LEN)];

/// Mailbox protocols: CoE (TMCL is carried by SDOs of object 0x2000).
pub const MAILBOX_PROTOCOLS: u16 = 0x0004;

/// The names of the twelve input fields (TxPDO 0x1A00, objects 0x6000:01…0C).
pub const INPUT_NAMES: [&str; 12] = [
    "Target position",
    "Actual position",
    "Virtual actual position",
    "Encoder position",
    "Target velocity",
    "Actual velocity",
    "Measured velocity",
    "Status word",
    "Error flags",
    "Scaler",
    "Delta/torque",
    "Gamma",
];

fn push_u32(w: &mut Vec<u16>, v: u32) {
    w.push(v as u16);
    w.push((v >> 16) as u16);
}

/// Bytes → words (odd lengths padded).
fn words(bytes: &[u8]) -> Vec<u16> {
    bytes.chunks(2).map(|c| u16::from(c[0]) | u16::from(*c.get(1).unwrap_or(&0)) << 8).collect()
}

fn category(w: &mut Vec<u16>, kind: u16, bytes: &[u8]) {
    let data = words(bytes);
    w.push(kind);
    w.push(data.len() as u16);
    w.extend(data);
}

/// The EEPROM image of a slave named `id`, with a serial number.
pub fn image(id: &Identity, serial: u32) -> Vec<u16> {
    let mut w = vec![0u16; 0x40];
    // 0x0000…0x0007: PDI control/configuration, alias 0, checksum.
    w[0] = 0x0080;
    w[1] = 0x0000;
    // 0x0008…0x000F: identity.
    let mut words = Vec::new();
    push_u32(&mut words, id.vendor_id);
    push_u32(&mut words, id.product_code);
    push_u32(&mut words, id.revision);
    push_u32(&mut words, serial);
    w[8..16].copy_from_slice(&words);
    // 0x0014…0x0017 bootstrap mailboxes, 0x0018…0x001B standard mailboxes.
    w[0x14] = BOOT_MAILBOX_OUT;
    w[0x15] = BOOT_MAILBOX_OUT_LEN;
    w[0x16] = BOOT_MAILBOX_IN;
    w[0x17] = BOOT_MAILBOX_IN_LEN;
    w[0x18] = MAILBOX_OUT;
    w[0x19] = MAILBOX_LEN;
    w[0x1A] = MAILBOX_IN;
    w[0x1B] = MAILBOX_LEN;
    w[0x1C] = MAILBOX_PROTOCOLS | 0x0008; // + FoE in bootstrap
    w[0x3E] = 0x000F; // EEPROM size: 16 kbit - 1 …
    w[0x3F] = 0x0001; // … version 1
    // Strings: 1 name, 2 group, 3 image, 4 order, 5 RxPDO, 6 TxPDO,
    // 7 "Controller mode", 8 "Set-point", 9… the input names.
    let mut strings: Vec<&str> = vec![&id.name, &id.group, &id.name, &id.order_code, "Outputs", "Inputs", "Controller mode", "Set-point"];
    strings.extend(INPUT_NAMES);
    let mut s = vec![strings.len() as u8];
    for t in &strings {
        s.push(t.len() as u8);
        s.extend_from_slice(t.as_bytes());
    }
    category(&mut w, 10, &s);
    // General: group 2, image 3, order 4, name 1, CoE details (SDO), FoE,
    // EoE, SoE, DS402, sysman, flags, EBus current.
    let mut g = vec![2u8, 3, 4, 1, 0, 0x01, 0x01, 0, 0, 0, 0, 0, 0, 0, 0, 0];
    g.resize(32, 0);
    category(&mut w, 30, &g);
    // FMMUs: outputs, inputs, SyncManager status.
    category(&mut w, 40, &[1, 2, 3, 0]);
    // SyncManagers 0…3 (start, length, control, status, enable, type).
    let mut sm = Vec::new();
    for (i, (start, len)) in SM_LAYOUT.iter().enumerate() {
        sm.extend_from_slice(&start.to_le_bytes());
        sm.extend_from_slice(&len.to_le_bytes());
        sm.extend_from_slice(&[SM_CONTROL[i], 0, 1, i as u8 + 1]);
    }
    category(&mut w, 41, &sm);
    // TxPDO 0x1A00 on SM3: twelve 32-bit entries 0x6000:01…0C.
    let mut tx = Vec::new();
    tx.extend_from_slice(&0x1A00u16.to_le_bytes());
    tx.extend_from_slice(&[12, 3, 0, 6, 0, 0]);
    for (i, _) in INPUT_NAMES.iter().enumerate() {
        tx.extend_from_slice(&0x6000u16.to_le_bytes());
        tx.extend_from_slice(&[i as u8 + 1, 9 + i as u8, if i == 7 || i == 8 { 7 } else { 4 }, 32, 0, 0]);
    }
    category(&mut w, 50, &tx);
    // RxPDO 0x1600 on SM2: controller mode (u32) and set-point (i32).
    let mut rx = Vec::new();
    rx.extend_from_slice(&0x1600u16.to_le_bytes());
    rx.extend_from_slice(&[2, 2, 0, 5, 0, 0]);
    rx.extend_from_slice(&0x7000u16.to_le_bytes());
    rx.extend_from_slice(&[1, 7, 7, 32, 0, 0]);
    rx.extend_from_slice(&0x7000u16.to_le_bytes());
    rx.extend_from_slice(&[2, 8, 4, 32, 0, 0]);
    category(&mut w, 51, &rx);
    w.push(0xFFFF);
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identity_and_categories() {
        let id = Identity::of(&tmclsim_firmware::Profile::built_in("tmcm-1310").unwrap()).unwrap();
        let w = image(&id, 7);
        let u32_at = |i: usize| u32::from(w[i]) | u32::from(w[i + 1]) << 16;
        assert_eq!((u32_at(8), u32_at(10), u32_at(12), u32_at(14)), (0x286, 1310, 0x0001_000E, 7));
        assert_eq!(w[0x18], MAILBOX_OUT);
        // Walk the categories.
        let mut at = 0x40;
        let mut kinds = vec![];
        while w[at] != 0xFFFF {
            kinds.push(w[at]);
            at += 2 + w[at + 1] as usize;
        }
        assert_eq!(kinds, [10, 30, 40, 41, 50, 51]);
    }
}
