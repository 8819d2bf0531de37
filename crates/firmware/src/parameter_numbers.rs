//! Axis (`ap`) and global (`gp`) parameter numbers the firmware gives a
//! meaning to.

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
    /// GP 64: the EEPROM magic word, which marks the stored settings as
    /// valid.
    pub const EEPROM_MAGIC: u8 = 64;
    /// GP 65: the RS-485 baud rate setting.
    pub const BAUD_RATE: u8 = 65;
    /// GP 66: the module's serial address.
    pub const SERIAL_ADDRESS: u8 = 66;
    /// GP 67: ASCII command mode on (1) or off.
    pub const ASCII_MODE: u8 = 67;
    /// GP 68: serial heartbeat in ms (0: off).
    pub const HEARTBEAT: u8 = 68;
    /// GP 77: auto start: the stored program runs after power-up.
    pub const AUTOSTART: u8 = 77;
    /// GP 73: EEPROM lock (docs/behaviour.md rule 73).
    pub const EEPROM_LOCK: u8 = 73;
    /// GP 80: shutdown pin function.
    pub const SHUTDOWN_PIN: u8 = 80;
    /// GP 81: TMCL code protection.
    pub const CODE_PROTECTION: u8 = 81;
    /// GP 75: telegram pause time, the delay before a reply.
    pub const TELEGRAM_PAUSE: u8 = 75;
    /// GP 76: the serial host address of replies.
    pub const HOST_ADDRESS: u8 = 76;
    /// GP 79: end switch polarity (one bit per switch).
    pub const END_SWITCH_POLARITY: u8 = 79;
    /// GP 84: coordinate storage (0: RAM only, 1: coordinates are also stored
    /// in the EEPROM).
    pub const COORDINATE_STORAGE: u8 = 84;
    /// GP 85: do not restore user variables from the EEPROM at power-up.
    pub const DONT_RESTORE_USER_VARIABLES: u8 = 85;
    /// GP 87: the serial secondary address (0: off).
    pub const SECONDARY_ADDRESS: u8 = 87;
    /// GP 90: reverse shaft direction.
    pub const REVERSE_SHAFT: u8 = 90;
    /// GP 128: TMCL application status (stop, run, step, reset).
    pub const APPLICATION_STATUS: u8 = 128;
    /// GP 129: download mode on or off.
    pub const DOWNLOAD_MODE: u8 = 129;
    /// GP 130: TMCL program counter.
    pub const PROGRAM_COUNTER: u8 = 130;
    /// GP 132: the tick timer, counting ms from where it was last set.
    pub const TICK_TIMER: u8 = 132;
    /// GP 133: a random number (a new one on each read).
    pub const RANDOM: u8 = 133;
    /// GP 255: 1 suppresses the replies in direct mode, except for GAP, GGP
    /// and GIO.
    pub const SUPPRESS_REPLY: u8 = 255;
}

/// Axis parameter numbers of the sixPoint modules (TMC5130/TMC5160) that
/// the TMC429 modules number otherwise or lack: the sixPoint motion
/// controller's own rows (docs/behaviour.md rules 104–110).
pub mod sp {
    /// Swap the left and right limit switches.
    pub const SWAP_SWITCHES: u8 = 14;
    /// A1: the acceleration below V1.
    pub const A1: u8 = 15;
    /// V1: where A1 gives way to AMAX, DMAX to D1.
    pub const V1: u8 = 16;
    /// DMAX: the deceleration above V1.
    pub const DMAX: u8 = 17;
    /// D1: the deceleration below V1.
    pub const D1: u8 = 18;
    /// VSTART: the speed a move starts at.
    pub const VSTART: u8 = 19;
    /// VSTOP: the speed at which the motor stops.
    pub const VSTOP: u8 = 20;
    /// TZEROWAIT: the standstill after a stop, in 512 clock cycles.
    pub const RAMP_WAIT: u8 = 21;
    /// A2 (eight-point): the acceleration from V1 to V2.
    pub const A2: u8 = 34;
    /// V2 (eight-point): where A2 gives way to AMAX, DMAX to D2.
    pub const V2: u8 = 35;
    /// D2 (eight-point): the deceleration from V2 to V1.
    pub const D2: u8 = 36;
    /// Right limit switch polarity (1: inverted).
    pub const RIGHT_SWITCH_POLARITY: u8 = 24;
    /// Left limit switch polarity (1: inverted).
    pub const LEFT_SWITCH_POLARITY: u8 = 25;
    /// Soft stop at a limit switch (1: decelerate).
    pub const SOFT_STOP: u8 = 26;
    /// The measured speed, pps.
    pub const MEASURED_SPEED: u8 = 29;
    /// The speed above which the driver runs in high-speed mode.
    pub const HIGH_SPEED_THRESHOLD: u8 = 22;
    /// dcStep's minimum speed.
    pub const DCSTEP_MIN_SPEED: u8 = 23;
    /// stealthChop is off above this speed.
    pub const PWM_THRESHOLD_SPEED: u8 = 186;
    /// stealthChop's PWM gradient; 0 switches stealthChop off.
    pub const PWM_GRADIENT: u8 = 187;
    /// The power-down ramp: IHOLDDELAY, 2^18 clock cycles per current step.
    pub const POWER_DOWN_RAMP: u8 = 31;
    /// dcStep's stall detection (DC_SG; 0: off).
    pub const DCSTEP_STALLGUARD: u8 = 33;
    /// The TMC5160's global current scaler.
    pub const GLOBAL_SCALER: u8 = 178;
    /// Reverse the motor's direction.
    pub const REVERSE_SHAFT: u8 = 251;
    /// Unit mode: 0 the chip's internal units, 1 pps.
    pub const UNIT_MODE: u8 = 255;
}

/// Axis parameter numbers of the TMC4361A modules (TMCM-1316, 1321, 1370,
/// 1378, 3312, 3351, 1230/1231) that the other families number otherwise
/// or lack, as ADI's open TMCL-Lite firmware for the TMCM-1316 and
/// PyTrinamic number them: the TMC4361A's ramp rows (docs/behaviour.md
/// rules 114–118).
pub mod tmc4361a {
    /// Ramp type: 0 trapezoid, 1 S-shaped.
    pub const RAMP_TYPE: u8 = 14;
    /// VSTART: the speed a move starts at.
    pub const VSTART: u8 = 15;
    /// ASTART: the acceleration below VBREAK (trapezoid), the
    /// acceleration B1 starts from (S-shaped).
    pub const ASTART: u8 = 16;
    /// DMAX: the deceleration above VBREAK, the S-shaped ramp's largest.
    pub const DMAX: u8 = 17;
    /// VBREAK: where ASTART gives way to AMAX and DMAX to DFINAL.
    pub const VBREAK: u8 = 18;
    /// DFINAL: the deceleration below VBREAK (trapezoid).
    pub const DFINAL: u8 = 19;
    /// VSTOP: the speed at which the motor stops.
    pub const VSTOP: u8 = 20;
    /// DSTOP: the deceleration of a soft stop at a switch.
    pub const DSTOP: u8 = 21;
    /// BOW1: the jerk raising the acceleration (B1).
    pub const BOW1: u8 = 22;
    /// BOW2: the jerk bringing the acceleration back to 0 (B2).
    pub const BOW2: u8 = 23;
    /// BOW3: the jerk raising the deceleration (B3).
    pub const BOW3: u8 = 24;
    /// BOW4: the jerk bringing the deceleration back to 0 (B4).
    pub const BOW4: u8 = 25;
    /// Swap the left and right limit switches.
    pub const SWAP_SWITCHES: u8 = 33;
    /// Soft stop at a limit switch (1: decelerate with DSTOP).
    pub const SOFT_STOP: u8 = 34;
    /// Bit 0 of AP 12 and 13: the switch stops the motor.
    pub const SWITCH_ENABLE: i32 = 1;
    /// Bit 1 of AP 12 and 13: the switch's polarity is inverted.
    pub const SWITCH_POLARITY: i32 = 2;
    /// The accelerations the module writes together (AMAX, ASTART, DMAX,
    /// DFINAL, DSTOP): when one of them is above 4 194 303 the module
    /// switches the chip to its direct acceleration values.
    pub const ACCELERATIONS: [u8; 5] = [5, 16, 17, 19, 21];
}
