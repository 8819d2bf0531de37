//! The 9-byte frame path: a network link's preamble screen, the frame
//! assembler, the frame and command decoders, and every module executing
//! what they let through, with virtual time passing between frames.
//! Properties: no panic; the screen decides within nine bytes, holds no
//! more and never changes its mind; every reply but the version string is
//! a whole frame with a good checksum; a decoded command encodes back to a
//! command that decodes the same.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tmclsim_firmware::Module;
use tmclsim_protocol::frame::checksum;
use tmclsim_protocol::preamble::{MAX_PREAMBLE, Preamble, Verdict};
use tmclsim_protocol::serial::FrameAssembler;
use tmclsim_protocol::{Command, Reply, Request};

const MODULES: [&str; 3] = ["tmcm-1141", "tmcm-351", "tmcm-1310"];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, data)) = data.split_first() else { return };
    let mut preamble = Preamble::new();
    let mut first = None;
    for (i, &b) in data.iter().enumerate() {
        let v = preamble.push(b);
        assert!(preamble.held().len() <= MAX_PREAMBLE);
        match (first, v) {
            (None, Verdict::Undecided) => assert!(i + 1 < MAX_PREAMBLE, "undecided after {} bytes", i + 1),
            (None, v) => first = Some(v),
            (Some(f), v) => assert_eq!(f, v, "the verdict changed"),
        }
    }
    let mut module = Module::built_in(MODULES[pick as usize % 3]).unwrap();
    let mut assembler = FrameAssembler::new(5_000_000);
    let mut now = 0u64;
    // Each chunk: a pause (0–2.55 ms), then 9 bytes; a zero checksum byte
    // is replaced by the right checksum so that most frames execute.
    for chunk in data.chunks(10) {
        now += chunk[0] as u64 * 10_000;
        let mut bytes = [0u8; 9];
        for (i, b) in chunk[1..].iter().enumerate() {
            bytes[i] = *b;
        }
        if chunk.len() == 10 && bytes[8] == 0 {
            bytes[8] = checksum(&bytes[..8]);
        }
        module.advance_to(now);
        let len = chunk.len() - 1;
        for &b in &bytes[..len] {
            let Some(frame) = assembler.push(b, now) else { continue };
            if let Ok(request) = Request::decode(&frame) {
                if let Ok(command) = Command::decode(request.instruction) {
                    assert_eq!(Command::decode(command.encode()), Ok(command));
                }
            }
            // 136 type 0 answers with the version string, which has no
            // checksum; every other reply has a good one.
            let version_string = frame[1] == 136 && frame[2] == 0;
            if let Some(reply) = module.handle_frame(&frame) {
                assert!(version_string || Reply::decode(&reply).is_some(), "reply with a bad checksum: {reply:?}");
            }
        }
    }
    // A second later the module still answers.
    module.advance_to(now + 1_000_000_000);
    let probe = Request::new(module.address(), tmclsim_protocol::Instruction::new(136, 1, 0, 0)).encode();
    if module.ascii_mode() {
        return;
    }
    let _ = module.handle_frame(&probe);
});
