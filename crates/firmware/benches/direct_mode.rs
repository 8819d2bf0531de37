//! Direct-mode commands through `Module::handle_frame`, in-process, and
//! programs running in virtual time.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use tmclsim_firmware::{Bus, Module};
use tmclsim_protocol::Request;
use tmclsim_protocol::mnemonic::parse_line;

fn frames(lines: &[&str]) -> Vec<[u8; 9]> {
    lines.iter().map(|l| Request::new(1, parse_line(l).unwrap()).encode()).collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("direct_mode");
    g.throughput(Throughput::Elements(1));
    for (name, lines) in [
        ("GAP actual position", &["GAP 1, 0"][..]),
        ("SAP max speed", &["SAP 4, 0, 1000"][..]),
        ("mix GAP/SAP/GGP/GIO/MVP", &["GAP 1, 0", "SAP 4, 0, 1500", "GGP 66, 0", "GIO 0, 0", "MVP ABS, 0, 5000", "GAP 8, 0"][..]),
    ] {
        let fs = frames(lines);
        for module in ["tmcm-1141", "tmcm-1260"] {
            let mut m = Module::built_in(module).unwrap();
            let mut i = 0;
            g.bench_function(format!("{name}, {module}"), |b| {
                b.iter(|| {
                    let f = &fs[i % fs.len()];
                    i += 1;
                    black_box(m.handle_frame(black_box(f)))
                });
            });
        }
    }
    g.finish();
    // Programs: 1000 instructions (25 ms of virtual time at 25 µs each)
    // per iteration. The polling loop asks for AP 8 (position reached)
    // while the motor moves, so each of its GAPs sees the world of its own
    // moment; the compute loop never looks at the world.
    let mut g = c.benchmark_group("program");
    g.throughput(Throughput::Elements(1000));
    for (name, lines) in [
        ("compute loop (CALC/COMP/JC)", &["CALC ADD, 1", "COMP 2147483647", "JC LT, 0"][..]),
        (
            "polling motion loop (GAP 8/JC)",
            &["MVP ABS, 0, 512000", "GAP 8, 0", "JC ZE, 1", "MVP ABS, 0, 0", "GAP 8, 0", "JC ZE, 4", "JA 0"][..],
        ),
    ] {
        let words: Vec<_> = lines.iter().map(|l| parse_line(l).unwrap()).collect();
        let mut m = Module::built_in("tmcm-1141").unwrap();
        m.load_program(&words).unwrap();
        m.start_program();
        let mut bus = Bus::single(m);
        g.bench_function(name, |b| b.iter(|| bus.advance(black_box(25_000_000))));
    }
    g.finish();
    // The TMC429 family's, the sixPoint family's and the TMC4361A's motion
    // controllers, the TMC4361A with its S-shaped ramp (AP 14 = 1; the four
    // bows at 51200 pps³, a second from no acceleration to the default
    // AMAX: with bows of 0 the S-shaped ramp is the trapezoid).
    let s_shaped = ["SAP 14, 0, 1", "SAP 22, 0, 51200", "SAP 23, 0, 51200", "SAP 24, 0, 51200", "SAP 25, 0, 51200"];
    for (module, name, rotate, setup) in [
        ("tmcm-1141", "tmcm-1141", "ROR 0, 1000", &[][..]),
        ("tmcm-1260", "tmcm-1260", "ROR 0, 50000", &[][..]),
        ("tmcm-1316", "tmcm-1316 S-shaped", "ROR 0, 50000", &s_shaped[..]),
    ] {
        let set_up = || {
            let mut bus = Bus::single(Module::built_in(module).unwrap());
            for (line, f) in setup.iter().zip(frames(setup)) {
                let answer = bus.handle_frame(&f);
                assert!(answer.replies.first().is_some_and(|r| r[2] == 100), "{module}: `{line}` failed");
            }
            bus
        };
        c.bench_function(&format!("advance 1 ms while moving, {name}"), |b| {
            let mut bus = set_up();
            bus.handle_frame(&frames(&[rotate])[0]);
            b.iter(|| bus.advance(black_box(1_000_000)));
        });
        c.bench_function(&format!("advance 1 ms during a move, {name}"), |b| {
            let mut bus = set_up();
            let (out, back, reached) = (frames(&["MVP ABS, 0, 1000000"])[0], frames(&["MVP ABS, 0, 0"])[0], frames(&["GAP 8, 0"])[0]);
            bus.handle_frame(&out);
            let mut outward = true;
            b.iter(|| {
                bus.advance(black_box(1_000_000));
                if bus.handle_frame(&reached).replies.first().is_some_and(|r| r[7] == 1) {
                    outward = !outward;
                    bus.handle_frame(if outward { &out } else { &back });
                }
            });
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
