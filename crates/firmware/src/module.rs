//! A virtual TMCL module: profile, state, EEPROM, motion and world, driven
//! by `handle_frame` (or `execute`) and `advance`.

use crate::driver::Driver;
use crate::eeprom::Eeprom;
use crate::motion::{self, Motion, RampMode};
use crate::profile::Profile;
use crate::program::{Program, RunMode};
use crate::reference_search::ReferenceSearch;
use crate::world::World;
use std::sync::Arc;
use tmclsim_protocol::frame::version_string_reply;
use tmclsim_protocol::{FRAME_LEN, Reply, Request, Status, opcode};

/// Axis parameter numbers the firmware gives a meaning to.
pub mod ap {
    pub const TARGET_POSITION: u8 = 0;
    pub const ACTUAL_POSITION: u8 = 1;
    pub const TARGET_SPEED: u8 = 2;
    pub const ACTUAL_SPEED: u8 = 3;
    pub const MAX_SPEED: u8 = 4;
    pub const MAX_ACCELERATION: u8 = 5;
    pub const MAX_CURRENT: u8 = 6;
    pub const STANDBY_CURRENT: u8 = 7;
    pub const POSITION_REACHED: u8 = 8;
    pub const HOME_SWITCH: u8 = 9;
    pub const RIGHT_SWITCH: u8 = 10;
    pub const LEFT_SWITCH: u8 = 11;
    pub const RIGHT_SWITCH_DISABLE: u8 = 12;
    pub const LEFT_SWITCH_DISABLE: u8 = 13;
    pub const MIN_SPEED: u8 = 130;
    pub const ACTUAL_ACCELERATION: u8 = 135;
    pub const RAMP_MODE: u8 = 138;
    pub const SOFT_STOP: u8 = 149;
    pub const END_SWITCH_POWER_DOWN: u8 = 150;
    pub const MICROSTEP_RESOLUTION: u8 = 140;
    pub const CHOPPER_OFF_TIME: u8 = 167;
    pub const SMART_ENERGY_CURRENT_MINIMUM: u8 = 168;
    pub const SMART_ENERGY_CURRENT_DOWN_STEP: u8 = 169;
    pub const SMART_ENERGY_HYSTERESIS: u8 = 170;
    pub const SMART_ENERGY_CURRENT_UP_STEP: u8 = 171;
    pub const SMART_ENERGY_HYSTERESIS_START: u8 = 172;
    pub const STALLGUARD_FILTER: u8 = 173;
    pub const STALLGUARD_THRESHOLD: u8 = 174;
    pub const STOP_ON_STALL: u8 = 181;
    pub const SMART_ENERGY_THRESHOLD_SPEED: u8 = 182;
    pub const SMART_ENERGY_SLOW_RUN_CURRENT: u8 = 183;
    pub const LOAD_VALUE: u8 = 206;
    pub const STALL_THRESHOLD: u8 = 205;
    pub const ENCODER_POSITION: u8 = 209;
    pub const ENCODER_PRESCALER: u8 = 210;
    pub const MAX_ENCODER_DEVIATION: u8 = 212;
    pub const GROUP_INDEX: u8 = 213;
    pub const DRIVER_ERROR_FLAGS: u8 = 208;
    pub const RAMP_DIVISOR: u8 = 153;
    pub const REFERENCE_SEARCH_MODE: u8 = 193;
    pub const REFERENCE_SEARCH_SPEED: u8 = 194;
    pub const REFERENCE_SWITCH_SPEED: u8 = 195;
    pub const END_SWITCH_DISTANCE: u8 = 196;
    pub const LAST_REFERENCE_POSITION: u8 = 197;
    pub const PULSE_DIVISOR: u8 = 154;
    pub const ACTUAL_CURRENT: u8 = 180;
    pub const BOOST_CURRENT: u8 = 200;
    pub const FREEWHEELING: u8 = 204;
    pub const EXTENDED_ERROR_FLAGS: u8 = 207;
    pub const POWER_DOWN_DELAY: u8 = 214;
}

/// Global parameter numbers (bank 0) the firmware gives a meaning to.
pub mod gp {
    pub const EEPROM_MAGIC: u8 = 64;
    pub const BAUD_RATE: u8 = 65;
    pub const SERIAL_ADDRESS: u8 = 66;
    pub const ASCII_MODE: u8 = 67;
    pub const HEARTBEAT: u8 = 68;
    pub const AUTOSTART: u8 = 77;
    pub const EEPROM_LOCK: u8 = 73;
    pub const SHUTDOWN_PIN: u8 = 80;
    pub const CODE_PROTECTION: u8 = 81;
    pub const TELEGRAM_PAUSE: u8 = 75;
    pub const HOST_ADDRESS: u8 = 76;
    pub const END_SWITCH_POLARITY: u8 = 79;
    pub const COORDINATE_STORAGE: u8 = 84;
    pub const DONT_RESTORE_USER_VARIABLES: u8 = 85;
    pub const SECONDARY_ADDRESS: u8 = 87;
    pub const REVERSE_SHAFT: u8 = 90;
    pub const APPLICATION_STATUS: u8 = 128;
    pub const DOWNLOAD_MODE: u8 = 129;
    pub const PROGRAM_COUNTER: u8 = 130;
    pub const TICK_TIMER: u8 = 132;
    pub const RANDOM: u8 = 133;
    pub const SUPPRESS_REPLY: u8 = 255;
}

/// One motor axis.
#[derive(Clone, Debug)]
pub struct Axis {
    /// RAM values of the axis parameters (stored ones; measured ones are
    /// computed on read).
    pub params: [i32; 256],
    pub motion: Motion,
    /// AP 0 as the host wrote it.
    pub target_word: i32,
    /// Coordinates 0…N.
    pub coordinates: Vec<i32>,
    /// Mechanical position minus motor position counter.
    pub mech_offset: f64,
    /// Virtual time (ns) since which the motor stands still.
    pub standstill_since: Option<u64>,
    /// A 138 event is due when this axis reaches its target.
    pub notify_on_arrival: bool,
    /// The reference search in progress.
    pub rfs: Option<ReferenceSearch>,
    pub driver: Driver,
    /// An interpolated move's ramp (MVP COORD with bit 6), until it ends.
    pub ramp_override: Option<motion::Ramp>,
    /// AP 209 minus what the encoder measures (set by SAP 209).
    pub encoder_offset: i64,
    pub closed_loop: crate::closed_loop::ClosedLoop,
}

/// Result of the last comparison (or of an accumulator load against 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compare {
    Less,
    #[default]
    Equal,
    Greater,
}

impl Compare {
    pub fn of(a: i32, b: i32) -> Compare {
        match a.cmp(&b) {
            std::cmp::Ordering::Less => Compare::Less,
            std::cmp::Ordering::Equal => Compare::Equal,
            std::cmp::Ordering::Greater => Compare::Greater,
        }
    }
}

/// Error flags (CLE / JC ETO…EPO), one bit each.
pub mod error_flag {
    pub const TIMEOUT: u8 = 1 << 1;
    pub const ALARM: u8 = 1 << 2;
    pub const DEVIATION: u8 = 1 << 3;
    pub const POSITION: u8 = 1 << 4;
    pub const SHUTDOWN: u8 = 1 << 5;
}

/// Accumulator, X register and flags of the TMCL interpreter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Registers {
    pub accumulator: i32,
    pub x: i32,
    pub compare: Compare,
    /// Error flags, see [`error_flag`].
    pub errors: u8,
}

/// How `execute` was reached: the host (direct mode) or a program.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    Direct,
    Program,
}

/// What a command produced besides status and value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Special {
    /// A normal reply.
    None,
    /// Send these 9 bytes instead of a normal reply.
    Frame([u8; FRAME_LEN]),
    /// Send no reply at all.
    Silent,
}

/// The result of executing one instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Outcome {
    pub status: Status,
    pub value: i32,
    pub special: Special,
}

impl Outcome {
    pub fn ok(value: i32) -> Outcome {
        Outcome { status: Status::Ok, value, special: Special::None }
    }

    pub fn error(status: Status, value: i32) -> Outcome {
        Outcome { status, value, special: Special::None }
    }
}

/// A virtual TMCL module.
#[derive(Clone, Debug)]
pub struct Module {
    pub(crate) profile: Arc<Profile>,
    /// Virtual time in nanoseconds since the module was created.
    pub(crate) now_ns: u64,
    pub(crate) axes: Vec<Axis>,
    /// Global parameter RAM, banks 0…3.
    pub(crate) globals: [[i32; 256]; 4],
    pub(crate) outputs: u32,
    pub(crate) pullups: bool,
    pub(crate) world: World,
    pub(crate) eeprom: Eeprom,
    /// Bumped on every EEPROM write; a server saves the image when it changes.
    pub(crate) eeprom_generation: u64,
    pub(crate) registers: Registers,
    /// Interrupt configuration: enabled flags, vectors, global enable.
    pub(crate) interrupts_enabled: [bool; 256],
    pub(crate) interrupt_vectors: [Option<u16>; 256],
    pub(crate) interrupts_global: bool,
    /// 138: arm for the next MVP (`Some(false)`) or every MVP (`Some(true)`).
    pub(crate) event_arm: Option<(bool, u32)>,
    pub(crate) events: Vec<[u8; FRAME_LEN]>,
    /// Address byte of the last request (events answer with it).
    pub(crate) last_address: u8,
    pub(crate) last_frame_ns: u64,
    pub(crate) heartbeat_tripped: bool,
    pub(crate) tick_base_ns: u64,
    pub(crate) tick_offset_ms: i64,
    pub(crate) rng: u32,
    pub(crate) restored_from_eeprom: bool,
    pub(crate) resets: u32,
    pub(crate) program: Program,
    /// Digital inputs and stop switches at the last look, for input-change
    /// and switch interrupts.
    pub(crate) last_inputs: u32,
    pub(crate) last_switches: Vec<(bool, bool)>,
    /// SAC: the shift register of the SPI device on each chip select.
    pub(crate) spi: [u32; 3],
    /// ASCII mode and the line being typed.
    pub(crate) ascii: bool,
    pub(crate) ascii_line: crate::ascii::AsciiLine,
}

impl Module {
    /// A module fresh from the factory (empty EEPROM), in a world without
    /// switches.
    pub fn new(profile: Arc<Profile>) -> Module {
        let eeprom = Eeprom::new(&profile.module.name);
        Module::with_eeprom(profile, eeprom)
    }

    /// A module powered up with the given EEPROM contents.
    pub fn with_eeprom(profile: Arc<Profile>, eeprom: Eeprom) -> Module {
        let world = World::free(profile.module.axes as usize);
        Module::with_world(profile, eeprom, world)
    }

    /// A module powered up with the given EEPROM, in the given world (its
    /// carriages start where the world says).
    pub fn with_world(profile: Arc<Profile>, eeprom: Eeprom, mut world: World) -> Module {
        let template = World::free(1).axes[0].clone();
        world.axes.resize(profile.module.axes as usize, template);
        let mut m = Module {
            world,
            axes: Vec::new(),
            globals: [[0; 256]; 4],
            outputs: 0,
            pullups: true,
            eeprom_generation: 0,
            registers: Registers::default(),
            interrupts_enabled: [false; 256],
            interrupt_vectors: [None; 256],
            interrupts_global: false,
            event_arm: None,
            events: Vec::new(),
            last_address: 1,
            last_frame_ns: 0,
            heartbeat_tripped: false,
            tick_base_ns: 0,
            tick_offset_ms: 0,
            rng: 0x2545_F491,
            restored_from_eeprom: false,
            resets: 0,
            program: Program::new(profile.module.program_memory as usize),
            last_inputs: 0,
            last_switches: Vec::new(),
            spi: [0; 3],
            ascii: false,
            ascii_line: Default::default(),
            now_ns: 0,
            eeprom,
            profile,
        };
        m.power_on();
        m
    }

    /// A module by built-in profile name.
    pub fn built_in(name: &str) -> Result<Module, String> {
        Ok(Module::new(Profile::built_in(name)?))
    }

    pub fn profile(&self) -> &Arc<Profile> {
        &self.profile
    }

    pub fn world(&self) -> &World {
        &self.world
    }

    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }

    pub fn eeprom(&self) -> &Eeprom {
        &self.eeprom
    }

    /// Changes whenever a command wrote the EEPROM.
    pub fn eeprom_generation(&self) -> u64 {
        self.eeprom_generation
    }

    /// True when this power-up found stored values in the EEPROM; false
    /// when the module started from factory defaults.
    pub fn restored_from_eeprom(&self) -> bool {
        self.restored_from_eeprom
    }

    /// How many times the module was reset (255) or reinitialised (137).
    pub fn resets(&self) -> u32 {
        self.resets
    }

    pub fn registers(&self) -> Registers {
        self.registers
    }

    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    pub fn axis(&self, motor: usize) -> &Axis {
        &self.axes[motor]
    }

    /// The module address (GP 66).
    pub fn address(&self) -> u8 {
        self.globals[0][gp::SERIAL_ADDRESS as usize] as u8
    }

    /// GP 87; 0 = off.
    pub fn secondary_address(&self) -> u8 {
        self.globals[0][gp::SECONDARY_ADDRESS as usize] as u8
    }

    pub fn host_address(&self) -> u8 {
        self.globals[0][gp::HOST_ADDRESS as usize] as u8
    }

    /// GP 65: the baud rate code.
    pub fn baud_rate_code(&self) -> i32 {
        self.globals[0][gp::BAUD_RATE as usize]
    }

    /// GP 75: delay before every reply.
    pub fn reply_delay_ns(&self) -> u64 {
        self.globals[0][gp::TELEGRAM_PAUSE as usize].max(0) as u64 * 1_000_000
    }

    /// Sets the module address (GP 66) the way SGP 66 would, without a
    /// frame (used by servers for `--address`).
    pub fn set_address(&mut self, address: u8) {
        self.globals[0][gp::SERIAL_ADDRESS as usize] = address as i32;
        self.eeprom.set_global(0, gp::SERIAL_ADDRESS, address as i32);
        self.eeprom_generation += 1;
    }

    /// Does a frame with this address byte reach this module?
    pub fn answers_to(&self, address: u8) -> bool {
        address == self.address() || (self.secondary_address() != 0 && address == self.secondary_address())
    }

    /// Power cycle: RAM from factory defaults, then what the EEPROM holds.
    pub fn power_on(&mut self) {
        let profile = self.profile.clone();
        if profile.global_parameter(0, gp::EEPROM_MAGIC).is_some() {
            // Any magic but 0xE4 re-initialises the EEPROM (TMCM-351 GP 64).
            if self.eeprom.global(0, gp::EEPROM_MAGIC).is_some_and(|v| v != 0xE4) {
                self.eeprom.clear();
                self.eeprom.set_global(0, gp::EEPROM_MAGIC, 0xE4);
                self.eeprom_generation += 1;
            }
        }
        let ee = &self.eeprom;
        let restored = !ee.axis.is_empty() || !ee.global.is_empty() || !ee.coordinates.is_empty();
        self.globals = [[0; 256]; 4];
        for bank in 0..4u8 {
            for p in profile.global_parameters(bank) {
                let stored = if p.access.auto || p.access.eeprom { ee.global(bank, p.number) } else { None };
                self.globals[bank as usize][p.number as usize] = stored.unwrap_or(p.default_word());
            }
        }
        // Bank 2 is restored unless GP 85 says otherwise.
        if self.globals[0][gp::DONT_RESTORE_USER_VARIABLES as usize] == 1 {
            for p in profile.global_parameters(2) {
                self.globals[2][p.number as usize] = p.default_word();
            }
        }
        self.globals[0][gp::SUPPRESS_REPLY as usize] = 0;
        let coords_from_eeprom = self.globals[0][gp::COORDINATE_STORAGE as usize] == 1;
        let old_axes = std::mem::take(&mut self.axes);
        for motor in 0..profile.module.axes {
            let mut params = [0i32; 256];
            for p in profile.axis_parameters() {
                let stored = if p.access.eeprom { ee.axis(motor, p.number) } else { None };
                params[p.number as usize] = stored.unwrap_or(p.default_word());
            }
            let mut coordinates = vec![0; profile.module.coordinates as usize + 1];
            if coords_from_eeprom {
                for (n, c) in coordinates.iter_mut().enumerate().skip(1) {
                    *c = ee.coordinate(motor, n as u8).unwrap_or(0);
                }
            }
            // The carriage stays where it is; the position counter restarts at 0.
            let sign = self.shaft_sign();
            let mech = old_axes.get(motor as usize).map_or(self.world.axes[motor as usize].start, |a| a.motion.x * sign + a.mech_offset);
            let mode = RampMode::from_code(params[ap::RAMP_MODE as usize]);
            self.axes.push(Axis {
                params,
                motion: Motion { mode, ..Motion::default() },
                target_word: 0,
                coordinates,
                mech_offset: mech,
                standstill_since: Some(self.now_ns),
                notify_on_arrival: false,
                rfs: None,
                driver: Driver::default(),
                ramp_override: None,
                encoder_offset: 0,
                closed_loop: Default::default(),
            });
        }
        self.restored_from_eeprom = restored;
        self.outputs = 0;
        self.pullups = profile.ports.iter().find(|p| p.direction == crate::profile::PortDirection::Pullup).is_none_or(|p| p.default != 0);
        self.registers = Registers::default();
        self.interrupts_enabled = [false; 256];
        self.interrupt_vectors = [None; 256];
        self.interrupts_global = false;
        self.event_arm = None;
        self.events.clear();
        self.last_frame_ns = self.now_ns;
        self.heartbeat_tripped = false;
        self.tick_base_ns = self.now_ns;
        self.tick_offset_ms = 0;
        // Program memory from the EEPROM; the interpreter starts afresh.
        let words = self.program.memory.len();
        let (trace, breakpoints, instruction_ns) =
            (self.program.trace.take(), std::mem::take(&mut self.program.breakpoints), self.program.instruction_ns);
        self.program = Program::new(words);
        self.program.trace = trace.map(|_| Vec::new());
        self.program.breakpoints = breakpoints;
        self.program.instruction_ns = instruction_ns;
        for (&a, bytes) in &self.eeprom.program {
            if let Some(w) = self.program.memory.get_mut(a as usize) {
                *w = tmclsim_protocol::Instruction::from_bytes(bytes);
            }
        }
        self.program.download_pointer = self.program.length() as u16;
        self.program.next_ns = self.now_ns;
        self.last_inputs = self.world.digital_inputs;
        self.last_switches = (0..self.axes.len())
            .map(|m| {
                let (l, r, _) = self.switches(m);
                (l, r)
            })
            .collect();
        for m in 0..self.axes.len() {
            self.closed_loop_power_on(m);
        }
        self.ascii = self.globals[0][gp::ASCII_MODE as usize] & 1 == 1;
        self.ascii_line = Default::default();
        if self.globals[0][gp::AUTOSTART as usize] == 1 && self.program.length() > 0 {
            self.program.mode = RunMode::Run;
        }
    }

    /// Handles one 9-byte frame from a serial-type link: address filter,
    /// checksum, execution, reply (decisions.md rules 2–4, 11).
    pub fn handle_frame(&mut self, frame: &[u8; FRAME_LEN]) -> Option<[u8; FRAME_LEN]> {
        let (request, checksum_ok) = match Request::decode(frame) {
            Ok(r) => (r, true),
            Err(r) => (r, false),
        };
        if !self.answers_to(request.address) {
            return None;
        }
        self.last_address = request.address;
        self.last_frame_ns = self.now_ns;
        self.heartbeat_tripped = false;
        let host = self.host_address();
        if !checksum_ok {
            if self.replies_suppressed(0) {
                return None;
            }
            return Some(Reply::new(host, request.address, Status::WrongChecksum, 0, 0).encode());
        }
        let ins = request.instruction;
        let outcome =
            if self.program.download.is_some() && !opcode::is_control(ins.opcode) { self.download_word(ins) } else { self.execute(ins) };
        let reply = match outcome.special {
            Special::Silent => return None,
            Special::Frame(f) => f,
            Special::None => Reply::new(host, request.address, outcome.status, ins.opcode, outcome.value).encode(),
        };
        if ins.opcode == opcode::RESET && outcome.status == Status::Ok {
            // The reply goes out, then the module restarts.
            self.reset();
            return Some(reply);
        }
        if self.replies_suppressed(ins.opcode) {
            return None;
        }
        Some(reply)
    }

    /// GP 255: replies in direct mode are suppressed except for GAP, GGP
    /// and GIO.
    fn replies_suppressed(&self, op: u8) -> bool {
        self.globals[0][gp::SUPPRESS_REPLY as usize] == 1 && !matches!(op, opcode::GAP | opcode::GGP | opcode::GIO)
    }

    /// Software reset (255 with 1234): a power cycle.
    pub fn reset(&mut self) {
        self.resets += 1;
        self.power_on();
    }

    /// Unsolicited frames (138 events) produced since the last call.
    pub fn take_events(&mut self) -> Vec<[u8; FRAME_LEN]> {
        std::mem::take(&mut self.events)
    }

    pub fn has_events(&self) -> bool {
        !self.events.is_empty()
    }

    pub(crate) fn push_event(&mut self, mask: u32) {
        let reply = Reply::new(self.host_address(), self.last_address, Status::Event, opcode::TARGET_REACHED_EVENT, mask as i32);
        self.events.push(reply.encode());
    }

    pub(crate) fn special_version(&self) -> [u8; FRAME_LEN] {
        version_string_reply(self.host_address(), &self.profile.version_text())
    }

    pub(crate) fn shaft_sign(&self) -> f64 {
        if self.globals[0][gp::REVERSE_SHAFT as usize] == 1 { -1.0 } else { 1.0 }
    }

    /// Mechanical position of an axis for a motor position.
    pub(crate) fn mech(&self, motor: usize, x: f64) -> f64 {
        x * self.shaft_sign() + self.axes[motor].mech_offset
    }

    /// Where the carriage of an axis is, in the world's coordinates.
    pub fn mechanical_position(&self, motor: usize) -> f64 {
        self.mech(motor, self.axes[motor].motion.x)
    }

    /// Logical switch states (after GP 79 polarity): (left, right, home).
    pub fn switches(&self, motor: usize) -> (bool, bool, bool) {
        self.switches_at(motor, self.axes[motor].motion.x)
    }

    pub(crate) fn switches_at(&self, motor: usize, x: f64) -> (bool, bool, bool) {
        let w = &self.world.axes[motor];
        let m = self.mech(motor, x);
        let invert = self.globals[0][gp::END_SWITCH_POLARITY as usize] == 1;
        (w.left_pressed(m) ^ invert, w.right_pressed(m) ^ invert, w.home_pressed(m))
    }

    pub(crate) fn stops_at(&self, motor: usize, x: f64) -> motion::Stops {
        if self.axes[motor].rfs.is_some() {
            // AP 12/13 do not influence the reference search.
            return motion::Stops::default();
        }
        let (left, right, _) = self.switches_at(motor, x);
        let p = &self.axes[motor].params;
        motion::Stops {
            block_positive: right && p[ap::RIGHT_SWITCH_DISABLE as usize] == 0,
            block_negative: left && p[ap::LEFT_SWITCH_DISABLE as usize] == 0,
            soft: p[ap::SOFT_STOP as usize] == 1,
        }
    }

    /// Ramp settings of an axis in µsteps and seconds.
    pub(crate) fn ramp(&self, motor: usize) -> motion::Ramp {
        if let Some(r) = self.axes[motor].ramp_override {
            return r;
        }
        let p = &self.axes[motor].params;
        let pd = p[ap::PULSE_DIVISOR as usize].clamp(0, 13) as u32;
        let rd = p[ap::RAMP_DIVISOR as usize].clamp(0, 13) as u32;
        let a = p[ap::MAX_ACCELERATION as usize].clamp(0, 2047) as u32;
        let mut vmax = p[ap::MAX_SPEED as usize].clamp(0, 2047) as f64;
        let mut target_velocity = p[ap::TARGET_SPEED as usize] as f64;
        if self.axes[motor].closed_loop.torque_mode {
            target_velocity = self.torque_mode_velocity(motor);
        }
        if let Some(rfs) = &self.axes[motor].rfs {
            let slow = p[ap::REFERENCE_SWITCH_SPEED as usize].clamp(0, 2047) as f64;
            match rfs.current() {
                Some(seek) => {
                    let fast = p[ap::REFERENCE_SEARCH_SPEED as usize].clamp(0, 2047) as f64;
                    target_velocity = seek.dir * if seek.fast { fast } else { slow };
                }
                None => vmax = slow.max(1.0),
            }
        }
        motion::Ramp {
            vmax: motion::velocity_pps(vmax, pd),
            vmin: motion::velocity_pps(p[ap::MIN_SPEED as usize].clamp(0, 2047) as f64, pd),
            accel_position: motion::accel_pps2(motion::positioning_accel(a.max(1), rd, pd), rd, pd),
            accel_velocity: motion::accel_pps2(a.max(1) as f64, rd, pd),
            target_velocity: motion::velocity_pps(target_velocity, pd),
        }
    }
}
