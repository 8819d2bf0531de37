//! Global parameter RAM (banks 0–3) and the state of the two global
//! parameters that are computed rather than stored: the tick timer (GP 132)
//! and the random number generator (GP 133).

use std::ops::{Index, IndexMut};

/// Banks 0…3, indexed `globals[bank][param]`.
#[derive(Clone, Debug)]
pub struct Globals {
    banks: [[i32; 256]; 4],
    /// GP 132 counts milliseconds from `tick_offset_ms` at `tick_base_ns`.
    tick_base_ns: u64,
    tick_offset_ms: i64,
    /// GP 133's xorshift32 state.
    rng: u32,
}

impl Default for Globals {
    fn default() -> Globals {
        Globals { banks: [[0; 256]; 4], tick_base_ns: 0, tick_offset_ms: 0, rng: 0x2545_F491 }
    }
}

impl Globals {
    /// Every parameter of every bank to 0 (before the power-up values).
    pub fn clear(&mut self) {
        self.banks = [[0; 256]; 4];
    }

    /// User variable `i` (bank 2).
    pub fn user_variable(&self, i: usize) -> i32 {
        self.banks[2][i]
    }

    pub fn set_user_variable(&mut self, i: usize, v: i32) {
        self.banks[2][i] = v;
    }

    /// GP 132: milliseconds since it was set, 31 bits.
    pub fn tick_timer(&self, now_ns: u64) -> i32 {
        let ms = (now_ns - self.tick_base_ns) / 1_000_000;
        (self.tick_offset_ms + ms as i64) as i32 & i32::MAX
    }

    /// SGP 132 (and power-up): the tick timer reads `ms` at `now_ns`.
    pub fn set_tick_timer(&mut self, now_ns: u64, ms: i64) {
        self.tick_base_ns = now_ns;
        self.tick_offset_ms = ms;
    }

    /// GP 133: the next random number (xorshift32, 31 bits).
    pub fn random(&mut self) -> i32 {
        self.rng = Self::next_random(self.rng);
        (self.rng >> 1) as i32
    }

    /// The number GP 133 will read next, leaving the generator as it is
    /// (an observer's look).
    pub fn peek_random(&self) -> i32 {
        (Self::next_random(self.rng) >> 1) as i32
    }

    fn next_random(mut x: u32) -> u32 {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        x
    }

    /// SGP 133: seeds the generator (never with 0).
    pub fn seed_random(&mut self, seed: i32) {
        self.rng = seed as u32 | 1;
    }
}

impl Index<usize> for Globals {
    type Output = [i32; 256];

    fn index(&self, bank: usize) -> &[i32; 256] {
        &self.banks[bank]
    }
}

impl IndexMut<usize> for Globals {
    fn index_mut(&mut self, bank: usize) -> &mut [i32; 256] {
        &mut self.banks[bank]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn banks_are_separate_and_clear_empties_them() {
        let mut g = Globals::default();
        g[0][66] = 3;
        g[2][66] = -9;
        assert_eq!((g[0][66], g[1][66], g[2][66], g[3][66]), (3, 0, -9, 0));
        g.clear();
        assert_eq!((g[0][66], g[2][66]), (0, 0));
    }

    #[test]
    fn tick_timer_counts_milliseconds_from_where_it_was_set() {
        let mut g = Globals::default();
        assert_eq!(g.tick_timer(2_500_000), 2);
        g.set_tick_timer(10_000_000, 100);
        assert_eq!(g.tick_timer(10_000_000), 100);
        assert_eq!(g.tick_timer(15_999_999), 105);
        g.set_tick_timer(0, i64::from(i32::MAX));
        assert_eq!(g.tick_timer(1_000_000), 0, "31 bits wrap");
    }

    #[test]
    fn random_numbers_are_31_bit_and_repeat_with_the_seed() {
        let mut g = Globals::default();
        g.seed_random(42);
        let a: Vec<i32> = (0..50).map(|_| g.random()).collect();
        assert!(a.iter().all(|&v| v >= 0));
        assert!(a.windows(2).any(|w| w[0] != w[1]));
        g.seed_random(42);
        assert_eq!((0..50).map(|_| g.random()).collect::<Vec<_>>(), a);
        g.seed_random(0);
        assert_ne!(g.random(), 0, "seed 0 is made odd");
    }
}
