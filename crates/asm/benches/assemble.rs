//! Assembling a megabyte of source: a long valid program, unknown names
//! among many labels (every one a "did you mean" search), random printable
//! text. docs/robustness.md: any text of 1 MB within 2 s.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use tmclsim_asm::{NoIncludes, assemble};

const SIZE: usize = 1 << 20;

/// Lines from `line(i)` up to `SIZE` bytes.
fn text(mut line: impl FnMut(usize) -> String) -> String {
    let mut out = String::with_capacity(SIZE);
    for i in 0.. {
        let l = line(i);
        if out.len() + l.len() > SIZE {
            return out;
        }
        out.push_str(&l);
    }
    out
}

/// A random-looking name of 6 to 9 letters.
fn name(i: usize) -> String {
    let mut x = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let len = 6 + (x % 4) as usize;
    (0..len)
        .map(|_| {
            x = x.rotate_left(5).wrapping_mul(0x2545_F491_4F6C_DD1D);
            (b'a' + (x >> 59) as u8 % 26) as char
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let program = {
        let head = "Speed = 1000\nAccel = Speed / 2 + 3\n".to_string();
        let mut i = 0;
        head + &text(|_| {
            i += 1;
            format!("L{i}:\n  SAP 4, 0, Speed\n  MVP ABS, 0, {i} * 100 + Accel\n  WAIT POS, 0, 0\n  JC NZ, L{}\n", i / 2 + 1)
        })
    };
    // Every other line jumps to a name that is not defined but close to a
    // label (one letter more).
    let unknown = text(|i| if i % 2 == 0 { format!("{}: STOP\n", name(i)) } else { format!("JA {}x\n", name(i - 1)) });
    let mut x = 0x5eedu64;
    let random: String = (0..SIZE)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            match (x % 96) as u8 {
                95 => '\n',
                c => (b' ' + c) as char,
            }
        })
        .collect();
    assert!(assemble(&program, "valid.tmc", &NoIncludes, None).is_ok());
    let mut g = c.benchmark_group("assemble 1 MB");
    g.sample_size(10);
    for (what, source) in [("valid program", &program), ("unknown names among labels", &unknown), ("random printable text", &random)] {
        g.throughput(Throughput::Bytes(source.len() as u64));
        g.bench_function(what, |b| b.iter(|| black_box(assemble(black_box(source), "bench.tmc", &NoIncludes, None))));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
