//! How virtual time relates to the wall clock: an explicit value, held by
//! the [`Bus`](crate::bus::Bus).
//!
//! The wall clock is `std::time::Instant`, the one thing of the system the
//! firmware uses. On `wasm32-unknown-unknown` it compiles but panics when
//! read ([`Clock::wall_from`], and [`Clock::now_ns`] of a wall clock): there
//! only a stepped clock runs.

use std::time::{Duration, Instant};

/// The source of "now" for a bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// Virtual time follows the wall clock: it was `origin_ns` at `origin`.
    Wall {
        /// The wall-clock instant taken as the origin.
        origin: Instant,
        /// Virtual time at `origin`, in ns.
        origin_ns: u64,
    },
    /// Virtual time moves only when the bus is told to advance.
    Stepped,
}

impl Clock {
    /// A wall clock that reads `now_ns` at this instant.
    pub fn wall_from(now_ns: u64) -> Clock {
        Clock::Wall { origin: Instant::now(), origin_ns: now_ns }
    }

    /// Virtual time now. A stepped clock does not move by itself: it reads
    /// `current_ns`, where the bus already is.
    pub fn now_ns(&self, current_ns: u64) -> u64 {
        match *self {
            Clock::Wall { origin, origin_ns } => (origin_ns + origin.elapsed().as_nanos() as u64).max(current_ns),
            Clock::Stepped => current_ns,
        }
    }

    /// The wall-clock instant of a virtual time; `None` for a stepped
    /// clock (nothing happens until the bus is advanced).
    pub fn instant_of(&self, ns: u64) -> Option<Instant> {
        match *self {
            Clock::Wall { origin, origin_ns } => Some(origin + Duration::from_nanos(ns.saturating_sub(origin_ns))),
            Clock::Stepped => None,
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
        let c = Clock::wall_from(5_000_000_000);
        let now = c.now_ns(0);
        assert!((5_000_000_000..6_000_000_000).contains(&now), "{now}");
        // A bus already ahead (it was advanced) is not sent back.
        assert_eq!(c.now_ns(u64::MAX / 2), u64::MAX / 2);
        let Clock::Wall { origin, .. } = c else { unreachable!() };
        assert_eq!(c.instant_of(5_000_000_000 + 1_000), Some(origin + Duration::from_nanos(1_000)));
    }
}
