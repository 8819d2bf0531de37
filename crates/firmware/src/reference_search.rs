//! The reference search (RFS) of the TMCM-1141: modes 1–8 with the +64
//! (right switch instead of left) and +128 (inverted home switch)
//! variants, as a sequence of seeks.
//!
//! Every seek moves in velocity mode until a switch changes to the wanted
//! state; the position of that change is recorded exactly (the motion
//! model stops its step at switch edges). Switching points are calibrated
//! as the manual says: leave the switch slowly, re-enter it from the other
//! direction, take the middle of the two points. At the end the motor
//! moves to the reference point at the slow speed, and the position
//! counter is set to zero there.
//!
//! The search is a state machine of its own: after every step of motion
//! [`ReferenceSearch::step`] looks at the axis it runs on through
//! [`SearchAxis`], the little it needs of an axis (its position, its
//! switches, stopping, moving to a point, zeroing its counter).

/// What a reference search needs of the axis it runs on.
pub trait SearchAxis {
    /// Where the ramp generator is, in motor coordinates.
    fn position(&self) -> f64;
    /// Whether a switch reads active (as wired, before any inversion of
    /// the search mode) with the motor at `probe`.
    fn switch_at(&self, switch: Switch, probe: f64) -> bool;
    /// A switch stopped the motor at once: the next seek starts from
    /// standstill.
    fn halt(&mut self);
    /// Moves to the reference point in position mode; true when the motor
    /// already stands there.
    fn approach(&mut self, reference: f64) -> bool;
    /// At the reference point: the position counter becomes 0 here, with
    /// the distance between the switches (AP 196) when the mode measures it.
    fn zero_here(&mut self, distance: Option<f64>);
}

/// Which input a seek watches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switch {
    /// The left stop switch.
    Left,
    /// The right stop switch.
    Right,
    /// The home switch.
    Home,
}

/// One seek: move in `dir` until `switch` reads `active`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seek {
    /// The switch the seek watches.
    pub switch: Switch,
    /// The level that ends the seek (true: pressed).
    pub active: bool,
    /// +1 or −1.
    pub dir: f64,
    /// AP 194 (fast) or AP 195 (slow).
    pub fast: bool,
    /// A stop switch that reverses the direction when reached (modes 5, 6).
    pub reverse_on: Option<Switch>,
}

/// How the reference point (and AP 196) follow from the recorded points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Result_ {
    /// Middle of marks 0 and 1.
    Edge,
    /// Mode 2: first switch from marks 0/1, zero point from marks 2/3.
    TwoSwitches,
    /// Mode 3: first switch from marks 0/1, zero = middle of the second
    /// switch (marks 2/3 and 4/5).
    SwitchAndMiddle,
    /// Modes 4, 7, 8: middle of a switch (marks 0/1 and 2/3).
    Middle,
}

/// A reference search in progress.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceSearch {
    seeks: Vec<(Seek, bool)>,
    next: usize,
    marks: Vec<f64>,
    result: Result_,
    /// The home switch's level is inverted (RFS mode with 128 added).
    invert_home: bool,
    /// Direction of the current seek (flipped by `reverse_on`).
    pub dir: f64,
    /// Once all seeks are done: the reference point (motor coordinates)
    /// the motor moves to, and the distance for AP 196.
    finish: Option<(f64, Option<f64>)>,
}

fn seek(switch: Switch, active: bool, dir: f64, fast: bool) -> Seek {
    Seek { switch, active, dir, fast, reverse_on: None }
}

impl ReferenceSearch {
    /// The TMCM-351's (TMC428) modes: 1 left switch; 2 right switch, then
    /// left switch, zero at the left one; 3 (three-switch mode) right
    /// switch, then the reference (home) switch in the negative direction,
    /// zero at its edge. AP 196 gets the distance in modes 2 and 3.
    pub fn new_tmc428(mode: i32) -> Option<ReferenceSearch> {
        let edge = |s: Switch, dir: f64| {
            vec![(seek(s, true, dir, true), false), (seek(s, false, -dir, false), true), (seek(s, true, dir, false), true)]
        };
        let (seeks, result) = match mode {
            1 => (edge(Switch::Left, -1.0), Result_::Edge),
            2 => ([edge(Switch::Right, 1.0), edge(Switch::Left, -1.0)].concat(), Result_::TwoSwitches),
            3 => ([edge(Switch::Right, 1.0), edge(Switch::Home, -1.0)].concat(), Result_::TwoSwitches),
            _ => return None,
        };
        let dir = seeks[0].0.dir;
        Some(ReferenceSearch { seeks, next: 0, marks: Vec::new(), result, invert_home: false, dir, finish: None })
    }

    /// A search for AP 193 = `mode` (TMCM-1141 modes); `None` for a mode
    /// the module lacks.
    pub fn new(mode: i32) -> Option<ReferenceSearch> {
        let base = mode & 0x3F;
        let right = mode & 64 != 0;
        let invert_home = mode & 128 != 0;
        if (right && !(1..=4).contains(&base)) || (invert_home && !(5..=8).contains(&base)) || !(1..=8).contains(&base) {
            return None;
        }
        // The switch searched for the zero point, and the other one.
        let (near, far, toward) = if right { (Switch::Right, Switch::Left, 1.0) } else { (Switch::Left, Switch::Right, -1.0) };
        // Find a stop switch's edge: in fast, out slow, in slow (marked).
        let edge = |s: Switch, dir: f64| {
            vec![(seek(s, true, dir, true), false), (seek(s, false, -dir, false), true), (seek(s, true, dir, false), true)]
        };
        // Its far edge: through it slowly, back in slowly (marked).
        let far_edge = |s: Switch, dir: f64| vec![(seek(s, false, dir, false), true), (seek(s, true, -dir, false), true)];
        let (seeks, result) = match base {
            1 => (edge(near, toward), Result_::Edge),
            2 => ([edge(far, -toward), edge(near, toward)].concat(), Result_::TwoSwitches),
            3 => ([edge(far, -toward), edge(near, toward), far_edge(near, toward)].concat(), Result_::SwitchAndMiddle),
            4 => ([edge(near, toward), far_edge(near, toward)].concat(), Result_::Middle),
            5 | 6 => {
                // Home switch, reversing at the stop switch on the way; the
                // zero point is the home switch edge met in the search
                // direction.
                let (dir, stop) = if base == 5 { (-1.0, Switch::Left) } else { (1.0, Switch::Right) };
                let first = Seek { reverse_on: Some(stop), ..seek(Switch::Home, true, dir, true) };
                (
                    vec![(first, false), (seek(Switch::Home, false, -dir, false), true), (seek(Switch::Home, true, dir, false), true)],
                    Result_::Edge,
                )
            }
            _ => {
                // 7: negative, 8: positive (chapter 7.1), ignoring the stop
                // switches; the middle of the home switch.
                let dir = if base == 7 { -1.0 } else { 1.0 };
                let s = Switch::Home;
                (
                    vec![
                        (seek(s, true, dir, true), false),
                        (seek(s, false, -dir, false), true),
                        (seek(s, true, dir, false), true),
                        (seek(s, false, dir, false), true),
                        (seek(s, true, -dir, false), true),
                    ],
                    Result_::Middle,
                )
            }
        };
        let dir = seeks[0].0.dir;
        Some(ReferenceSearch { seeks, next: 0, marks: Vec::new(), result, invert_home, dir, finish: None })
    }

    /// Lets the search look at its axis after a step of motion (`crossed`:
    /// the step ended at a switch edge; `arrived`: at its target): next
    /// seek, final positioning, zeroing. False once the search is over.
    pub fn step(&mut self, axis: &mut impl SearchAxis, crossed: bool, arrived: bool) -> bool {
        if self.finish.is_none() && crossed {
            let x = axis.position();
            let invert_home = self.invert_home;
            let changed = self.look(x, |s, probe| axis.switch_at(s, probe) ^ (s == Switch::Home && invert_home));
            if changed {
                axis.halt();
            }
            if let Some((reference, distance)) = self.finish {
                // Move to the reference point at the switch speed.
                if axis.approach(reference) {
                    axis.zero_here(distance);
                    return false;
                }
            }
        } else if let (Some((_, distance)), true) = (self.finish, arrived) {
            axis.zero_here(distance);
            return false;
        }
        true
    }

    /// The seek in progress (`None` once the reference point is known).
    pub fn current(&self) -> Option<Seek> {
        self.seeks.get(self.next).map(|(s, _)| Seek { dir: self.dir, ..*s })
    }

    /// Looks at the switches with the motor at `x`: `state(switch, probe)`
    /// tells whether a switch reads active at `probe`, which is taken just
    /// past `x` in the direction of the seek (the motor stands on a switch
    /// edge after every seek, and the next one leaves it at once). Advances
    /// through every seek whose condition holds; returns true when the
    /// motor must stop (a seek ended or the direction reversed).
    pub fn look(&mut self, x: f64, state: impl Fn(Switch, f64) -> bool) -> bool {
        let mut changed = false;
        while let Some(&(s, mark)) = self.seeks.get(self.next) {
            let probe = x + self.dir * 1e-6;
            if let Some(stop) = s.reverse_on
                && stop_is_ahead(stop, self.dir)
                && state(stop, probe)
            {
                self.dir = -self.dir;
                changed = true;
                continue;
            }
            if state(s.switch, probe) != s.active {
                break;
            }
            if mark {
                self.marks.push(x);
            }
            self.next += 1;
            changed = true;
            if let Some(&(n, _)) = self.seeks.get(self.next) {
                self.dir = n.dir;
            }
        }
        if self.next >= self.seeks.len() && self.finish.is_none() {
            self.finish = Some(self.reference());
        }
        changed
    }

    fn reference(&self) -> (f64, Option<f64>) {
        let mid = |a: usize| (self.marks[a] + self.marks[a + 1]) / 2.0;
        match self.result {
            Result_::Edge => (mid(0), None),
            Result_::TwoSwitches => {
                let (first, zero) = (mid(0), mid(2));
                (zero, Some((first - zero).abs()))
            }
            Result_::SwitchAndMiddle => {
                let first = mid(0);
                let zero = (mid(2) + mid(4)) / 2.0;
                (zero, Some((first - zero).abs()))
            }
            Result_::Middle => ((mid(0) + mid(2)) / 2.0, None),
        }
    }
}

fn stop_is_ahead(stop: Switch, dir: f64) -> bool {
    (stop == Switch::Left && dir < 0.0) || (stop == Switch::Right && dir > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_and_variants() {
        for mode in [1, 2, 3, 4, 5, 6, 7, 8, 65, 66, 67, 68, 133, 134, 135, 136] {
            assert!(ReferenceSearch::new(mode).is_some(), "{mode}");
        }
        for mode in [0, 9, 69, 129, 64 + 5, 128 + 1] {
            assert!(ReferenceSearch::new(mode).is_none(), "{mode}");
        }
    }

    #[test]
    fn mode_1_calibrates_the_left_edge() {
        let mut r = ReferenceSearch::new(1).unwrap();
        assert_eq!(r.current().unwrap().dir, -1.0);
        // Reaches the switch at −1000 moving left.
        // Pressed at and below −1000.
        let left = |s: Switch, x: f64| s == Switch::Left && x <= -1000.0;
        assert!(!r.look(-500.0, left));
        // Reaches the edge moving left: leaving it to the right releases
        // the switch at once, re-entering presses it: the edge is found.
        assert!(r.look(-1000.0, left));
        assert_eq!(r.finish, Some((-1000.0, None)));
    }
}
