//! One TMCM-1310 behind its EtherCAT slave controller: the AL state
//! machine's checks, process data to and from the module, the TMCL
//! mailbox, the process data watchdog.

use crate::esc::{Esc, code, state};
use crate::identity::Identity;
use crate::mailbox::{self, Sdo};
use crate::sii;
use tmclsim_firmware::Module;
use tmclsim_firmware::module::Special;
use tmclsim_protocol::{Command, Instruction, Status, opcode};

/// Status code 8 over EtherCAT: the parameter is password protected.
pub const PASSWORD_PROTECTED: u8 = 8;

/// Global parameters that EtherCAT may not change (the USB identity of the
/// module: its address, secondary address and host address).
const PROTECTED_GLOBALS: [u8; 3] = [66, 76, 87];

pub struct Slave {
    pub esc: Esc,
    identity: Identity,
    tmcl_reply: [u8; 8],
    /// Valid outputs arrived since SafeOp was entered.
    outputs_valid: bool,
    last_outputs_ns: u64,
    applied: Option<(u32, i32)>,
}

impl Slave {
    pub fn new(identity: Identity, serial: u32) -> Slave {
        let esc = Esc::new(sii::image(&identity, serial));
        Slave { esc, identity, tmcl_reply: [0; 8], outputs_valid: false, last_outputs_ns: 0, applied: None }
    }

    /// Before a frame passes: time moves on, inputs are fresh.
    pub fn before_frame(&mut self, m: &mut Module, now_ns: u64) {
        if self.esc.state() >= state::SAFE_OP && self.esc.state() != state::BOOTSTRAP {
            let inputs = self.inputs(m);
            let at = sii::INPUTS as usize;
            self.esc.mem[at..at + inputs.len()].copy_from_slice(&inputs);
        }
        self.watchdog(m, now_ns);
    }

    /// After the frame: AL control, mailbox, outputs.
    pub fn after_frame(&mut self, m: &mut Module, now_ns: u64) {
        let events = std::mem::take(&mut self.esc.events);
        if events.al_control {
            self.al_control(m);
        }
        if events.mailbox_written {
            self.mailbox(m);
        }
        if events.outputs_written && self.esc.outputs_fresh {
            self.esc.outputs_fresh = false;
            self.last_outputs_ns = now_ns;
            self.esc.set_watchdog_expired(false);
            match self.esc.state() {
                state::SAFE_OP => self.outputs_valid = true,
                state::OP => self.apply_outputs(m),
                _ => {}
            }
        }
    }

    fn al_control(&mut self, m: &mut Module) {
        let control = self.esc.al_control();
        let requested = (control & 0x0F) as u8;
        let ack = control & 0x10 != 0;
        let current = self.esc.state();
        let error = self.esc.mem[crate::esc::reg::AL_STATUS as usize] & 0x10 != 0;
        if error && ack && requested == current {
            self.esc.set_state(current, None);
            return;
        }
        if !matches!(requested, state::INIT | state::PRE_OP | state::BOOTSTRAP | state::SAFE_OP | state::OP) {
            self.esc.set_state(current, Some(code::UNKNOWN_STATE));
            return;
        }
        if requested == current {
            if error && ack {
                self.esc.set_state(current, None);
            }
            return;
        }
        let down = requested < current && current != state::BOOTSTRAP || (current == state::BOOTSTRAP && requested == state::INIT);
        if down {
            if current == state::OP {
                self.safe_outputs(m);
            }
            self.esc.set_state(requested, None);
            return;
        }
        let refusal = match (current, requested) {
            (state::INIT, state::PRE_OP) => self.check_mailboxes(),
            (state::INIT, state::BOOTSTRAP) => None,
            (state::PRE_OP, state::SAFE_OP) => self.check_process_data(),
            (state::SAFE_OP, state::OP) => (!self.outputs_valid).then_some(code::NO_VALID_OUTPUTS),
            _ => Some(code::INVALID_STATE_CHANGE),
        };
        match refusal {
            Some(c) => self.esc.set_state(current, Some(c)),
            None => {
                if requested == state::SAFE_OP {
                    self.outputs_valid = false;
                    self.applied = None;
                }
                self.esc.set_state(requested, None);
            }
        }
    }

    /// SyncManagers 0/1 must be the mailboxes of the SII.
    fn check_mailboxes(&self) -> Option<u16> {
        for n in 0..2 {
            let sm = self.esc.sync_manager(n);
            let (start, len) = sii::SM_LAYOUT[n];
            if !sm.enabled || sm.start != start || sm.len != len || !sm.is_mailbox() || sm.master_writes() != (n == 0) {
                return Some(code::INVALID_MAILBOX_CONFIG);
            }
        }
        None
    }

    /// SyncManagers 2/3 must hold the process data of the SII.
    fn check_process_data(&self) -> Option<u16> {
        let out = self.esc.sync_manager(2);
        if !out.enabled || out.start != sii::OUTPUTS || out.len != sii::OUTPUTS_LEN || out.is_mailbox() || !out.master_writes() {
            return Some(code::INVALID_OUTPUT_CONFIG);
        }
        let inp = self.esc.sync_manager(3);
        if !inp.enabled || inp.start != sii::INPUTS || inp.len != sii::INPUTS_LEN || inp.is_mailbox() || inp.master_writes() {
            return Some(code::INVALID_INPUT_CONFIG);
        }
        None
    }

    fn watchdog(&mut self, m: &mut Module, now_ns: u64) {
        let wd = self.esc.watchdog_ns();
        let enabled = self.esc.sync_manager(2).control & 0x40 != 0;
        if self.esc.state() == state::OP && enabled && wd > 0 && now_ns.saturating_sub(self.last_outputs_ns) > wd {
            self.esc.set_watchdog_expired(true);
            self.safe_outputs(m);
            self.esc.set_state(state::SAFE_OP, Some(code::SM_WATCHDOG));
            self.outputs_valid = false;
        }
    }

    /// Outputs in a safe state: the motor stops.
    fn safe_outputs(&mut self, m: &mut Module) {
        self.run(m, Command::Mst { motor: 0 }.encode());
        self.applied = None;
    }

    /// Controller mode and set-point (little endian) at 0x1000.
    fn apply_outputs(&mut self, m: &mut Module) {
        let at = sii::OUTPUTS as usize;
        let mem = &self.esc.mem;
        let mode = u32::from_le_bytes([mem[at], mem[at + 1], mem[at + 2], mem[at + 3]]);
        let setpoint = i32::from_le_bytes([mem[at + 4], mem[at + 5], mem[at + 6], mem[at + 7]]);
        if self.applied == Some((mode, setpoint)) {
            return;
        }
        self.applied = Some((mode, setpoint));
        let command = match mode {
            1 => Command::Mvp { mode: tmclsim_protocol::MoveMode::Absolute, motor: 0, value: setpoint },
            2 => {
                // A velocity set-point within the speeds ROR takes (AP 2's range).
                let limit = m.profile().axis_parameter(2).map_or(2047, |p| p.max.min(i64::from(i32::MAX)) as i32);
                Command::Ror { motor: 0, velocity: setpoint.clamp(-limit, limit) }
            }
            3 => Command::Sap { param: 14, motor: 0, value: setpoint },
            _ => return,
        };
        self.run(m, command.encode());
    }

    fn run(&mut self, m: &mut Module, ins: Instruction) -> tmclsim_firmware::Outcome {
        m.execute(ins)
    }

    /// The twelve input fields (tmcm-1310.md), little endian. The error
    /// flags are AP 208 with AP 207 above it (peeked: reading AP 207 over
    /// TMCL clears it, process data must not).
    fn inputs(&mut self, m: &mut Module) -> [u8; 48] {
        let extended = m.axis(0).params[207];
        let mut ap = |n: u8| m.get_axis_parameter(n, 0).unwrap_or(0);
        let fields = [ap(0), ap(1), ap(233), ap(209), ap(2), ap(3), ap(131), ap(18), ap(208) | extended << 8, ap(123), ap(14), ap(230)];
        let mut out = [0u8; 48];
        for (i, v) in fields.iter().enumerate() {
            out[4 * i..4 * i + 4].copy_from_slice(&v.to_le_bytes());
        }
        out
    }

    /// A message arrived in the output mailbox.
    fn mailbox(&mut self, m: &mut Module) {
        let Some(msg) = self.esc.take_mailbox() else { return };
        if self.esc.state() == state::INIT {
            return;
        }
        let reply = match mailbox::parse(&msg) {
            Ok(None) => return,
            Err((index, subindex, code)) => mailbox::abort_response(0, index, subindex, code),
            Ok(Some((counter, sdo))) => self.sdo(m, counter, sdo),
        };
        self.esc.post_mailbox(&reply);
    }

    fn sdo(&mut self, m: &mut Module, counter: u8, sdo: Sdo) -> Vec<u8> {
        use mailbox::abort;
        match sdo {
            Sdo::Download { index: mailbox::TMCL_OBJECT, subindex: 0, data } => {
                if data.len() != 8 {
                    return mailbox::abort_response(counter, mailbox::TMCL_OBJECT, 0, abort::LENGTH);
                }
                self.tmcl_reply = self.tmcl(m, &data);
                mailbox::download_response(counter, mailbox::TMCL_OBJECT, 0)
            }
            Sdo::Upload { index: mailbox::TMCL_OBJECT, subindex: 0 } => {
                mailbox::upload_response(counter, mailbox::TMCL_OBJECT, 0, &self.tmcl_reply)
            }
            Sdo::Upload { index, subindex } => match self.object(index, subindex) {
                Ok(data) => mailbox::upload_response(counter, index, subindex, &data),
                Err(code) => mailbox::abort_response(counter, index, subindex, code),
            },
            Sdo::Download { index, subindex, .. } => {
                let code = match self.object(index, subindex) {
                    Ok(_) => abort::READ_ONLY,
                    Err(code) => code,
                };
                mailbox::abort_response(counter, index, subindex, code)
            }
        }
    }

    /// The read-only objects of the object dictionary: device type, name,
    /// identity, and the SyncManager/PDO description a master reads to map
    /// the process data.
    fn object(&self, index: u16, subindex: u8) -> Result<Vec<u8>, u32> {
        use mailbox::abort;
        let u32s = |v: u32| v.to_le_bytes().to_vec();
        let mapping = |index: u16, sub: u8| u32s(u32::from(index) << 16 | u32::from(sub) << 8 | 32);
        let missing = Err(abort::SUBINDEX_MISSING);
        Ok(match (index, subindex) {
            (0x1000, 0) => u32s(0),
            (0x1008, 0) => self.identity.name.as_bytes().to_vec(),
            (0x1018, 0) => vec![4],
            (0x1018, 1) => u32s(self.identity.vendor_id),
            (0x1018, 2) => u32s(self.identity.product_code),
            (0x1018, 3) => u32s(self.identity.revision),
            (0x1018, 4) => u32s(self.serial()),
            (0x1018, _) => return missing,
            // SyncManager communication types: mailbox out/in, outputs, inputs.
            (0x1C00, 0) => vec![4],
            (0x1C00, 1..=4) => vec![subindex],
            (0x1C00, _) => return missing,
            // PDO assignment of SM2 and SM3.
            (0x1C12 | 0x1C13, 0) => vec![1],
            (0x1C12, 1) => 0x1600u16.to_le_bytes().to_vec(),
            (0x1C13, 1) => 0x1A00u16.to_le_bytes().to_vec(),
            (0x1C12 | 0x1C13, _) => return missing,
            // PDO mapping: controller mode and set-point; the twelve inputs.
            (0x1600, 0) => vec![2],
            (0x1600, 1..=2) => mapping(0x7000, subindex),
            (0x1A00, 0) => vec![12],
            (0x1A00, 1..=12) => mapping(0x6000, subindex),
            (0x1600 | 0x1A00, _) => return missing,
            _ => return Err(abort::OBJECT_MISSING),
        })
    }

    fn serial(&self) -> u32 {
        let w = &self.esc.sii;
        u32::from(w[14]) | u32::from(w[15]) << 16
    }

    /// One TMCL request over the mailbox: `[address][opcode][type][motor]
    /// [value]` → `[host][address][status][opcode][value]`.
    fn tmcl(&mut self, m: &mut Module, req: &[u8]) -> [u8; 8] {
        let ins = Instruction::new(req[1], req[2], req[3], i32::from_be_bytes([req[4], req[5], req[6], req[7]]));
        let host = m.host_address();
        let address = m.address();
        let protected = matches!(ins.opcode, opcode::SGP | opcode::STGP | opcode::AGP | opcode::RSGP)
            && ins.motor == 0
            && PROTECTED_GLOBALS.contains(&ins.kind);
        let (status, value, special) = if protected {
            (PASSWORD_PROTECTED, ins.value, None)
        } else if m.program().download.is_some() && !opcode::is_control(ins.opcode) {
            let f = m.handle_frame(&tmclsim_protocol::Request::new(address, ins).encode());
            let r = f.and_then(|f| tmclsim_protocol::Reply::decode(&f));
            (r.map_or(Status::InvalidValue.code(), |r| r.status), ins.value, None)
        } else {
            let o = m.execute(ins);
            let special = match o.special {
                Special::Frame(f) => Some(f),
                _ => None,
            };
            (o.status.code(), o.value, special)
        };
        if let Some(f) = special {
            // 136 type 0 and 134: the special 9-byte reply without checksum.
            let mut out = [0u8; 8];
            if ins.opcode == opcode::FIRMWARE_VERSION {
                out.copy_from_slice(&f[1..9]);
            } else {
                out.copy_from_slice(&f[..8]);
            }
            return out;
        }
        // Over EtherCAT there is no status 101: a stored word answers 100.
        let status = if status == Status::Loaded.code() { Status::Ok.code() } else { status };
        let v = value.to_be_bytes();
        [host, address, status, ins.opcode, v[0], v[1], v[2], v[3]]
    }
}
