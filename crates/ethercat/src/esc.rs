//! The EtherCAT slave controller: register and process memory, station
//! address, DL status, SII EEPROM interface, SyncManagers (mailbox
//! handshake and buffered mode), FMMUs, the AL state machine, and the
//! datagram commands with their working counters.

use crate::frame::Datagram;

/// Memory: registers 0x0000–0x0FFF and process RAM 0x1000–0x2FFF.
pub const MEMORY: usize = 0x3000;

pub mod reg {
    pub const TYPE: u16 = 0x0000;
    pub const FMMUS: u16 = 0x0004;
    pub const SYNC_MANAGERS: u16 = 0x0005;
    pub const RAM_SIZE: u16 = 0x0006;
    pub const PORTS: u16 = 0x0007;
    pub const STATION_ADDRESS: u16 = 0x0010;
    pub const DL_STATUS: u16 = 0x0110;
    pub const AL_CONTROL: u16 = 0x0120;
    pub const AL_STATUS: u16 = 0x0130;
    pub const AL_STATUS_CODE: u16 = 0x0134;
    pub const WD_DIVIDER: u16 = 0x0400;
    pub const WD_PROCESS_DATA: u16 = 0x0420;
    pub const WD_STATUS: u16 = 0x0440;
    pub const EEPROM_CONTROL: u16 = 0x0502;
    pub const EEPROM_ADDRESS: u16 = 0x0504;
    pub const EEPROM_DATA: u16 = 0x0508;
    pub const FMMU: u16 = 0x0600;
    pub const SYNC_MANAGER: u16 = 0x0800;
}

/// AL states.
pub mod state {
    pub const INIT: u8 = 1;
    pub const PRE_OP: u8 = 2;
    pub const BOOTSTRAP: u8 = 3;
    pub const SAFE_OP: u8 = 4;
    pub const OP: u8 = 8;
}

/// AL status codes used for refusals.
pub mod code {
    pub const INVALID_STATE_CHANGE: u16 = 0x0011;
    pub const UNKNOWN_STATE: u16 = 0x0012;
    pub const INVALID_MAILBOX_CONFIG: u16 = 0x0016;
    pub const INVALID_OUTPUT_CONFIG: u16 = 0x001D;
    pub const INVALID_INPUT_CONFIG: u16 = 0x001E;
    pub const SM_WATCHDOG: u16 = 0x001B;
    pub const NO_VALID_OUTPUTS: u16 = 0x001A;
}

/// What a frame did that the slave's application must react to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Events {
    /// The master completed a write of the output mailbox (SM0).
    pub mailbox_written: bool,
    /// The master read the input mailbox (SM1) to its end.
    pub mailbox_read: bool,
    /// The master completed a write of the outputs (SM2).
    pub outputs_written: bool,
    /// The master wrote the AL control register.
    pub al_control: bool,
}

/// One SyncManager's configuration (registers 0x0800 + 8n).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SyncManager {
    pub start: u16,
    pub len: u16,
    pub control: u8,
    pub enabled: bool,
}

impl SyncManager {
    pub fn is_mailbox(&self) -> bool {
        self.control & 0x03 == 0x02
    }

    /// The master writes this buffer (else it reads it).
    pub fn master_writes(&self) -> bool {
        self.control & 0x0C == 0x04
    }

    fn covers(&self, addr: usize) -> bool {
        self.enabled && self.len > 0 && addr >= self.start as usize && addr < self.start as usize + self.len as usize
    }
}

pub struct Esc {
    pub mem: Vec<u8>,
    pub sii: Vec<u16>,
    /// A mailbox buffer holds a message not yet taken (SM0: by the slave,
    /// SM1: by the master).
    pub mailbox_full: [bool; 2],
    /// Outputs were written since the last look (SM2).
    pub outputs_fresh: bool,
    pub events: Events,
    /// Has a next slave behind port 1 (for the DL status).
    pub next_port_open: bool,
}

fn rd16(mem: &[u8], a: u16) -> u16 {
    u16::from_le_bytes([mem[a as usize], mem[a as usize + 1]])
}

fn wr16(mem: &mut [u8], a: u16, v: u16) {
    mem[a as usize..a as usize + 2].copy_from_slice(&v.to_le_bytes());
}

/// Registers the master may write (all of process RAM too).
fn writable(addr: usize) -> bool {
    matches!(addr,
        0x0010..=0x0013 | 0x0100..=0x0103 | 0x0108..=0x0109 | 0x0120..=0x0121 | 0x0200..=0x0203 | 0x0300..=0x0313
        | 0x0400..=0x0401 | 0x0410..=0x0411 | 0x0420..=0x0421 | 0x0500 | 0x0502..=0x050F | 0x0600..=0x06FF | 0x0900..=0x09FF)
        || (0x0800..0x0880).contains(&addr) && addr % 8 != 5 // SM status bytes are read-only
        || (0x1000..MEMORY).contains(&addr)
}

impl Esc {
    pub fn new(sii: Vec<u16>) -> Esc {
        let mut mem = vec![0u8; MEMORY];
        mem[reg::TYPE as usize] = 0x11;
        mem[reg::FMMUS as usize] = 8;
        mem[reg::SYNC_MANAGERS as usize] = 8;
        mem[reg::RAM_SIZE as usize] = ((MEMORY - 0x1000) / 1024) as u8;
        mem[reg::PORTS as usize] = 0x0F;
        wr16(&mut mem, reg::WD_DIVIDER, 2498);
        wr16(&mut mem, reg::WD_PROCESS_DATA, 1000);
        // EEPROM interface: 8-byte reads.
        wr16(&mut mem, reg::EEPROM_CONTROL, 0x0040);
        let mut esc = Esc { mem, sii, mailbox_full: [false; 2], outputs_fresh: false, events: Events::default(), next_port_open: false };
        esc.set_state(state::INIT, None);
        esc
    }

    pub fn station_address(&self) -> u16 {
        rd16(&self.mem, reg::STATION_ADDRESS)
    }

    pub fn state(&self) -> u8 {
        self.mem[reg::AL_STATUS as usize] & 0x0F
    }

    /// Sets the AL status; `Some(code)` sets the error indication.
    pub fn set_state(&mut self, s: u8, error: Option<u16>) {
        self.mem[reg::AL_STATUS as usize] = s | if error.is_some() { 0x10 } else { 0 };
        wr16(&mut self.mem, reg::AL_STATUS_CODE, error.unwrap_or(0));
    }

    pub fn al_control(&self) -> u16 {
        rd16(&self.mem, reg::AL_CONTROL)
    }

    pub fn sync_manager(&self, n: usize) -> SyncManager {
        let a = reg::SYNC_MANAGER + 8 * n as u16;
        SyncManager {
            start: rd16(&self.mem, a),
            len: rd16(&self.mem, a + 2),
            control: self.mem[a as usize + 4],
            enabled: self.mem[a as usize + 6] & 1 == 1,
        }
    }

    /// Process data watchdog time in nanoseconds (0: off).
    pub fn watchdog_ns(&self) -> u64 {
        let divider = u64::from(rd16(&self.mem, reg::WD_DIVIDER));
        u64::from(rd16(&self.mem, reg::WD_PROCESS_DATA)) * (divider + 2) * 40
    }

    pub fn set_watchdog_expired(&mut self, expired: bool) {
        self.mem[reg::WD_STATUS as usize] = u8::from(!expired);
    }

    /// The slave puts a reply into the input mailbox (SM1).
    pub fn post_mailbox(&mut self, message: &[u8]) -> bool {
        let sm = self.sync_manager(1);
        if self.mailbox_full[1] || !sm.enabled || message.len() > sm.len as usize {
            return false;
        }
        let start = sm.start as usize;
        self.mem[start..start + sm.len as usize].fill(0);
        self.mem[start..start + message.len()].copy_from_slice(message);
        self.mailbox_full[1] = true;
        self.update_sm_status();
        true
    }

    /// The slave takes the message of the output mailbox (SM0).
    pub fn take_mailbox(&mut self) -> Option<Vec<u8>> {
        if !self.mailbox_full[0] {
            return None;
        }
        let sm = self.sync_manager(0);
        self.mailbox_full[0] = false;
        self.update_sm_status();
        Some(self.mem[sm.start as usize..sm.start as usize + sm.len as usize].to_vec())
    }

    fn update_sm_status(&mut self) {
        for n in 0..2 {
            let a = (reg::SYNC_MANAGER + 8 * n as u16 + 5) as usize;
            self.mem[a] = if self.mailbox_full[n] { 0x08 } else { 0 };
        }
    }

    fn dl_status(&self) -> u16 {
        // PDI operational, link and communication on port 0; port 1 open
        // with communication when a slave follows, else closed.
        let port1 = if self.next_port_open { 0x0820 } else { 0x0400 };
        0x0001 | 0x0010 | 0x0200 | port1 | 0x1000 | 0x4000
    }

    /// May the master read (`write == false`) or write this byte? (Bytes
    /// of read-only registers are allowed and left unchanged.)
    fn access(&self, addr: usize, write: bool) -> bool {
        for n in 0..4 {
            let sm = self.sync_manager(n);
            if sm.covers(addr) {
                if sm.master_writes() != write {
                    return false;
                }
                if sm.is_mailbox() {
                    let full = self.mailbox_full[if write { 0 } else { 1 }];
                    return if write { !full } else { full };
                }
            }
        }
        true
    }

    /// Reads `len` bytes at `addr` (0 = denied).
    fn read(&mut self, addr: usize, out: &mut [u8], or: bool) -> bool {
        if addr + out.len() > MEMORY || out.is_empty() {
            return false;
        }
        if !(addr..addr + out.len()).all(|a| self.access(a, false)) {
            return false;
        }
        let dl = self.dl_status().to_le_bytes();
        self.mem[reg::DL_STATUS as usize..reg::DL_STATUS as usize + 2].copy_from_slice(&dl);
        for (i, o) in out.iter_mut().enumerate() {
            let v = self.mem[addr + i];
            *o = if or { *o | v } else { v };
        }
        // Reading the last byte of the input mailbox empties it.
        let sm = self.sync_manager(1);
        if sm.enabled
            && self.mailbox_full[1]
            && addr + out.len() >= sm.start as usize + sm.len as usize
            && addr < sm.start as usize + sm.len as usize
        {
            self.mailbox_full[1] = false;
            self.events.mailbox_read = true;
            self.update_sm_status();
        }
        true
    }

    fn write(&mut self, addr: usize, data: &[u8]) -> bool {
        if addr + data.len() > MEMORY || data.is_empty() {
            return false;
        }
        if !(addr..addr + data.len()).all(|a| self.access(a, true)) {
            return false;
        }
        for (i, b) in data.iter().enumerate() {
            if writable(addr + i) {
                self.mem[addr + i] = *b;
            }
        }
        let end = addr + data.len();
        let touches = |a: u16, n: usize| addr < a as usize + n && end > a as usize;
        for n in [0usize, 2] {
            let sm = self.sync_manager(n);
            if sm.enabled && sm.len > 0 && end >= sm.start as usize + sm.len as usize && addr < sm.start as usize + sm.len as usize {
                if n == 0 {
                    self.mailbox_full[0] = true;
                    self.events.mailbox_written = true;
                    self.update_sm_status();
                } else {
                    self.outputs_fresh = true;
                    self.events.outputs_written = true;
                }
            }
        }
        if touches(reg::AL_CONTROL, 2) {
            self.events.al_control = true;
        }
        if touches(reg::EEPROM_CONTROL, 2) {
            self.eeprom_command();
        }
        if touches(reg::SYNC_MANAGER, 0x80) {
            // A reconfigured mailbox starts empty.
            for n in 0..2 {
                if !self.sync_manager(n).enabled {
                    self.mailbox_full[n] = false;
                }
            }
            self.update_sm_status();
        }
        true
    }

    /// Executes an SII command written to 0x0502 (reads only; 8 bytes).
    fn eeprom_command(&mut self) {
        let control = rd16(&self.mem, reg::EEPROM_CONTROL);
        let command = (control >> 8) & 0x07;
        let mut status = 0x0040; // 8-byte reads, not busy, no error
        match command {
            0 => {}
            1 => {
                let word = u32::from_le_bytes(self.mem[reg::EEPROM_ADDRESS as usize..reg::EEPROM_ADDRESS as usize + 4].try_into().unwrap())
                    as usize;
                for i in 0..4 {
                    let v = self.sii.get(word + i).copied().unwrap_or(0xFFFF);
                    wr16(&mut self.mem, reg::EEPROM_DATA + 2 * i as u16, v);
                }
            }
            4 => {}
            _ => status |= 0x2000, // write and others: command error
        }
        wr16(&mut self.mem, reg::EEPROM_CONTROL, status);
    }

    /// Logical access through the FMMUs; returns (read happened, write happened).
    fn logical(&mut self, address: u32, data: &mut [u8], read: bool, write: bool) -> (bool, bool) {
        let (mut did_read, mut did_write) = (false, false);
        for n in 0..8 {
            let a = (reg::FMMU + 16 * n) as usize;
            let f = &self.mem[a..a + 16];
            if f[12] & 1 == 0 {
                continue;
            }
            let log_start = u32::from_le_bytes([f[0], f[1], f[2], f[3]]);
            let len = u32::from(u16::from_le_bytes([f[4], f[5]]));
            let phys = u32::from(u16::from_le_bytes([f[8], f[9]]));
            let kind = f[11];
            let lo = address.max(log_start);
            let hi = (address + data.len() as u32).min(log_start + len);
            if lo >= hi {
                continue;
            }
            let (d0, p0, n_bytes) = ((lo - address) as usize, (phys + lo - log_start) as usize, (hi - lo) as usize);
            if read && kind & 1 == 1 && self.read(p0, &mut data[d0..d0 + n_bytes], false) {
                did_read = true;
            }
            if write && kind & 2 == 2 {
                let chunk = data[d0..d0 + n_bytes].to_vec();
                if self.write(p0, &chunk) {
                    did_write = true;
                }
            }
        }
        (did_read, did_write)
    }

    /// Processes one datagram of a frame in place; `position` is this
    /// slave's place in the line (for auto-increment addressing, the
    /// frame's address field is incremented as it passes).
    pub fn datagram(&mut self, frame: &mut [u8], d: Datagram) {
        let a = d.address_offset();
        let adp = u16::from_le_bytes([frame[a], frame[a + 1]]);
        let ado = u16::from_le_bytes([frame[a + 2], frame[a + 3]]) as usize;
        let logical = u32::from_le_bytes([frame[a], frame[a + 1], frame[a + 2], frame[a + 3]]);
        let range = d.data();
        let mut wkc = 0u16;
        let me_auto = adp == 0;
        let me_fixed = adp == self.station_address();
        match d.command {
            0 => {}
            // APRD, APWR, APRW, FPRD, FPWR, FPRW
            1..=6 => {
                let addressed = if d.command <= 3 { me_auto } else { me_fixed };
                if addressed {
                    let (r, w) = match d.command {
                        1 | 4 => (true, false),
                        2 | 5 => (false, true),
                        _ => (true, true),
                    };
                    let written = frame[range.clone()].to_vec();
                    if r && self.read(ado, &mut frame[range.clone()], false) {
                        wkc += 1;
                    }
                    if w && self.write(ado, &written) {
                        wkc += if r { 2 } else { 1 };
                    }
                }
            }
            // BRD, BWR, BRW
            7..=9 => {
                let written = frame[range.clone()].to_vec();
                if d.command != 8 && self.read(ado, &mut frame[range.clone()], true) {
                    wkc += 1;
                }
                if d.command != 7 && self.write(ado, &written) {
                    wkc += if d.command == 9 { 2 } else { 1 };
                }
            }
            // LRD, LWR, LRW
            10..=12 => {
                let mut data = frame[range.clone()].to_vec();
                let (r, w) = self.logical(logical, &mut data, d.command != 11, d.command != 10);
                frame[range.clone()].copy_from_slice(&data);
                wkc += u16::from(r) + if w { 2 - u16::from(d.command == 11) } else { 0 };
            }
            // ARMW, FRMW: the addressed slave reads, the others write.
            13 | 14 => {
                let addressed = if d.command == 13 { me_auto } else { me_fixed };
                if addressed {
                    if self.read(ado, &mut frame[range.clone()], false) {
                        wkc += 1;
                    }
                } else {
                    let written = frame[range.clone()].to_vec();
                    if self.write(ado, &written) {
                        wkc += 1;
                    }
                }
            }
            _ => {}
        }
        if d.command <= 3 || d.command == 13 {
            frame[a..a + 2].copy_from_slice(&adp.wrapping_add(1).to_le_bytes());
        }
        let w = d.wkc_offset();
        let old = u16::from_le_bytes([frame[w], frame[w + 1]]);
        frame[w..w + 2].copy_from_slice(&old.wrapping_add(wkc).to_le_bytes());
    }
}
