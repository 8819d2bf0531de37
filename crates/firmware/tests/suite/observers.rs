//! Observers and links: an observer's reads come from the model and change
//! nothing (docs/behaviour.md rule 86); download mode belongs to the link
//! that entered it (rule 91); breakpoints are bounded by program memory.

use tmclsim_firmware::{Bus, IN_PROCESS, Module};
use tmclsim_protocol::mnemonic::parse_line;
use tmclsim_protocol::{Instruction, Reply, Request};

fn module() -> Module {
    Module::built_in("tmcm-1141").unwrap()
}

fn ins(line: &str) -> Instruction {
    parse_line(line).unwrap()
}

/// A frame from link `link` to address 1: the reply's status and value.
fn from(m: &mut Module, link: u64, line: &str) -> (u8, i32) {
    let r = Reply::decode(&m.handle_frame_from(link, &Request::new(1, ins(line)).encode()).unwrap()).unwrap();
    (r.status, r.value)
}

/// An observation: the reply's status and value.
fn observed(m: &Module, line: &str) -> (u8, i32) {
    let r = Reply::decode(&m.observe(ins(line)).expect("a read")).unwrap();
    (r.status, r.value)
}

#[test]
fn observations_answer_as_the_requests_would() {
    let mut m = module();
    for line in
        ["GAP 4, 0", "GAP 1, 0", "GAP 200, 0", "GAP 4, 5", "GGP 66, 0", "GGP 0, 2", "GGP 1, 7", "GIO 0, 0", "GIO 255, 0", "#135 1 0 0"]
    {
        let seen = observed(&m, line);
        assert_eq!(seen, from(&mut m, IN_PROCESS, line), "{line}");
    }
    assert_eq!(m.observe(ins("#136 0 0 0")), m.handle_frame(&Request::new(1, ins("#136 0 0 0")).encode()), "the version string");
    assert_eq!(m.observe(ins("#134 0 0 3")), m.handle_frame(&Request::new(1, ins("#134 0 0 3")).encode()), "a program word");
    assert_eq!(m.observe(ins("SAP 4, 0, 100")), None, "a write is no observation");
    assert_eq!(observed(&m, "#6 1 9 0").0, 4, "no such motor");
}

#[test]
fn observations_take_nothing_from_the_module() {
    let mut m = module();
    from(&mut m, IN_PROCESS, "SGP 133, 0, 99");
    let seen = observed(&m, "GGP 133, 0");
    assert_eq!(observed(&m, "GGP 133, 0"), seen, "GP 133 stays on its next number");
    assert_eq!(from(&mut m, IN_PROCESS, "GGP 133, 0"), seen, "the host gets that number");
    assert_ne!(from(&mut m, IN_PROCESS, "GGP 133, 0"), seen, "and the next read the one after");

    // In download mode an observation stores no word.
    from(&mut m, IN_PROCESS, "#132 0 0 0");
    for _ in 0..10 {
        observed(&m, "GAP 1, 0");
    }
    assert_eq!(from(&mut m, IN_PROCESS, "#135 0 0 0").1 & 0xFFFF, 0, "the download pointer did not move");
}

#[test]
fn a_download_belongs_to_the_link_that_entered_it() {
    let mut m = module();
    let (owner, other) = (7, 8);
    assert_eq!(from(&mut m, owner, "#132 0 0 0"), (100, 0));
    assert_eq!(from(&mut m, owner, "SAP 4, 0, 500").0, 101, "the owner's frame is a word");
    let speed = m.axis(0).params[4];
    assert_eq!(from(&mut m, other, "GAP 4, 0"), (100, speed), "another link reads in direct mode");
    assert_eq!(from(&mut m, other, "SAP 4, 0, 321"), (100, 321), "and writes too");
    for op in [129, 130, 131, 132, 133] {
        assert_eq!(from(&mut m, other, &format!("#{op} 0 0 0")).0, 6, "opcode {op} from another link");
    }
    assert_eq!(from(&mut m, other, "#135 0 0 0").1 & 0xFFFF, 1, "135 is answered: one word so far");
    assert_eq!(from(&mut m, owner, "MVP ABS, 0, 10").0, 101);
    assert_eq!(from(&mut m, owner, "#133 0 0 0"), (100, 0));
    assert_eq!(m.program().memory[..2], [ins("SAP 4, 0, 500"), ins("MVP ABS, 0, 10")]);
    assert_eq!(from(&mut m, other, "#132 0 0 0"), (100, 0), "after it ends, any link may download");
}

#[test]
fn a_download_whose_link_closed_passes_to_the_next_speaker() {
    let mut bus = Bus::single(module());
    let frame = |line: &str| Request::new(1, ins(line)).encode();
    let status = |bus: &mut Bus, link, line: &str| bus.handle_frame_from(link, &frame(line)).replies[0][2];
    assert_eq!(status(&mut bus, 1, "#132 0 0 0"), 100);
    assert_eq!(status(&mut bus, 2, "SAP 4, 0, 1"), 100, "not the owner");
    bus.link_closed(1);
    assert_eq!(status(&mut bus, 2, "SAP 4, 0, 1"), 101, "the owner is gone: link 2 downloads now");
    assert_eq!(status(&mut bus, 3, "#133 0 0 0"), 6, "and owns it");
}

#[test]
fn breakpoints_are_kept_once_each_inside_program_memory() {
    let mut m = module();
    let words = m.program().memory.len() as u16;
    let many: Vec<u16> = (0..400_000u32).map(|n| (n % 70_000) as u16).collect();
    m.set_breakpoints(&many);
    assert_eq!(m.program().breakpoints, (0..words).collect::<Vec<_>>());
    m.set_breakpoints(&[9, 3, 9, words, 3]);
    assert_eq!(m.program().breakpoints, [3, 9]);
}
