//! A typed, read-only picture of a module at one virtual moment, for
//! observers (a web UI, a plot, a test): axes, program and I/O.

use crate::module::Module;
use crate::program::RunMode;

/// One axis.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisSnapshot {
    /// Actual position (AP 1), µsteps.
    pub position: i32,
    /// Target position (AP 0).
    pub target: i32,
    /// Actual speed (AP 3), internal units.
    pub speed: i32,
    /// The motor stands on its target (AP 8).
    pub position_reached: bool,
    /// A stop switch stopped the motor.
    pub stopped_by_switch: bool,
    /// Logical switch states after GP 79: left, right, home.
    pub left: bool,
    /// The right switch reads pressed.
    pub right: bool,
    /// The home switch reads pressed.
    pub home: bool,
    /// The load torque the world puts on the axis here, % of rated.
    pub load: f64,
    /// The motor current in effect, 0…255 (AP 6/7/200 scale).
    pub current: u32,
    /// The last stallGuard2 reading (AP 206), 0…1023.
    pub stallguard: i32,
    /// Where the carriage is, in world coordinates.
    pub carriage: f64,
}

/// The program interpreter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProgramSnapshot {
    /// What the interpreter is doing (GP 128).
    pub state: RunMode,
    /// The program counter as the module reports it (GP 130).
    pub pc: u16,
    /// The accumulator.
    pub accumulator: i32,
    /// The X register.
    pub x: i32,
    /// Result of the last comparison: -1 less, 0 equal, 1 greater.
    pub compare: i8,
    /// Error flags (timeout, alarm, deviation, position, shutdown bits).
    pub errors: u8,
    /// Return addresses on the CSUB stack.
    pub stack_depth: usize,
    /// A WAIT is in progress.
    pub waiting: bool,
    /// In an interrupt handler.
    pub in_interrupt: bool,
}

/// Inputs and outputs.
#[derive(Clone, Debug, PartialEq)]
pub struct IoSnapshot {
    /// Digital inputs, bit n = input n.
    pub inputs: u32,
    /// Digital outputs, bit n = output n.
    pub outputs: u32,
    /// ADC readings 0…4095.
    pub analog: Vec<u16>,
    /// Supply voltage, volts.
    pub supply: f64,
    /// Driver temperature, °C.
    pub temperature: f64,
}

/// One module.
#[derive(Clone, Debug, PartialEq)]
pub struct ModuleSnapshot {
    /// The module's name, as its profile gives it.
    pub name: String,
    /// The module's serial address (GP 66).
    pub address: u8,
    /// Virtual time of the picture, ns.
    pub time_ns: u64,
    /// The axes, axis 0 first.
    pub axes: Vec<AxisSnapshot>,
    /// The program interpreter.
    pub program: ProgramSnapshot,
    /// Inputs and outputs.
    pub io: IoSnapshot,
}

impl ModuleSnapshot {
    /// The picture of `m` at its virtual now.
    pub fn of(m: &Module) -> ModuleSnapshot {
        let t_s = m.now_ns() as f64 * 1e-9;
        let axes = (0..m.profile().module.axes as usize)
            .map(|a| {
                let axis = m.axis(a);
                let (left, right, home) = m.switches(a);
                let position = m.actual_position(a);
                let carriage = m.mechanical_position(a);
                AxisSnapshot {
                    position,
                    target: axis.target_word,
                    speed: m.actual_speed(a),
                    position_reached: position == axis.target_word && axis.motion.v == 0.0,
                    stopped_by_switch: axis.motion.stopped_by_switch,
                    left,
                    right,
                    home,
                    load: m.world().axes[a].load_at(carriage, t_s),
                    current: m.motor_current(a),
                    stallguard: axis.driver.load_value,
                    carriage,
                }
            })
            .collect();
        let r = m.registers();
        let p = m.program();
        let program = ProgramSnapshot {
            state: p.mode,
            pc: p.counter(),
            accumulator: r.accumulator,
            x: r.x,
            compare: match r.compare {
                crate::module::Compare::Less => -1,
                crate::module::Compare::Equal => 0,
                crate::module::Compare::Greater => 1,
            },
            errors: r.errors,
            stack_depth: p.stack.len(),
            waiting: p.wait.is_some(),
            in_interrupt: p.handler.is_some(),
        };
        let w = m.world();
        let io = IoSnapshot {
            inputs: w.digital_inputs,
            outputs: m.outputs(),
            analog: w.analog_inputs.clone(),
            supply: f64::from(w.supply_decivolts) / 10.0,
            temperature: w.temperature,
        };
        ModuleSnapshot { name: m.profile().module.name.clone(), address: m.address(), time_ns: m.now_ns(), axes, program, io }
    }
}
