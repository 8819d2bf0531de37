//! `tmclsim asm`, `disasm`, `run` and `upload` as a user runs them.

use crate::common;

use common::{text, tmclsim};

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tmclsim-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../asm/tests/programs").join(name)
}

#[test]
fn asm_disasm_asm_is_byte_identical() {
    let d = dir("asm");
    let bin = d.join("prog.bin");
    let o = tmclsim(&["asm", example("timer_interrupt_3_6_6.tmc").to_str().unwrap(), "-o", bin.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(d.join("prog.sym").exists());
    let src = d.join("back.tmc");
    let o = tmclsim(&["disasm", bin.to_str().unwrap(), "-o", src.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(std::fs::read_to_string(&src).unwrap().contains("Timer0Irq:"), "labels from the symbol file");
    let bin2 = d.join("back.bin");
    let o = tmclsim(&["asm", src.to_str().unwrap(), "-o", bin2.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(std::fs::read(&bin).unwrap(), std::fs::read(&bin2).unwrap());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn asm_reports_every_error_with_line_and_column() {
    let d = dir("errors");
    let src = d.join("bad.tmc");
    std::fs::write(&src, "Loop:\n  MVP ABS, 0, 1000\n  FOO 1\n  JA Lop\n  SAP 4, 0, 99999\n").unwrap();
    let o = tmclsim(&["asm", src.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let t = text(&o);
    assert!(t.contains("bad.tmc:3:3:"), "{t}");
    assert!(t.contains("bad.tmc:4:6:"), "{t}");
    assert!(t.contains("bad.tmc:5:"), "{t}");
    assert!(t.contains("3 error(s)"), "{t}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn run_prints_a_summary_and_writes_trace_and_plot() {
    let d = dir("run");
    let csv = d.join("t.csv");
    let png = d.join("p.png");
    let o = tmclsim(&[
        "run",
        example("djnz_3_7_43.tmc").to_str().unwrap(),
        "--for",
        "30s",
        "--trace",
        csv.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("ran 30.000 s of virtual time"), "{t}");
    let trace = std::fs::read_to_string(&csv).unwrap();
    let mut lines = trace.lines();
    assert_eq!(lines.next(), Some("time_s,pc,instruction,accumulator,x,failed_status,position_0,speed_0"));
    assert_eq!(lines.next().unwrap(), "0.000000,0,SGP 42 2 100,0,0,,0,0");
    assert!(trace.lines().any(|l| l.contains("DJNZ 42 1")));
    let image = std::fs::read(&png).unwrap();
    assert_eq!(&image[..8], &[0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1A, b'\n']);
    // IHDR: 1200 px wide, one 230 px panel per quantity (position,
    // velocity, load and current change in this run).
    let (w, h) = (u32::from_be_bytes(image[16..20].try_into().unwrap()), u32::from_be_bytes(image[20..24].try_into().unwrap()));
    assert_eq!((w, h), (1200, 4 * 230));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn run_plots_svg_with_labelled_axes_and_samples_at_a_fixed_step() {
    let d = dir("svg");
    let (svg, csv) = (d.join("p.svg"), d.join("s.csv"));
    let program = example("djnz_3_7_43.tmc");
    let o = tmclsim(&[
        "run",
        program.to_str().unwrap(),
        "--for",
        "20s",
        "--plot",
        svg.to_str().unwrap(),
        "--from",
        "5s",
        "--to",
        "15s",
        "--samples",
        csv.to_str().unwrap(),
        "--sample",
        "10ms",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let text_svg = std::fs::read_to_string(&svg).unwrap();
    assert!(text_svg.starts_with("<svg"), "an SVG, not a PNG with another name");
    for label in ["time (s)", "µsteps", "actual position (AP 1)", "target position (AP 0)", "actual speed (AP 3)", "axis 0: velocity"] {
        assert!(text_svg.contains(label), "{label} missing");
    }
    // The legend stands right of the curves, never on them: the actual
    // position's curve (blue, 2 px, many points) ends left of its name.
    let curve_right = text_svg
        .split("<polyline")
        .filter(|p| p.contains("stroke=\"#1F77B4\" stroke-width=\"2\""))
        .filter_map(|p| p.split("points=\"").nth(1)?.split('"').next())
        .filter(|points| points.split_whitespace().count() > 2)
        .flat_map(|points| points.split_whitespace().filter_map(|xy| xy.split(',').next()?.parse::<f64>().ok()).collect::<Vec<_>>())
        .fold(f64::MIN, f64::max);
    let name_x: f64 = text_svg
        .split("<text x=\"")
        .find(|p| p.split("</text>").next().and_then(|t| t.split('>').nth(1)).is_some_and(|t| t.trim() == "actual position (AP 1)"))
        .and_then(|p| p.split('"').next()?.parse().ok())
        .expect("the legend names the actual position");
    assert!(curve_right > 500.0 && name_x > curve_right, "legend at x {name_x}, curve up to x {curve_right}");
    // The time axis is the window: its ticks (centred under the axis) run
    // from 5 to 15 s.
    let ticks: Vec<f64> = text_svg
        .split("dy=\"0.76em\" text-anchor=\"middle\"")
        .skip(1)
        .filter_map(|part| part.lines().nth(1).and_then(|l| l.trim().parse().ok()))
        .collect();
    let (lo, hi) = ticks.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &t| (lo.min(t), hi.max(t)));
    assert_eq!((lo, hi), (5.0, 15.0), "{ticks:?}");
    let rows: Vec<String> = std::fs::read_to_string(&csv).unwrap().lines().map(String::from).collect();
    assert_eq!(rows[0], "time_s,position_0,target_0,speed_0,load_0,current_0,outputs");
    assert_eq!(rows.len(), 1 + 2001, "a row every 10 ms from 0 to 20 s");
    assert!(rows[1].starts_with("0.000000,0,0,0,"), "{}", rows[1]);
    assert!(rows[2].starts_with("0.010000,"), "{}", rows[2]);
    // Refusals: an unknown extension, an empty window.
    let o = tmclsim(&["run", program.to_str().unwrap(), "--plot", d.join("p.jpg").to_str().unwrap()]);
    assert!(!o.status.success() && text(&o).contains("p.jpg: the plot is written as .png or .svg"), "{}", text(&o));
    let o = tmclsim(&["run", program.to_str().unwrap(), "--for", "2s", "--plot", svg.to_str().unwrap(), "--from", "3s"]);
    assert!(!o.status.success() && text(&o).contains("the plot's window 3 s … 2 s is empty"), "{}", text(&o));
    std::fs::remove_dir_all(&d).unwrap();
}

/// Runs the manual's DJNZ loop with a breakpoint at Loop, typing `input`
/// into the debugger; what it printed.
fn debug_djnz_loop(input: &[u8]) -> String {
    debug(&example("djnz_3_7_43.tmc"), &["--break", "Loop"], input)
}

/// Runs a program for 60 s with more `run` options, typing `input` into
/// the debugger; what it printed.
fn debug(program: &Path, options: &[&str], input: &[u8]) -> String {
    use std::io::Write;
    let mut child = Command::new(env!("CARGO_BIN_EXE_tmclsim"))
        .args(["run", program.to_str().unwrap(), "--for", "60s"])
        .args(options)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.as_mut().unwrap().write_all(input).unwrap();
    String::from_utf8_lossy(&child.wait_with_output().unwrap().stdout).into_owned()
}

#[test]
fn continue_at_a_breakpoint_runs_to_the_next_hit() {
    let t = debug_djnz_loop(b"c\nc\nc\nq\n");
    // Each pass of the loop (a move and a 5 s WAIT) hits Loop once more.
    let times: Vec<f64> = t
        .split("\n[")
        .skip(1)
        .filter(|p| p.contains("djnz_3_7_43.tmc:6 (1, Loop)  MVP REL, 0, 51200 >"))
        .map(|p| p.split(" s]").next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(times.len(), 4, "{t}");
    assert!(times.windows(2).all(|w| w[1] - w[0] > 5.0), "every continue runs one pass of the loop: {times:?}");
    let hits = t.split("breakpoint at ").skip(1).filter(|p| p.split('\n').next().unwrap().ends_with("djnz_3_7_43.tmc:6 (1, Loop)"));
    assert_eq!(hits.count(), 4, "{t}");
}

#[test]
fn the_debugger_speaks_in_source_lines_and_names() {
    let djnz = example("djnz_3_7_43.tmc");
    // A breakpoint on line 8 (WAIT TICKS); line 5 holds only the label
    // Loop, so a breakpoint there stands on the MVP of line 6.
    let t = debug(&djnz, &["--break", "djnz_3_7_43.tmc:8", "--break", "djnz_3_7_43.tmc:5"], b"b\nq\n");
    assert!(t.contains("breakpoint at ") && t.contains("djnz_3_7_43.tmc:6 (1, Loop)  MVP REL, 0, 51200\n"), "{t}");
    assert!(t.contains("djnz_3_7_43.tmc:8 (3)  WAIT TICKS, 0, 500\n"), "{t}");
    // Watches report changes at every stop; prints name the parameter and
    // its unit; advance runs virtual time and stops at a breakpoint.
    let input = b"w var 42\nw AP actual position\np AP 4\np GP 0 2\np acc\nc\nd Loop\nadvance 2s\nq\n";
    let t = debug(&djnz, &["--break", "Loop"], input);
    assert!(t.contains("watch 1: user variable 42 = 100"), "{t}");
    assert!(t.contains("watch 2: AP 1 (Actual position) motor 0 = 0 µsteps"), "{t}");
    assert!(t.contains("AP 4 (Maximum positioning speed) motor 0 = "), "{t}");
    assert!(t.contains("GP 0 (") && t.contains(") bank 2 = 0"), "{t}");
    assert!(t.contains("> accumulator = 0"), "{t}");
    assert!(t.contains("watch 1: user variable 42 100 → 99"), "{t}");
    assert!(t.contains("watch 2: AP 1 (Actual position) motor 0 0 µsteps → 51200 µsteps"), "{t}");
    let stops: Vec<f64> = t.split("\n[").skip(1).map(|p| p.split(" s]").next().unwrap().parse().unwrap()).collect();
    let (&last, rest) = stops.split_last().unwrap();
    assert!((last - rest.last().unwrap() - 2.0).abs() < 0.0015, "advance 2s: {stops:?}\n{t}");
    // Nonsense gets an answer, not a step.
    let t = debug(&djnz, &["--break", "Loop"], b"s -1\ns 0\ns x\nstp\np AP actul position\nb Lop\nb 99\nu 3\nh\nq\n");
    for answer in [
        "step takes a count of 1 or more instructions, not '-1'",
        "step takes a count of 1 or more instructions, not '0'",
        "step takes a count of 1 or more instructions, not 'x'",
        "unknown command 'stp' (did you mean 'step'?)",
        "no axis parameter 'actul position' (did you mean 'Actual position'?)",
        "'Lop' is neither a label of the program, an address nor FILE:LINE (did you mean 'Loop'?)",
        // Five instructions and the STOP appended after DJNZ (rule 93).
        "address 99 is outside the program (0…5)",
        "no watch 3",
        "a[dvance] TIME",
    ] {
        assert!(t.contains(answer), "{answer}\n{t}");
    }
    assert_eq!(t.matches("djnz_3_7_43.tmc:6 (1, Loop)  MVP REL, 0, 51200 >").count(), 10, "nothing moved: {t}");
    // next runs a whole subroutine: CALL at line 7, then line 8.
    let call = example("call_3_7_44.tmc");
    let t = debug(&call, &["--break", "call_3_7_44.tmc:7"], b"n\np stack\nq\n");
    assert!(t.contains("call_3_7_44.tmc:7 (3)  CALL LT, RunLeft >"), "{t}");
    assert!(t.contains("call_3_7_44.tmc:8 (4)  CALL ZE, MotorStop > stack = []"), "{t}");
    // A line without instructions at the end of the file is refused.
    let o = tmclsim(&["run", djnz.to_str().unwrap(), "--break", "djnz_3_7_43.tmc:40"]);
    assert!(!o.status.success() && text(&o).contains("no instruction at or after line 40"), "{}", text(&o));
}

#[test]
fn asm_list_shows_the_source_beside_the_bytes() {
    let o = tmclsim(&["asm", "--list", example("djnz_3_7_43.tmc").to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("Loop:\n    1  04 01 00 00 00 C8 00      6  MVP REL, 0, 51200\n"), "{t}");
    assert!(t.contains("    4  31 2A 00 00 00 00 01      9  DJNZ 42, Loop\n"), "{t}");
    // The STOP appended after DJNZ (docs/behaviour.md rule 93): no line.
    assert!(t.ends_with("    5  1C 00 00 00 00 00 00         STOP  (appended: the program does not end in STOP)\n"), "{t}");
}

#[test]
fn run_with_breakpoint_and_scripted_debugger() {
    let t = debug_djnz_loop(b"i\ns\ns\ni\nq\n");
    assert!(t.contains("breakpoint at ") && t.contains("djnz_3_7_43.tmc:6 (1, Loop)\n"), "{t}");
    assert!(t.contains("djnz_3_7_43.tmc:7 (2)  WAIT POS, 0, 0 >"), "{t}");
    assert!(t.contains("user variables 42=100"), "{t}");
}

fn serve(d: &Path) -> (Child, String, PathBuf) {
    let pty = d.join("pty");
    let (child, tcp) = common::serve(&["--pty", pty.to_str().unwrap()], Stdio::inherit());
    (child, tcp, pty)
}

#[test]
#[cfg_attr(windows, ignore = "a pty is a Unix device: Windows refuses --pty")]
fn upload_over_tcp_and_pty_verifies_and_runs() {
    let d = dir("upload");
    let (mut server, tcp, pty) = serve(&d);
    let prog = example("djnz_3_7_43.tmc");
    let o = tmclsim(&["upload", prog.to_str().unwrap(), "--tcp", &tcp, "--run"]);
    assert!(o.status.success(), "{}", text(&o));
    // Five instructions, the last DJNZ, and the STOP the assembler appends
    // (docs/behaviour.md rule 93).
    assert!(text(&o).contains("uploaded and verified 6 instructions (the last one the STOP appended"), "{}", text(&o));
    let o = tmclsim(&["send", "--tcp", &tcp, "GGP", "128,", "0"]);
    assert!(text(&o).contains("value 1"), "running: {}", text(&o));
    // Over the pty, a binary this time, with autostart.
    let bin = d.join("p.bin");
    assert!(tmclsim(&["asm", example("call_3_7_44.tmc").to_str().unwrap(), "-o", bin.to_str().unwrap()]).status.success());
    let o = tmclsim(&["upload", bin.to_str().unwrap(), "--port", pty.to_str().unwrap(), "--autostart"]);
    assert!(o.status.success(), "{}", text(&o));
    let o = tmclsim(&["send", "--port", pty.to_str().unwrap(), "GGP", "77,", "0"]);
    assert!(text(&o).contains("value 1"), "{}", text(&o));
    let o = tmclsim(&["send", "--port", pty.to_str().unwrap(), "#134", "0", "0", "0"]);
    assert!(text(&o).contains("memory:  GIO 0, 1"), "{}", text(&o));
    server.kill().unwrap();
    server.wait().unwrap();
    std::fs::remove_dir_all(&d).unwrap();
}

/// What `tmclsim upload` sends over a real link and what the module
/// answers, recorded by `tmclsim trace record` between them
/// (docs/behaviour.md rules 93, 94, 15, 17): 128, 132, the program's
/// words, the STOP appended after its last instruction, the NOP TMCL-IDE
/// sends after the last word, 133, then 134 for every word; every word in
/// download mode, the NOP too, answered with status 101; 135 then points
/// past the NOP.
#[test]
#[cfg_attr(windows, ignore = "a clean stop needs Ctrl-C in the child, which Wine does not deliver to another process")]
fn upload_sends_the_words_the_appended_stop_and_the_nop_as_tmcl_ide_does() {
    use tmclsim_host::trace::Dir;
    use tmclsim_protocol::{Instruction, Request, opcode};
    let d = dir("upload-as-tmcl-ide");
    let source = d.join("shuttle.tmc");
    std::fs::write(&source, "Loop: MVP ABS, 0, 1000\n  WAIT POS, 0, 0\n  MVP ABS, 0, 0\n  WAIT POS, 0, 0\n  JA Loop\n").unwrap();
    let (mut server, tcp) = common::serve(&[], Stdio::inherit());
    let trace = d.join("upload.jsonl");
    let mut c = Command::new(env!("CARGO_BIN_EXE_tmclsim"));
    c.args(["trace", "record", "--listen", "127.0.0.1:0", "--tcp", &tcp, "--out", trace.to_str().unwrap()]);
    c.stdout(Stdio::piped()).stderr(Stdio::piped());
    let mut rec = common::Server::spawn(c);
    let listen = rec.printed("listen");
    let o = tmclsim(&["upload", source.to_str().unwrap(), "--tcp", &listen]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("uploaded and verified 6 instructions"), "{}", text(&o));
    // 135 type 0 on the module's own link: stopped (0 in the high byte),
    // not waiting, the download pointer after the NOP: address 7.
    let mut s = std::net::TcpStream::connect(&tcp).unwrap();
    s.set_read_timeout(Some(std::time::Duration::from_secs(5))).unwrap();
    let status = common::ask(&mut s, "#135 0 0 0").expect("a reply to 135");
    assert_eq!((status.status, status.value), (100, 7));
    common::interrupt(&mut rec.child);
    assert_eq!(rec.exit_code_within(std::time::Duration::from_secs(10)), Some(0));
    server.kill().unwrap();
    server.wait().unwrap();

    let entries = tmclsim_host::trace::read(std::fs::File::open(&trace).unwrap(), "upload.jsonl").unwrap();
    let sent: Vec<[u8; 9]> = entries.iter().filter(|e| e.dir == Dir::Host).map(|e| e.frame).collect();
    let answered: Vec<[u8; 9]> = entries.iter().filter(|e| e.dir == Dir::Module).map(|e| e.frame).collect();
    assert_eq!(sent.len(), answered.len(), "a reply to every request");
    let opcodes: Vec<u8> = sent.iter().map(|f| f[1]).collect();
    assert_eq!(opcodes, [128, 132, 4, 27, 4, 27, 22, 28, 0, 133, 134, 134, 134, 134, 134, 134]);
    // The last two words exactly: the STOP (1C …) and the NOP, each
    // followed by its checksum; the address byte 1 leads both.
    let frame = |ins| Request::new(1, ins).encode();
    assert_eq!(sent[7], frame(Instruction::new(opcode::STOP, 0, 0, 0)));
    assert_eq!(sent[7], [0x01, 0x1C, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1D]);
    assert_eq!(sent[8], [0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01]);
    // In download mode every word, the NOP too, is answered with status
    // 101, its own opcode and value; 132 and 133 with 100.
    for (request, reply) in sent[2..=8].iter().zip(&answered[2..=8]) {
        assert_eq!((reply[2], reply[3], &reply[4..8]), (101, request[1], &request[4..8]), "{request:02X?} → {reply:02X?}");
    }
    assert_eq!((answered[1][2], answered[9][2]), (100, 100));
    // 134 reads the STOP back at address 5.
    assert_eq!(answered[15][1..8], [0x1C, 0, 0, 0, 0, 0, 0]);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_long_run_is_quiet_when_stderr_is_no_terminal() {
    let d = dir("quiet");
    let source = d.join("poll.tmc");
    std::fs::write(&source, "Loop:\n  MVP ABS, 0, 512000\nWait:\n  GAP 8, 0\n  JC ZE, Wait\n  MVP ABS, 0, 0\n  JA Loop\n").unwrap();
    let started = std::time::Instant::now();
    // Twenty minutes of a busy loop: over a second even in a release build.
    let o = tmclsim(&["run", source.to_str().unwrap(), "--for", "20m"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(started.elapsed().as_secs_f64() > 1.0, "long enough for a bar on a terminal");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.is_empty(), "no progress bar in a pipe: {stderr}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_waiting_wait_is_where_the_debugger_stands_and_console_names_are_taken() {
    let djnz = example("djnz_3_7_43.tmc");
    // The step onto the WAIT starts it: the counter holds the WAIT's own
    // address while it waits (docs/behaviour.md rule 35).
    let t = debug(&djnz, &["--break", "djnz_3_7_43.tmc:8"], b"s\np pc\np AP actual_position\np GP tmcl_tick_timer\nq\n");
    assert!(t.contains("djnz_3_7_43.tmc:8 (3)  WAIT TICKS, 0, 500 (waiting) >"), "{t}");
    assert!(t.contains("> program counter = 3"), "{t}");
    assert!(t.contains("AP 1 (Actual position) motor 0 = "), "{t}");
    assert!(t.contains("GP 132 ("), "{t}");
}

#[test]
fn run_to_the_end_of_the_clock_s_range_ends() {
    // A WAIT begun near the end of the 64-bit clock would end past it: it
    // waits until the end instead of looping (docs/behaviour.md rule 84).
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("wait.tmc");
    std::fs::write(&source, "Loop:\n  WAIT TICKS, 0, 2147483647\n  JA Loop\n").unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_tmclsim"))
        .args(["run", source.to_str().unwrap(), "--for", "18446000000"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let status = common::exit_within(&mut child, std::time::Duration::from_secs(30));
    if status.is_none() {
        let _ = child.kill();
        let _ = child.wait();
    }
    assert!(status.is_some_and(|s| s.success()), "tmclsim run --for 18446000000 did not end within 30 s: {status:?}");
}
