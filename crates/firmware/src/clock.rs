//! How virtual time relates to the wall clock: an explicit value, held by
//! the [`Bus`](crate::bus::Bus).
//!
//! The wall clock is `std::time::Instant`, the one thing of the system the
//! firmware uses. On `wasm32-unknown-unknown` it compiles but panics when
//! read ([`Clock::wall_from`], and [`Clock::now_ns`] of a wall clock): there
//! only a stepped clock runs.

use std::time::{Duration, Instant};

/// The source of "now" for a bus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Clock {
    /// Virtual time follows the wall clock: it was `origin_ns` at `origin`
    /// and runs `speed` times as fast.
    Wall {
        /// The wall-clock instant taken as the origin.
        origin: Instant,
        /// Virtual time at `origin`, in ns.
        origin_ns: u64,
        /// Virtual seconds per wall-clock second ([`Speed`]).
        speed: Speed,
    },
    /// Virtual time moves only when the bus is told to advance.
    Stepped,
}

/// How fast virtual time runs against the wall clock: a factor from
/// [`Speed::MIN`] to [`Speed::MAX`] (1: as fast as the wall clock).
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
pub struct Speed(f64);

/// Why a speed was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BadSpeed(pub f64);

impl std::fmt::Display for BadSpeed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        // Very large or small values in the exponent form, as typed.
        let value = if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) { format!("{v:e}") } else { v.to_string() };
        if v.is_finite() && v > 0.0 {
            write!(f, "speed {value} is outside {}…{} (1 = as fast as the wall clock)", Speed::MIN, Speed::MAX)
        } else {
            write!(f, "speed {value} is not a positive finite number (1 = as fast as the wall clock)")
        }
    }
}

impl std::error::Error for BadSpeed {}

impl Speed {
    /// The wall clock's own pace.
    pub const REAL_TIME: Speed = Speed(1.0);
    /// The slowest speed: a thousandth of the wall clock's pace.
    pub const MIN: f64 = 0.001;
    /// The fastest speed: a virtual day in under a wall-clock second.
    pub const MAX: f64 = 100_000.0;

    /// A speed of `factor` virtual seconds per wall-clock second, within
    /// [`Speed::MIN`]…[`Speed::MAX`].
    pub fn new(factor: f64) -> Result<Speed, BadSpeed> {
        if factor.is_finite() && (Speed::MIN..=Speed::MAX).contains(&factor) { Ok(Speed(factor)) } else { Err(BadSpeed(factor)) }
    }

    /// The factor.
    pub fn factor(self) -> f64 {
        self.0
    }

    /// The wall-clock time that `virtual_ns` of virtual time take.
    pub fn wall(self, virtual_ns: u64) -> Duration {
        // (u64::MAX ns at the slowest speed are 5.8e14 s: a Duration holds them.)
        if self.0 == 1.0 { Duration::from_nanos(virtual_ns) } else { Duration::from_secs_f64(virtual_ns as f64 * 1e-9 / self.0) }
    }

    /// The virtual time that passes in `wall` of wall-clock time.
    fn virtual_ns(self, wall: Duration) -> u64 {
        if self.0 == 1.0 { wall.as_nanos() as u64 } else { (wall.as_secs_f64() * self.0 * 1e9) as u64 }
    }
}

impl Default for Speed {
    /// The wall clock's own pace.
    fn default() -> Speed {
        Speed::REAL_TIME
    }
}

impl std::str::FromStr for Speed {
    type Err = String;

    /// A speed as a command line or a fleet file writes it (`50`, `0.5`).
    fn from_str(text: &str) -> Result<Speed, String> {
        let factor: f64 = text.trim().parse().map_err(|_| format!("speed '{text}' is not a number (1 = as fast as the wall clock)"))?;
        Speed::new(factor).map_err(|e| e.to_string())
    }
}

/// Wall-clock time allowed for work done on the wall clock's behalf (a
/// bus catching up with it), from when it was made.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Budget {
    start: Instant,
    limit: Duration,
}

impl Budget {
    /// A budget of `limit` from now.
    pub(crate) fn new(limit: Duration) -> Budget {
        Budget { start: Instant::now(), limit }
    }

    /// The budget is used up.
    pub(crate) fn spent(&self) -> bool {
        self.start.elapsed() >= self.limit
    }

    /// Wall-clock time since the budget was made.
    pub(crate) fn elapsed(&self) -> Duration {
        self.start.elapsed()
    }
}

impl Clock {
    /// A wall clock that reads `now_ns` at this instant, running `speed`
    /// times as fast as the wall clock.
    pub fn wall_from(now_ns: u64, speed: Speed) -> Clock {
        Clock::Wall { origin: Instant::now(), origin_ns: now_ns, speed }
    }

    /// Virtual time now. A stepped clock does not move by itself: it reads
    /// `current_ns`, where the bus already is.
    pub fn now_ns(&self, current_ns: u64) -> u64 {
        match *self {
            Clock::Wall { origin, origin_ns, speed } => origin_ns.saturating_add(speed.virtual_ns(origin.elapsed())).max(current_ns),
            Clock::Stepped => current_ns,
        }
    }

    /// The wall-clock instant of a virtual time; `None` for a stepped
    /// clock (nothing happens until the bus is advanced).
    pub fn instant_of(&self, ns: u64) -> Option<Instant> {
        match *self {
            // Beyond what an Instant holds (centuries away): never.
            Clock::Wall { origin, origin_ns, speed } => origin.checked_add(speed.wall(ns.saturating_sub(origin_ns))),
            Clock::Stepped => None,
        }
    }

    /// The wall-clock time that `virtual_ns` take: scaled by the speed of
    /// a wall clock; as it is for a stepped clock (its replies are not
    /// held back by anything but their own delays).
    pub fn wall_duration(&self, virtual_ns: u64) -> Duration {
        match *self {
            Clock::Wall { speed, .. } => speed.wall(virtual_ns),
            Clock::Stepped => Duration::from_nanos(virtual_ns),
        }
    }

    /// True when virtual time moves only when the bus is told to advance.
    pub fn is_stepped(&self) -> bool {
        matches!(self, Clock::Stepped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stepped_clock_reads_where_the_bus_is() {
        assert_eq!(Clock::Stepped.now_ns(42), 42);
        assert_eq!(Clock::Stepped.instant_of(1_000), None);
    }

    #[test]
    fn a_wall_clock_starts_at_its_origin_and_never_goes_back() {
        let c = Clock::wall_from(5_000_000_000, Speed::REAL_TIME);
        let now = c.now_ns(0);
        assert!((5_000_000_000..6_000_000_000).contains(&now), "{now}");
        // A bus already ahead (it was advanced) is not sent back.
        assert_eq!(c.now_ns(u64::MAX / 2), u64::MAX / 2);
        let Clock::Wall { origin, .. } = c else { unreachable!() };
        assert_eq!(c.instant_of(5_000_000_000 + 1_000), Some(origin + Duration::from_nanos(1_000)));
    }

    #[test]
    fn a_faster_clock_maps_virtual_time_to_a_shorter_wall_time() {
        let fifty = Speed::new(50.0).unwrap();
        let c = Clock::wall_from(1_000_000_000, fifty);
        let Clock::Wall { origin, .. } = c else { unreachable!() };
        // One virtual second after the origin is 20 ms of wall time later.
        assert_eq!(c.instant_of(2_000_000_000), Some(origin + Duration::from_millis(20)));
        assert_eq!(c.wall_duration(500_000_000), Duration::from_millis(10));
        assert_eq!(fifty.virtual_ns(Duration::from_millis(20)), 1_000_000_000);
        assert_eq!(Clock::Stepped.wall_duration(7), Duration::from_nanos(7));
    }

    #[test]
    fn only_positive_finite_speeds() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(Speed::new(bad).is_err(), "{bad}");
        }
        assert_eq!("50".parse::<Speed>().map(Speed::factor), Ok(50.0));
        assert_eq!("0.25".parse::<Speed>().map(Speed::factor), Ok(0.25));
        assert_eq!("0".parse::<Speed>().unwrap_err(), "speed 0 is not a positive finite number (1 = as fast as the wall clock)");
        assert_eq!("fast".parse::<Speed>().unwrap_err(), "speed 'fast' is not a number (1 = as fast as the wall clock)");
        assert!("inf".parse::<Speed>().is_err());
        assert_eq!(Speed::new(1e-300).unwrap_err().to_string(), "speed 1e-300 is outside 0.001…100000 (1 = as fast as the wall clock)");
        assert_eq!(Speed::new(1e6).unwrap_err().to_string(), "speed 1e6 is outside 0.001…100000 (1 = as fast as the wall clock)");
        // The extremes map every virtual time to a wall time, or to never.
        for factor in [Speed::MIN, Speed::MAX] {
            let c = Clock::wall_from(0, Speed::new(factor).unwrap());
            let _ = c.instant_of(u64::MAX);
            let _ = c.wall_duration(u64::MAX);
            assert!(c.now_ns(0) < u64::MAX);
        }
    }
}
