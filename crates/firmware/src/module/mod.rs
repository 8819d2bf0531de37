//! A virtual TMCL module: the `Module` struct, a composition of its parts
//! (`state/`, `program.rs`), its constructors and accessors, the motor
//! model's views of its axes (`motor.rs`), and power-up and reset. The
//! parts are private to the files of this directory: what the module does
//! lives in them, and they call each other top-down: the links
//! (`frames.rs`, `can.rs`, `ascii.rs`), virtual time (`time.rs`), direct
//! mode (`control.rs`), the program (`interpreter.rs`), the one dispatch
//! (`executor.rs`) and the command families (`commands/`). Everything else
//! (the bus, snapshots, the world's commands) goes through the accessors.

pub mod ascii;
mod boot;
pub mod can;
mod commands;
mod control;
mod executor;
mod frames;
mod interpreter;
mod time;

use crate::eeprom::Eeprom;
use crate::motor::{Motor, MotorMut, Surroundings};
use crate::program::{Program, RunMode};
use crate::state::globals::Globals;
use crate::state::interrupts::Interrupts;
use crate::state::io::Io;
use crate::state::link::Link;
use crate::state::persistence::Persistence;
use crate::world::World;
use std::sync::Arc;
use tmclsim_profile::{Profile, ProfileError};

pub use crate::outcome::{Origin, Outcome, Special};
pub use crate::parameter_numbers::gp;
pub use crate::state::axis::Axis;
pub use crate::state::registers::{Compare, Registers, error_flag};

/// A virtual TMCL module: a composition of its state, one part per concern.
#[derive(Clone, Debug)]
pub struct Module {
    profile: Arc<Profile>,
    /// Virtual time in nanoseconds since the module was created.
    now_ns: u64,
    axes: Vec<Axis>,
    /// Global parameter RAM, banks 0…3.
    globals: Globals,
    io: Io,
    world: World,
    /// The world the module was created in (`reset` of the world control
    /// goes back to it).
    initial_world: World,
    /// The EEPROM image and whether it was written.
    persistence: Persistence,
    registers: Registers,
    interrupts: Interrupts,
    /// The host link: last address, heartbeat, ASCII mode.
    link: Link,
    program: Program,
    /// Resets (255) and reinitialisations (137) since the module was created.
    resets: u32,
    /// The bootloader, while it runs instead of the firmware.
    boot: Option<crate::bootloader::Session>,
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
        world.own_analog_lines = profile.ports.iter().filter(|p| p.own_line && p.number < 32).fold(0, |m, p| m | 1 << p.number);
        let mut m = Module {
            initial_world: world.clone(),
            world,
            axes: Vec::new(),
            globals: Globals::default(),
            io: Io::default(),
            persistence: Persistence::new(eeprom, profile.features.eeprom_lock),
            registers: Registers::default(),
            interrupts: Interrupts::default(),
            link: Link::default(),
            resets: 0,
            boot: None,
            program: Program::new(profile.module.program_memory as usize),
            now_ns: 0,
            profile,
        };
        m.power_on();
        m
    }

    /// A module by built-in profile name.
    pub fn built_in(name: &str) -> Result<Module, ProfileError> {
        Ok(Module::new(Profile::built_in(name)?))
    }

    /// The module's profile: its parameter tables, ports, interrupts and
    /// features.
    pub fn profile(&self) -> &Arc<Profile> {
        &self.profile
    }

    /// The world around the module (switches, loads, inputs, supply).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The world, to change it directly (world commands go through
    /// `WorldCommand::apply`).
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }

    /// The world goes back to the one the module was created in, and each
    /// carriage to that world's start position; the module's own state
    /// (position counters, parameters, program) stays as it is.
    pub fn reset_world(&mut self) {
        self.world = self.initial_world.clone();
        for m in 0..self.axes.len() {
            let start = self.world.axes[m].start;
            self.place_carriage(m, start);
        }
    }

    /// Puts the carriage of an axis at a position of the world (its
    /// mechanical position) without moving the motor: the position counter
    /// keeps its value, as when a carriage is pushed by hand.
    pub fn place_carriage(&mut self, axis: usize, position: f64) {
        let sign = self.motor_view(axis).shaft_sign();
        let a = &mut self.axes[axis];
        a.mech_offset = position - a.motion.x * sign;
    }

    /// The module's EEPROM image as it is stored now.
    pub fn eeprom(&self) -> &Eeprom {
        self.persistence.eeprom()
    }

    /// Puts back an EEPROM image that is known to be stored, after writes
    /// that could not be (docs/behaviour.md rule 82): the RAM stays as it
    /// is, and this is no new write.
    pub fn restore_eeprom(&mut self, image: Eeprom) {
        self.persistence.replace(image);
    }

    /// Changes whenever a command wrote the EEPROM.
    pub fn eeprom_generation(&self) -> u64 {
        self.persistence.generation()
    }

    /// True when this power-up found stored values in the EEPROM; false
    /// when the module started from factory defaults.
    pub fn restored_from_eeprom(&self) -> bool {
        self.persistence.restored
    }

    /// How many times the module was reset (255) or reinitialised (137).
    pub fn resets(&self) -> u32 {
        self.resets
    }

    /// Accumulator, X register, comparison result and error flags of the
    /// interpreter.
    pub fn registers(&self) -> Registers {
        self.registers
    }

    /// The module's virtual time, in ns since it was created.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// Axis `motor` (panics when the module has no such axis).
    pub fn axis(&self, motor: usize) -> &Axis {
        &self.axes[motor]
    }

    /// The motor model's view of axis `m` (panics when there is none).
    pub(crate) fn motor_view(&self, m: usize) -> Motor<'_> {
        Motor { axis: &self.axes[m], world: &self.world.axes[m], at: self.surroundings() }
    }

    /// The motor model's view of axis `m`, to step it.
    pub(crate) fn motor_view_mut(&mut self, m: usize) -> MotorMut<'_> {
        let at = Surroundings::of(&self.profile, &self.globals, &self.world, self.now_ns);
        MotorMut { axis: &mut self.axes[m], world: &self.world.axes[m], at }
    }

    /// What the motor model reads of the module around its axes now.
    pub(crate) fn surroundings(&self) -> Surroundings<'_> {
        Surroundings::of(&self.profile, &self.globals, &self.world, self.now_ns)
    }

    /// AP 1 of axis `m`: the position counter.
    pub fn actual_position(&self, m: usize) -> i32 {
        self.motor_view(m).actual_position()
    }

    /// AP 3 of axis `m`: the actual speed in internal units.
    pub fn actual_speed(&self, m: usize) -> i32 {
        self.motor_view(m).actual_speed()
    }

    /// Where the carriage of axis `m` is, in the world's coordinates.
    pub fn mechanical_position(&self, m: usize) -> f64 {
        self.motor_view(m).mechanical_position()
    }

    /// The switches of axis `m` as the module reads them (after GP 79
    /// polarity): (left, right, home).
    pub fn switches(&self, m: usize) -> (bool, bool, bool) {
        self.motor_view(m).switches()
    }

    /// The current setting in effect on axis `m` (0…255): run, boost,
    /// standby or off.
    pub fn motor_current(&self, m: usize) -> u32 {
        self.motor_view(m).motor_current()
    }

    /// Sign-extends to the module's position counter width (32 or 24 bits).
    pub(crate) fn wrap_position(&self, v: i64) -> i32 {
        crate::motor::wrap_position(v, self.profile.position_bits())
    }

    /// The module address (GP 66).
    pub fn address(&self) -> u8 {
        self.globals[0][gp::SERIAL_ADDRESS as usize] as u8
    }

    /// GP 87; 0 = off.
    pub fn secondary_address(&self) -> u8 {
        self.globals[0][gp::SECONDARY_ADDRESS as usize] as u8
    }

    /// The host address of replies (GP 76).
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
    /// Places the module at `address` on its link: the serial address
    /// (GP 66) and, on a module with CAN identifier parameters, its CAN ID
    /// too, so that modules placed at different addresses on one bus are
    /// reached apart on every interface (docs/behaviour.md rule 92).
    pub fn set_address(&mut self, address: u8) {
        self.globals[0][gp::SERIAL_ADDRESS as usize] = i32::from(address);
        self.persistence.store_global(0, gp::SERIAL_ADDRESS, i32::from(address));
        if let Some(can) = self.profile.features.can {
            self.globals[0][can.id as usize] = i32::from(address);
            self.persistence.store_global(0, can.id, i32::from(address));
        }
    }

    /// Power cycle: RAM from factory defaults, then what the EEPROM holds.
    pub fn power_on(&mut self) {
        let profile = self.profile.clone();
        if let Some(magic) = profile.features.eeprom_magic {
            // Any magic but 0xE4 re-initialises the EEPROM (TMCM-351 GP 64).
            self.persistence.check_magic(magic.parameter, magic.value);
        }
        let ee = self.persistence.eeprom();
        let restored = !ee.axis.is_empty() || !ee.global.is_empty() || !ee.coordinates.is_empty();
        self.globals.clear();
        for bank in 0..4u8 {
            for p in profile.global_parameters(bank) {
                // A stored value the parameter does not take is not taken:
                // files are checked when they are loaded (docs/behaviour.md
                // rule 88); an image handed over from Rust is not, and must
                // not make the module unreachable either (GP 75, GP 66).
                let stored = if p.access.auto || p.access.eeprom { ee.global(bank, p.number) } else { None };
                let stored = stored.filter(|&v| p.accepts(v));
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
                let stored = stored.filter(|&v| p.accepts(v));
                params[p.number as usize] = stored.unwrap_or(p.default_word());
            }
            let mut coordinates = vec![0; profile.module.coordinates as usize + 1];
            if coords_from_eeprom {
                for (n, c) in coordinates.iter_mut().enumerate().skip(1) {
                    *c = ee.coordinate(motor, n as u8).unwrap_or(0);
                }
            }
            // The carriage stays where it is; the position counter restarts at 0.
            let mech = old_axes.get(motor as usize).map_or(self.world.axes[motor as usize].start, |a| {
                let sign = Motor { axis: a, world: &self.world.axes[motor as usize], at: self.surroundings() }.shaft_sign();
                a.motion.x * sign + a.mech_offset
            });
            let mut axis = Axis::new(params, coordinates, mech, self.now_ns);
            if profile.features.motion_controller == tmclsim_profile::MotionController::Tmc4361a {
                // AP 138 is a row of its own there (docs/behaviour.md rule 114).
                axis.ramp_mode_row = false;
                axis.motion.mode = crate::motion::RampMode::Position;
            }
            // ROR and ROL take the speeds AP 2 (target speed) takes.
            if let Some(p) = profile.axis_parameter(crate::parameter_numbers::ap::TARGET_SPEED) {
                axis.speed_limit = p.max.min(i64::from(i32::MAX)) as i32;
            }
            self.axes.push(axis);
        }
        self.persistence.restored = restored;
        self.registers = Registers::default();
        self.interrupts.reset();
        self.link.restart_heartbeat(self.now_ns);
        self.globals.set_tick_timer(self.now_ns, 0);
        // Program memory from the EEPROM; the interpreter starts afresh.
        let words = self.program.memory.len();
        let (trace, breakpoints, instruction_ns) =
            (self.program.trace.take(), std::mem::take(&mut self.program.breakpoints), self.program.instruction_ns);
        self.program = Program::new(words);
        self.program.trace = trace.map(|_| Vec::new());
        self.program.breakpoints = breakpoints;
        self.program.instruction_ns = instruction_ns;
        for (&a, bytes) in &self.persistence.eeprom().program {
            if let Some(w) = self.program.memory.get_mut(a as usize) {
                *w = tmclsim_protocol::Instruction::from_bytes(bytes);
            }
        }
        self.program.download_pointer = self.program.length() as u16;
        self.program.next_ns = self.now_ns;
        let switches = (0..self.axes.len())
            .map(|m| {
                let (l, r, _) = self.switches(m);
                (l, r)
            })
            .collect();
        self.io.power_on(&profile, self.world.digital_inputs, switches);
        for m in 0..self.axes.len() {
            self.motor_view_mut(m).closed_loop_power_on();
        }
        self.link.ascii = self.globals[0][gp::ASCII_MODE as usize] & 1 == 1;
        self.link.new_ascii_session();
        if self.globals[0][gp::AUTOSTART as usize] == 1 && self.program.length() > 0 {
            self.program.mode = RunMode::Run;
        }
        // The bootloader starts first and stays when the flash holds no
        // valid firmware (docs/behaviour.md rule 100).
        self.boot = None;
        if self.persistence.eeprom().firmware == crate::eeprom::Firmware::Invalid
            && let Some(facts) = profile.bootloader.as_ref()
        {
            self.enter_bootloader(facts, true);
        }
    }

    /// The CPU restarts into the bootloader (docs/behaviour.md rule 99):
    /// the firmware's RAM is gone (motors stop, the program and ASCII mode
    /// end); `erased`: the flash holds no firmware (then this is the
    /// power-up itself).
    pub(crate) fn enter_bootloader(&mut self, facts: &tmclsim_profile::Bootloader, erased: bool) {
        if !erased {
            self.resets += 1;
            self.power_on();
        }
        self.boot = Some(crate::bootloader::Session::new(facts, erased));
        self.program.mode = RunMode::Stop;
        self.link.ascii = false;
    }

    /// Software reset (255 with 1234): a power cycle.
    pub fn reset(&mut self) {
        self.resets += 1;
        self.power_on();
    }
}
