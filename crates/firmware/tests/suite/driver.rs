//! stallGuard2, coolStep, stop on stall, driver faults and lost steps
//! against the load model of docs/world.md.

use crate::common;

use common::{BusOfOne, MS, load, send};

use tmclsim_protocol::mnemonic::parse_line;

fn module() -> BusOfOne {
    let mut m = BusOfOne::built_in("tmcm-1141");
    send(&mut m, "SAP 6, 0, 255");
    m
}

#[test]
fn load_value_falls_with_load() {
    let mut m = module();
    send(&mut m, "ROR 0, 500");
    m.advance(500 * MS);
    let free = send(&mut m, "GAP 206, 0");
    load(&mut m, 40.0);
    m.advance(10 * MS);
    let loaded = send(&mut m, "GAP 206, 0");
    load(&mut m, 80.0);
    m.advance(10 * MS);
    let heavy = send(&mut m, "GAP 206, 0");
    assert!(free > loaded && loaded > heavy && heavy > 0, "{free} {loaded} {heavy}");
    // A higher threshold (less sensitive) reads higher.
    send(&mut m, "SAP 174, 0, 20");
    m.advance(10 * MS);
    assert_eq!(send(&mut m, "GAP 206, 0"), heavy + 160);
}

#[test]
fn stall_stops_above_ap181_but_not_below() {
    // Below the stop speed: the motor goes on (and loses steps).
    let mut m = module();
    send(&mut m, "SAP 181, 0, 800");
    send(&mut m, "ROR 0, 500");
    m.advance(500 * MS);
    load(&mut m, 150.0);
    m.advance(100 * MS);
    assert_eq!(send(&mut m, "GAP 206, 0"), 0);
    assert_eq!(send(&mut m, "GAP 208, 0") & 1, 1, "stallGuard2 status bit");
    assert_eq!(send(&mut m, "GAP 3, 0"), 500, "below AP 181: not stopped");
    // The carriage does not follow: steps are lost.
    let mech = m.mechanical_position(0);
    m.advance(100 * MS);
    assert_eq!(m.mechanical_position(0), mech);
    // Above the stop speed: stopped, AP 207 set (and cleared by reading).
    let mut m = module();
    send(&mut m, "SAP 181, 0, 300");
    send(&mut m, "ROR 0, 500");
    m.advance(500 * MS);
    load(&mut m, 150.0);
    m.advance(10 * MS);
    assert_eq!(send(&mut m, "GAP 3, 0"), 0);
    assert_eq!(send(&mut m, "GAP 2, 0"), 0);
    assert_eq!(send(&mut m, "GAP 207, 0"), 1);
    assert_eq!(send(&mut m, "GAP 207, 0"), 0);
}

#[test]
fn stall_interrupt_fires() {
    let mut m = module();
    send(&mut m, "SAP 181, 0, 100");
    let words: Vec<_> =
        ["VECT 15, 5", "EI 15", "EI 255", "ROR 0, 500", "JA 4", "CALCV ADD, 9, 1", "RETI"].iter().map(|l| parse_line(l).unwrap()).collect();
    m.load_program(&words).unwrap();
    m.start_program();
    m.advance(500 * MS);
    load(&mut m, 150.0);
    m.advance(50 * MS);
    assert_eq!(send(&mut m, "GGP 9, 2"), 1);
}

#[test]
fn coolstep_current_rises_with_load() {
    let mut m = module();
    // coolStep on: SEMIN 2 (lower threshold 64), hysteresis 1 (upper 128),
    // above speed 100.
    send(&mut m, "SAP 172, 0, 2");
    send(&mut m, "SAP 170, 0, 1");
    send(&mut m, "SAP 171, 0, 3");
    send(&mut m, "SAP 169, 0, 3");
    send(&mut m, "SAP 182, 0, 100");
    send(&mut m, "ROR 0, 500");
    m.advance(2000 * MS);
    let light = send(&mut m, "GAP 180, 0");
    load(&mut m, 50.0);
    m.advance(2000 * MS);
    let heavy = send(&mut m, "GAP 180, 0");
    assert!(light < heavy, "coolStep scale {light} without load, {heavy} with");
    assert!(light >= 15, "not below half of CS: {light}");
    // Below the threshold speed the slow-run current applies.
    send(&mut m, "SAP 183, 0, 80");
    send(&mut m, "ROR 0, 50");
    m.advance(2000 * MS);
    assert_eq!(send(&mut m, "GAP 180, 0"), 80 >> 3);
}

#[test]
fn driver_fault_flags() {
    let mut m = module();
    assert_eq!(send(&mut m, "GAP 208, 0") & 0x7E, 0);
    m.world_mut().temperature = 125.0;
    assert_eq!(send(&mut m, "GAP 208, 0") & 0x06, 0x04, "pre-warning");
    m.world_mut().temperature = 155.0;
    assert_eq!(send(&mut m, "GAP 208, 0") & 0x06, 0x06, "shutdown");
    m.world_mut().temperature = 40.0;
    m.world_mut().axes[0].faults.short_a = true;
    m.world_mut().axes[0].faults.open_b = true;
    assert_eq!(send(&mut m, "GAP 208, 0") & 0x78, 0x08 | 0x40);
    // A driver that is shut down gives no torque: the carriage stays.
    send(&mut m, "ROR 0, 500");
    m.advance(500 * MS);
    assert_eq!(m.mechanical_position(0), 0.0);
    assert!(send(&mut m, "GAP 1, 0") > 0, "the counter runs on");
    // Standstill flag after 2^20 clocks without a step.
    let mut m = module();
    m.advance(100 * MS);
    assert_eq!(send(&mut m, "GAP 208, 0") & 0x80, 0x80);
    send(&mut m, "ROR 0, 100");
    m.advance(10 * MS);
    assert_eq!(send(&mut m, "GAP 208, 0") & 0x80, 0);
}

#[test]
fn undervoltage_and_end_stops_lose_steps() {
    let mut m = module();
    m.world_mut().supply_decivolts = 60;
    send(&mut m, "ROR 0, 500");
    m.advance(200 * MS);
    assert_eq!(m.mechanical_position(0), 0.0);
    let mut m = module();
    m.world_mut().axes[0].travel = Some((-1000.0, 1000.0));
    send(&mut m, "SAP 4, 0, 2047");
    send(&mut m, "MVP ABS, 0, 5000");
    m.advance(2000 * MS);
    assert_eq!(send(&mut m, "GAP 1, 0"), 5000);
    assert_eq!(m.mechanical_position(0), 1000.0, "against the end stop");
}
