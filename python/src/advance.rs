//! Moving virtual time on from Python: durations are checked (refused, not
//! capped, beyond the 2^64 ns virtual time can count: docs/behaviour.md
//! rule 84), and a long advance runs in slices with Ctrl-C checked between
//! them.

use crate::errors::{catch, internal_error, value_error};
use pyo3::prelude::*;
use std::time::{Duration, Instant};
use tmclsim_host::SharedBus;

/// The wall time a slice aims at: Ctrl-C answers within about this long.
const SLICE_WALL: Duration = Duration::from_millis(20);

/// The first slice, in virtual nanoseconds (later ones adapt).
const FIRST_SLICE_NS: u64 = 1_000_000;

/// The longest duration virtual time can count, in seconds.
fn longest_s() -> f64 {
    u64::MAX as f64 * 1e-9
}

/// Seconds (a float) to nanoseconds: finite, not negative, and within
/// virtual time.
pub fn seconds_to_ns(seconds: f64) -> PyResult<u64> {
    if !(seconds >= 0.0 && seconds.is_finite()) {
        return Err(value_error(format!("time moves forward only: a duration is a finite number of seconds ≥ 0, not {seconds}")));
    }
    let ns = (seconds * 1e9).round();
    if ns >= u64::MAX as f64 {
        return Err(value_error(format!("{seconds} s is too long: virtual time ends after {:.0} s (about 584 years)", longest_s())));
    }
    Ok(ns as u64)
}

/// Moves the bus on by `ns` in slices of about [`SLICE_WALL`] of wall
/// time, without the GIL; between slices pending signals are handled, so
/// Ctrl-C raises `KeyboardInterrupt` (the modules stay at the time
/// reached). Slicing changes nothing the modules do (docs/behaviour.md
/// rule 81). A time beyond the end of virtual time is refused first.
pub fn advance_in_slices(py: Python<'_>, shared: &SharedBus, ns: u64) -> PyResult<()> {
    let now = catch(|| shared.now_ns()).map_err(|m| internal_error(py, m))?;
    if now.checked_add(ns).is_none() {
        return Err(value_error(format!(
            "advancing {} s from {} s passes the end of virtual time ({:.0} s)",
            ns as f64 * 1e-9,
            now as f64 * 1e-9,
            longest_s()
        )));
    }
    let mut left = ns;
    let mut slice = FIRST_SLICE_NS;
    loop {
        let step = slice.min(left);
        let started = Instant::now();
        py.detach(|| catch(|| shared.advance(step))).map_err(|m| internal_error(py, m))?;
        left -= step;
        let wall = started.elapsed();
        if wall < SLICE_WALL / 2 {
            slice = slice.saturating_mul(2);
        } else if wall > SLICE_WALL * 2 {
            slice = (slice / 2).max(1);
        }
        py.check_signals()?;
        if left == 0 {
            return Ok(());
        }
    }
}
