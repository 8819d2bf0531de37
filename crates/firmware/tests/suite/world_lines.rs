//! Many generated control lines (the abuse cases among them) through the
//! control socket's path, `Addressed::parse` then `Bus::apply_world`, on a
//! module whose motor runs: no panic, every refusal says why, the world
//! keeps to the rule set (docs/behaviour.md rule 84) whatever was
//! accepted, and the module keeps answering. The `control_line` fuzz target
//! checks the same on arbitrary text.

use crate::common;

use common::{MS, frame};
use tmclsim_firmware::world_command::Addressed;
use tmclsim_firmware::{Bus, Module};
use tmclsim_protocol::Reply;

const WORDS: &[&str] = &[
    "input",
    "analog",
    "supply",
    "temperature",
    "switch",
    "place",
    "travel",
    "load",
    "fault",
    "show",
    "left",
    "right",
    "home",
    "press",
    "release",
    "auto",
    "short-a",
    "open-b",
    "on",
    "off",
    "@1",
    "@2",
    "@x",
];

const NUMBERS: &[&str] = &[
    "0", "1", "2", "3", "4", "7", "99", "255", "256", "-1", "10", "-10", "0.5", "4095", "4096", "24", "130", "1e12", "1e13", "-1e300",
    "1e300", "nan", "NaN", "inf", "-inf", "infinity", "", "x",
];

/// The same "random" sequence every run (xorshift64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0 as usize
    }

    fn pick<'a>(&mut self, from: &[&'a str]) -> &'a str {
        from[self.next() % from.len()]
    }
}

/// Control lines in their shapes, `N` a number, `A` an axis, `S` a switch.
const SHAPES: &[&str] = &[
    "input N N",
    "analog N N",
    "supply N",
    "temperature N",
    "switch A S press",
    "switch A S auto",
    "place A S N",
    "place A S N N",
    "travel A N N",
    "load A N",
    "load A N N N",
    "fault A open-a on",
    "fault A open-a off",
    "show",
    "show A",
    "@1 travel A N N",
    "@1 supply N",
];

/// A line in one of the shapes (numbers good and bad), or loose words.
fn line(rng: &mut Rng) -> String {
    if rng.next().is_multiple_of(4) {
        let words: Vec<&str> =
            (0..1 + rng.next() % 5).map(|_| if rng.next().is_multiple_of(2) { rng.pick(WORDS) } else { rng.pick(NUMBERS) }).collect();
        return words.join(" ");
    }
    let shape = rng.pick(SHAPES);
    let words: Vec<&str> = shape
        .split(' ')
        .map(|w| match w {
            "N" => rng.pick(NUMBERS),
            "A" => rng.pick(&["0", "0", "0", "1"]),
            "S" => rng.pick(&["left", "right", "home"]),
            other => other,
        })
        .collect();
    words.join(" ")
}

fn answers(bus: &mut Bus, command: &str) -> Reply {
    let answer = bus.handle_frame(&frame(command));
    Reply::decode(answer.replies.first().unwrap_or_else(|| panic!("{command}: no reply"))).unwrap()
}

#[test]
fn generated_lines_never_break_the_module() {
    let abuse = ["travel 0 10 -10", "supply nan", "temperature inf", "load 0 -1", "load 0 nan", "input 99 1", "travel 0 nan nan"];
    let mut bus = Bus::single(Module::built_in("tmcm-1141").unwrap());
    assert_eq!(answers(&mut bus, "ROR 0, 500").status, 100);
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let (mut accepted, mut refused) = (0, 0);
    for n in 0..20_000 {
        let text = if n % 100 < abuse.len() { abuse[n % 100].to_string() } else { line(&mut rng) };
        match Addressed::parse(&text).and_then(|a| bus.apply_world(a.address, &a.command)).map_err(String::from) {
            Ok(_) => {
                assert!(!abuse.contains(&text.as_str()), "{text:?} was accepted");
                accepted += 1;
                let world = bus.module(0).world();
                assert_eq!(world.validate(), Ok(()), "after {text:?}");
            }
            Err(e) => {
                refused += 1;
                assert!(!e.is_empty() && !e.contains("panicked"), "{text:?}: {e:?}");
            }
        }
        bus.advance(MS);
        if n % 1000 == 0 {
            assert_eq!(answers(&mut bus, "GAP 2, 0").status, 100, "after {text:?}");
        }
    }
    // The generator reaches both outcomes often.
    assert!(accepted > 1000 && refused > 1000, "{accepted} accepted, {refused} refused");
    assert_eq!(answers(&mut bus, "ROR 0, 300").status, 100);
    bus.advance(100 * MS);
    assert_eq!(answers(&mut bus, "GAP 2, 0").value, 300);
    assert_eq!(bus.now_ns(), 20_100 * MS);
}
