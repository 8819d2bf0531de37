//! Peak memory of an assembly: at most 16 bytes of heap per byte of
//! source, the program included, whatever the source holds
//! (docs/robustness.md). A counting allocator measures the heap each
//! thread of this test binary allocates; the worst cases below, each up to
//! the limits (2 MiB per file, 4 MiB per assembly, 100 000 statements),
//! run on two threads.

#[path = "suite/common/mod.rs"]
mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use common::{Rng, tmcm_1141};
use tmclsim_asm::limits::{MAX_LINE_BYTES, MAX_SOURCE_BYTES, MAX_STATEMENTS};
use tmclsim_asm::{IncludeResolver, MemoryResolver, NoIncludes, assemble};

/// Bytes of heap per byte of source an assembly may use at its peak.
const BYTES_PER_SOURCE_BYTE: usize = 16;

struct Counting;

thread_local! {
    /// Bytes this thread holds, and the most it held since the last reset.
    static CURRENT: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

fn count(bytes: isize) {
    // `try_with`: a thread being torn down frees without counting.
    let _ = CURRENT.try_with(|c| {
        let now = c.get() + bytes;
        c.set(now);
        let _ = PEAK.try_with(|p| p.set(p.get().max(now)));
    });
}

// SAFETY: every call goes to the system allocator unchanged; the counters
// only watch (they are thread-locals without destructors: using them
// allocates nothing).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            count(layout.size() as isize);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            count(layout.size() as isize);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        count(-(layout.size() as isize));
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            // Counted as the difference: a large block grows in place or
            // is remapped, not copied beside the old one.
            count(new_size as isize - layout.size() as isize);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Lines from `line(i)` until the text would pass `bytes`.
fn lines_upto(bytes: usize, mut line: impl FnMut(usize) -> String) -> String {
    let mut text = String::with_capacity(bytes);
    for i in 0.. {
        let l = line(i);
        if text.len() + l.len() > bytes {
            break;
        }
        text.push_str(&l);
    }
    text
}

/// One statement `line(i)` for each of the most statements an assembly
/// takes.
fn statements(line: impl FnMut(usize) -> String) -> String {
    (0..MAX_STATEMENTS).map(line).collect()
}

/// A long line of `piece(i)` joined by `sep`, at most `bytes` long.
fn joined(bytes: usize, sep: &str, mut piece: impl FnMut(usize) -> String) -> String {
    let mut text = String::new();
    for i in 0.. {
        let p = piece(i);
        if text.len() + sep.len() + p.len() > bytes {
            break;
        }
        if i > 0 {
            text.push_str(sep);
        }
        text.push_str(&p);
    }
    text
}

/// A name of letters only, distinct for every `i`, as short as can be.
fn name(mut i: usize) -> String {
    let mut s = String::new();
    loop {
        s.push((b'a' + (i % 26) as u8) as char);
        i /= 26;
        if i == 0 {
            return s;
        }
    }
}

/// `1+1+…+1` with `n` ones.
fn sum(n: usize) -> String {
    vec!["1"; n].join("+")
}

struct Case {
    source: String,
    includes: MemoryResolver,
    profile: bool,
}

fn text(source: String) -> Case {
    Case { source, includes: MemoryResolver::new(), profile: false }
}

type Make = fn() -> Case;

const SIZE: usize = MAX_SOURCE_BYTES as usize;

/// The worst cases: each as large as the limits allow.
const CASES: &[(&str, Make)] = &[
    // 499 operators: the most one expression may have.
    ("instructions with long expressions", || text(lines_upto(SIZE, |_| format!("SAP 4, 0, {}\n", sum(500))))),
    ("constants with long expressions", || text(lines_upto(SIZE, |i| format!("C{i} = {}\n", sum(500))))),
    ("constants, each through the next", || text(lines_upto(SIZE, |i| format!("C{i} = {} + C{}\n", sum(499), i + 1)))),
    ("deep parentheses", || text(lines_upto(SIZE, |_| format!("X = {}1{}\n", "(".repeat(99), ")".repeat(99))))),
    ("too deep parentheses", || text(lines_upto(SIZE, |_| format!("X = {}\n", "(".repeat(MAX_LINE_BYTES - 10))))),
    ("unknown labels", || text(lines_upto(SIZE, |i| format!("JA Unknown{i}\n")))),
    ("unknown names in long expressions", || text(lines_upto(SIZE, |i| format!("C{i} = {}\n", joined(1000, "+", |k| name(k + 1000 * i)))))),
    ("unknown labels among many labels", || text(lines_upto(SIZE, |i| format!("{}: JA {}x\n", name(i), name(i / 2))))),
    ("unknown mnemonics", || text(lines_upto(SIZE, |i| format!("{} 1\n", name(i))))),
    ("labels", || text(lines_upto(SIZE, |i| format!("{}:\n", name(i))))),
    ("labels, as many as fit", || text(statements(|i| format!("{}:\n", name(i))))),
    ("many labels per line", || {
        text(lines_upto(SIZE, |i| format!("{}\n", joined(MAX_LINE_BYTES, "", |k| format!("{}:", name(k + 2000 * i))))))
    }),
    ("duplicate labels", || text(lines_upto(SIZE, |_| "Same:\n".into()))),
    ("constants", || text(lines_upto(SIZE, |i| format!("{}={i}\n", name(i))))),
    ("constants, as many as fit", || text(statements(|i| format!("{}=1\n", name(i))))),
    ("labels used by jumps", || text(statements(|i| format!("{}: JA {}\n", name(i), name(i / 2))))),
    ("errors", || text("bogus!\n".repeat(SIZE / 7))),
    ("shortest instructions", || text("GIV\n".repeat(MAX_STATEMENTS))),
    ("shortest instructions with labels", || text(statements(|i| format!("{}:GIV\n", name(i))))),
    ("long lines without commas", || text(lines_upto(SIZE, |_| format!("SAP {}\n", joined(MAX_LINE_BYTES - 10, " ", |_| "1".into()))))),
    ("comments", || text(lines_upto(SIZE, |_| "/* ä */ // ö\n".into()))),
    ("unclosed comment", || text(format!("/*{}", "x\n".repeat(SIZE / 2 - 2)))),
    ("lines past the limit", || text(lines_upto(SIZE, |_| format!("{}\n", "x".repeat(MAX_LINE_BYTES + 1))))),
    ("random printable text", || {
        let mut rng = Rng(0x5eed);
        text((0..SIZE).map(|_| if rng.below(96) == 95 { '\n' } else { (b' ' + rng.below(95) as u8) as char }).collect())
    }),
    ("random words", || {
        let words = ["MVP", "ABS", "SAP", "JA", "L1:", "X", "=", "1", ",", "+", "(", ")", "\n", "Loop:", "JC", "NZ", "Loop", "#db"];
        let mut rng = Rng(0x5eed);
        let mut s = String::new();
        while s.len() < SIZE - 8 {
            let word: &&str = rng.pick(&words);
            s.push_str(word);
            s.push(' ');
        }
        text(s)
    }),
    ("random bytes", || {
        let mut rng = Rng(0x5eed);
        text(String::from_utf8_lossy(&(0..SIZE).map(|_| rng.byte()).collect::<Vec<u8>>()).chars().take(SIZE / 3).collect())
    }),
    ("a valid program checked against a module", || {
        let body = "  SAP 4, 0, Speed\n  MVP ABS, 0, 1000 * 2 + Accel\n  WAIT POS, 0, 0\n  JC NZ, Loop\n";
        let source = format!("Speed = 1000\nAccel = Speed / 2 + 3\nLoop:\n{}", body.repeat(1020 / 4));
        Case { profile: true, ..text(source) }
    }),
    ("two included files of 2 MiB", || {
        let mut includes = MemoryResolver::new();
        for (file, first) in [("a.inc", 0), ("b.inc", 1 << 24)] {
            let labels =
                lines_upto(SIZE - 16, |i| format!("{}\n", joined(MAX_LINE_BYTES, "", |k| format!("{}:", name(first + k + 2000 * i)))));
            includes.files.insert(file.into(), labels);
        }
        Case { source: "#include a.inc\n#include b.inc\n".into(), includes, profile: false }
    }),
];

/// Peak heap of an assembly beyond what its thread held before (the source
/// is the caller's), the result included; whether it gave a program.
fn measure(case: &Case) -> (usize, bool) {
    let profile = tmcm_1141();
    let resolver: &dyn IncludeResolver = if case.includes.files.is_empty() { &NoIncludes } else { &case.includes };
    let before = CURRENT.with(Cell::get);
    PEAK.with(|p| p.set(before));
    let result = assemble(&case.source, "program.tmc", resolver, case.profile.then_some(&*profile));
    let peak = PEAK.with(Cell::get) - before;
    (peak as usize, result.is_ok())
}

#[test]
fn a_worst_case_source_peaks_below_16_bytes_per_byte() {
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                while let Some((what, make)) = CASES.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let case = make();
                    let bytes = case.source.len() + case.includes.files.values().map(String::len).sum::<usize>();
                    let (peak, program) = measure(&case);
                    let per_byte = peak as f64 / bytes as f64;
                    let outcome = if program { "program" } else { "errors" };
                    println!("{what:<42} {bytes:>8} bytes  peak {peak:>9}  {per_byte:4.1} B/byte  ({outcome})");
                    if peak > BYTES_PER_SOURCE_BYTE * bytes {
                        failures.lock().unwrap().push(format!("{what}: {per_byte:.1} bytes per source byte"));
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(failures.is_empty(), "more than {BYTES_PER_SOURCE_BYTE} bytes per source byte:\n{}", failures.join("\n"));
}
