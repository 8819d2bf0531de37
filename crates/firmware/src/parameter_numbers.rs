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
