//! Traces of TMCL sessions: every frame between a host and a module with
//! its time, as JSON Lines, one frame per line (docs/host-software.md,
//! "The trace format"):
//!
//! ```text
//! {"t": 0.012300, "dir": "host", "frame": "01 06 01 00 00 00 00 00 08"}
//! {"t": 0.013100, "dir": "module", "frame": "02 01 64 06 00 00 00 00 6D"}
//! ```
//!
//! `tmclsim trace record` writes them, `tmclsim trace check` replays them
//! on a virtual module, and any other tool may write them. Also here: which
//! replies depend on the physics of the module's surroundings, and how a
//! recorded reply is compared with the virtual module's.

use crate::client::hex;
use std::io::{BufRead, BufReader, Read, Write};
use tmclsim_protocol::{FRAME_LEN, Instruction, Reply, opcode};

/// The longest line of a trace, without its line end.
pub const MAX_LINE_BYTES: usize = 4096;
/// The most frames one trace holds (half a million exchanges).
pub const MAX_ENTRIES: usize = 1_000_000;
/// The largest trace file.
pub const MAX_TRACE_BYTES: u64 = 256 << 20;
/// The latest time in a trace: 10⁷ s (about 115 days).
pub const MAX_T_SECONDS: f64 = 1e7;

/// Who sent a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dir {
    /// The host: a request.
    Host,
    /// The module: a reply, or a frame of its own (a 138 event).
    Module,
}

impl Dir {
    /// The word a trace file uses: `host` or `module`.
    pub fn as_str(self) -> &'static str {
        match self {
            Dir::Host => "host",
            Dir::Module => "module",
        }
    }
}

/// One frame of a trace, with the line it stands on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Entry {
    /// 1-based line of the trace file.
    pub line: usize,
    /// Nanoseconds since the start of the recording.
    pub t_ns: u64,
    /// Who sent the frame.
    pub dir: Dir,
    /// The frame's nine bytes.
    pub frame: [u8; FRAME_LEN],
}

impl Entry {
    /// A module frame that is a 138 event (status 128, instruction 138),
    /// not the reply to a request.
    pub fn is_event(&self) -> bool {
        self.dir == Dir::Module && is_event(&self.frame)
    }
}

/// A frame a module sends on its own: the 138 event (status 128,
/// instruction 138, a valid checksum).
pub fn is_event(frame: &[u8; FRAME_LEN]) -> bool {
    Reply::decode(frame).is_some_and(|r| r.status == 128 && r.opcode == opcode::TARGET_REACHED_EVENT)
}

/// `t` as written: seconds with six decimals.
pub fn seconds(t_ns: u64) -> String {
    format!("{}.{:06}", t_ns / 1_000_000_000, (t_ns % 1_000_000_000) / 1000)
}

/// One line of a trace (without its line end).
pub fn format_line(t_ns: u64, dir: Dir, frame: &[u8; FRAME_LEN]) -> String {
    format!("{{\"t\": {}, \"dir\": \"{}\", \"frame\": \"{}\"}}", seconds(t_ns), dir.as_str(), hex(frame))
}

/// What is wrong with a line of a trace.
#[derive(Clone, Debug, PartialEq)]
pub enum LineError {
    /// The line is no JSON.
    NotJson {
        /// The parser's message, without its position.
        message: String,
        /// Where the parser stopped: 1-based, in characters of the text.
        column: usize,
    },
    /// The line is JSON but no object.
    NotObject,
    /// No `t`.
    NoTime,
    /// `t` is no number (the value, as JSON).
    TimeNotNumber(String),
    /// `t` is outside 0…[`MAX_T_SECONDS`].
    TimeOutside(f64),
    /// No `dir`.
    NoDir,
    /// `dir` is neither `host` nor `module` (the value, as JSON, cut).
    BadDir(String),
    /// No `frame`.
    NoFrame,
    /// `frame` is no string (the value, as JSON, cut).
    FrameNotString(String),
    /// A piece of `frame` is no byte in hex (the piece, cut).
    NotHexByte(String),
    /// `frame` has this many bytes, not 9.
    FrameLength(usize),
}

impl std::fmt::Display for LineError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LineError::NotJson { message, .. } => write!(f, "not a JSON object: {message}"),
            LineError::NotObject => {
                write!(f, "not a JSON object: write {{\"t\": 0.0123, \"dir\": \"host\", \"frame\": \"01 06 01 00 00 00 00 00 08\"}}")
            }
            LineError::NoTime => write!(f, "no \"t\" (seconds since the start of the recording)"),
            LineError::TimeNotNumber(t) => write!(f, "\"t\" is {t}, not a number of seconds"),
            LineError::TimeOutside(t) => write!(f, "\"t\" is {t}: seconds since the start, 0…{MAX_T_SECONDS:.0}"),
            LineError::NoDir => write!(f, "no \"dir\" (\"host\" or \"module\")"),
            LineError::BadDir(d) => write!(f, "\"dir\" is {d}; write \"host\" or \"module\""),
            LineError::NoFrame => write!(f, "no \"frame\" (9 bytes in hex)"),
            LineError::FrameNotString(v) => write!(f, "\"frame\" is {v}, not a string of hex bytes"),
            LineError::NotHexByte(p) => {
                write!(f, "\"frame\": '{p}' is not a byte in hex (write 9 bytes as \"01 06 01 00 00 00 00 00 08\")")
            }
            LineError::FrameLength(n) => write!(f, "\"frame\" has {n} bytes; a TMCL frame has 9"),
        }
    }
}

impl std::error::Error for LineError {}

impl From<LineError> for String {
    fn from(e: LineError) -> String {
        e.to_string()
    }
}

/// A frame as a trace writes it: nine bytes in hex, separated by spaces
/// (upper or lower case; one run of 18 digits is taken too).
pub fn parse_frame(text: &str) -> Result<[u8; FRAME_LEN], LineError> {
    let words: Vec<&str> = text.split_whitespace().collect();
    let pairs: Vec<&str> = match words.as_slice() {
        [one] if one.len() > 2 && one.len().is_multiple_of(2) && one.is_ascii() => {
            (0..one.len()).step_by(2).map(|i| &one[i..i + 2]).collect()
        }
        _ => words,
    };
    let mut bytes = Vec::with_capacity(FRAME_LEN);
    for p in &pairs {
        if p.len() != 2 || !p.chars().all(|c| c.is_ascii_hexdigit()) {
            return Err(LineError::NotHexByte(cut(p)));
        }
        bytes.push(u8::from_str_radix(p, 16).map_err(|_| LineError::NotHexByte(cut(p)))?);
    }
    bytes.try_into().map_err(|b: Vec<u8>| LineError::FrameLength(b.len()))
}

/// At most 20 characters of a piece of text, for messages.
fn cut(text: &str) -> String {
    let mut out: String = text.chars().take(20).collect();
    if out.len() < text.len() {
        out.push('…');
    }
    out
}

/// One line of a trace: its time in nanoseconds, who sent the frame, the
/// frame. Keys other than `t`, `dir` and `frame` are ignored.
pub fn parse_line(text: &str) -> Result<(u64, Dir, [u8; FRAME_LEN]), LineError> {
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| {
        // serde_json ends its message with " at line L column C"; a trace
        // line is one line, so the column alone says where. Its column
        // counts bytes: it becomes characters here.
        let message = e.to_string();
        let message = message.strip_suffix(&format!(" at line {} column {}", e.line(), e.column())).unwrap_or(&message).to_string();
        let before = e.column().saturating_sub(1).min(text.len());
        let column = text.get(..before).map_or(e.column(), |b| b.chars().count() + 1);
        LineError::NotJson { message, column }
    })?;
    let Some(object) = value.as_object() else {
        return Err(LineError::NotObject);
    };
    let t = match object.get("t") {
        None => return Err(LineError::NoTime),
        Some(t) => t.as_f64().ok_or_else(|| LineError::TimeNotNumber(t.to_string()))?,
    };
    if !(0.0..=MAX_T_SECONDS).contains(&t) {
        return Err(LineError::TimeOutside(t));
    }
    let dir = match object.get("dir").map(|d| (d, d.as_str())) {
        None => return Err(LineError::NoDir),
        Some((_, Some("host"))) => Dir::Host,
        Some((_, Some("module"))) => Dir::Module,
        Some((d, _)) => return Err(LineError::BadDir(cut(&d.to_string()))),
    };
    let frame = match object.get("frame") {
        None => return Err(LineError::NoFrame),
        Some(f) => parse_frame(f.as_str().ok_or_else(|| LineError::FrameNotString(cut(&f.to_string())))?)?,
    };
    Ok(((t * 1e9).round() as u64, dir, frame))
}

/// Reads a whole trace; `name` (the file) starts each message, with the
/// line number where a line is at fault. Times must not go back.
pub fn read(input: impl Read, name: &str) -> Result<Vec<Entry>, String> {
    read_within(input, name, MAX_TRACE_BYTES)
}

fn read_within(input: impl Read, name: &str, max_bytes: u64) -> Result<Vec<Entry>, String> {
    let mut reader = BufReader::new(input.take(max_bytes + 1));
    let mut entries = Vec::new();
    let mut buf = Vec::new();
    let mut total = 0u64;
    let mut last_t = 0u64;
    for number in 1.. {
        buf.clear();
        let got = (&mut reader).take(MAX_LINE_BYTES as u64 + 1).read_until(b'\n', &mut buf).map_err(|e| format!("{name}: {e}"))?;
        if got == 0 {
            break;
        }
        total += got as u64;
        if total > max_bytes {
            return Err(format!("{name}: larger than {}, the limit for a trace", size_text(max_bytes)));
        }
        let ended = buf.last() == Some(&b'\n');
        if !ended && buf.len() > MAX_LINE_BYTES {
            return Err(format!("{name}:{number}: line longer than {MAX_LINE_BYTES} bytes"));
        }
        let text = std::str::from_utf8(&buf).map_err(|_| format!("{name}:{number}: not UTF-8 text"))?;
        let indent = text.len() - text.trim_start().len();
        let indent_chars = text[..indent].chars().count();
        let text = text.trim();
        if text.is_empty() {
            continue;
        }
        if entries.len() == MAX_ENTRIES {
            return Err(format!("{name}:{number}: more than {MAX_ENTRIES} frames, the limit of a trace"));
        }
        let (t_ns, dir, frame) = parse_line(text).map_err(|e| match e {
            LineError::NotJson { column, .. } => format!("{name}:{number}:{}: {e}", indent_chars + column),
            e => format!("{name}:{number}: {e}"),
        })?;
        if t_ns < last_t {
            return Err(format!("{name}:{number}: \"t\" goes back in time ({} after {})", seconds(t_ns), seconds(last_t)));
        }
        last_t = t_ns;
        entries.push(Entry { line: number, t_ns, dir, frame });
    }
    Ok(entries)
}

/// "256 MiB", "4 KiB", "100 bytes".
fn size_text(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 20 && b.is_multiple_of(1 << 20) => format!("{} MiB", b >> 20),
        b if b >= 1 << 10 && b.is_multiple_of(1 << 10) => format!("{} KiB", b >> 10),
        b => format!("{b} bytes"),
    }
}

/// Writes a trace line by line; each line is flushed as it is written, so
/// a recording that is killed keeps every frame but the one being written.
pub struct Writer<W: Write> {
    out: W,
    last_ns: u64,
    entries: usize,
}

impl<W: Write> Writer<W> {
    /// A writer of a new trace whose time starts at 0.
    pub fn new(out: W) -> Self {
        Writer { out, last_ns: 0, entries: 0 }
    }

    /// Writes one frame; `Ok(false)` when the trace holds [`MAX_ENTRIES`]
    /// frames already (nothing is written). A time before the last one is
    /// written as the last one, so times never go back.
    pub fn write(&mut self, t_ns: u64, dir: Dir, frame: &[u8; FRAME_LEN]) -> std::io::Result<bool> {
        if self.entries >= MAX_ENTRIES {
            return Ok(false);
        }
        self.last_ns = self.last_ns.max(t_ns);
        writeln!(self.out, "{}", format_line(self.last_ns, dir, frame))?;
        self.out.flush()?;
        self.entries += 1;
        Ok(true)
    }

    /// Frames written.
    pub fn entries(&self) -> usize {
        self.entries
    }
}

/// How a recorded reply is compared with the virtual module's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Byte for byte (a read: with the virtual module's reply at either end
    /// of the read's time window).
    Exact,
    /// A value that moves with the motor (positions, speeds, the
    /// acceleration): it matches anywhere between the virtual module's
    /// values at the two ends of the read's time window.
    Motion,
    /// It depends on what the virtual module cannot know (the motor's load,
    /// the supply, what is wired to the inputs, the time since power-on):
    /// listed as not comparable, never counted as a match or a difference.
    NotComparable(&'static str),
}

/// How the reply to `ins` is compared.
pub fn kind(ins: Instruction) -> Kind {
    use Kind::*;
    match ins.opcode {
        opcode::GAP => match ins.kind {
            1 | 3 | 131 | 135 | 209 | 216 | 233 => Motion,
            206 => NotComparable("load value: follows the motor's load"),
            19 | 123 | 180 | 236 => NotComparable("motor current: follows the motor's load (coolStep, closed loop)"),
            230 | 237 => NotComparable("closed-loop value: follows the motor and its load"),
            207 | 208 => NotComparable("error flags: depend on the motor, its wiring and its load"),
            9..=11 => NotComparable("switch state: depends on the machine's switches"),
            196 | 197 => NotComparable("reference search result: depends on where the machine's switches are"),
            215 => NotComparable("resolver value: depends on the machine"),
            _ => Exact,
        },
        opcode::GGP if ins.motor == 0 => match ins.kind {
            132 => NotComparable("tick timer: counts from the module's power-on, not from the start of the trace"),
            133 => NotComparable("random number"),
            _ => Exact,
        },
        opcode::GIO => match ins.motor {
            0 => NotComparable("digital input: depends on what is wired to the module"),
            1 => NotComparable("analog input: depends on the supply and on what is wired to the module"),
            _ => Exact,
        },
        opcode::RFS if ins.kind == 2 => NotComparable("reference search status: depends on where the machine's switches are"),
        _ => Exact,
    }
}

/// Reads whose answer may change with time alone: their reply is compared
/// with the virtual module's at both ends of the read's time window.
pub fn windowed(ins: Instruction) -> bool {
    matches!(ins.opcode, opcode::GAP | opcode::GGP | opcode::GIO | opcode::APPLICATION_STATUS)
        || (ins.opcode == opcode::RFS && ins.kind == 2)
}

/// The outcome of comparing one recorded reply.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The replies agree.
    Match,
    /// A difference, with a note on what the virtual module's value could
    /// have been (empty when the replies speak for themselves).
    Differs(String),
    /// Both replies are there and succeeded, but the value is not
    /// comparable; the reason.
    NotComparable(&'static str),
}

/// Compares the recorded reply to `ins` with the virtual module's replies
/// at the start (`early`) and the end (`late`) of the read's time window
/// (the same reply twice for a request that is not a windowed read).
pub fn compare(
    ins: Instruction,
    recorded: Option<&[u8; FRAME_LEN]>,
    early: Option<&[u8; FRAME_LEN]>,
    late: Option<&[u8; FRAME_LEN]>,
) -> Verdict {
    let (recorded, early) = match (recorded, early) {
        (None, None) => return Verdict::Match,
        (Some(r), Some(v)) => (r, v),
        _ => return Verdict::Differs(String::new()),
    };
    let late = late.unwrap_or(early);
    let string_reply = ins.opcode == opcode::FIRMWARE_VERSION && ins.kind == 0;
    let decoded = (Reply::decode(recorded), Reply::decode(early), Reply::decode(late));
    let (Some(r), Some(e), Some(l)) = decoded else {
        return if recorded == early || recorded == late { Verdict::Match } else { Verdict::Differs(String::new()) };
    };
    if string_reply || ins.opcode == opcode::READ_MEMORY {
        return if recorded == early || recorded == late { Verdict::Match } else { Verdict::Differs(String::new()) };
    }
    let header = |x: &Reply| (x.host, x.module, x.status, x.opcode);
    if header(&r) != header(&e) && header(&r) != header(&l) {
        return Verdict::Differs(String::new());
    }
    if r.status < 100 {
        return if recorded == early || recorded == late { Verdict::Match } else { Verdict::Differs(String::new()) };
    }
    let k = kind(ins);
    if let Kind::NotComparable(why) = k {
        return Verdict::NotComparable(why);
    }
    if r.value == e.value || r.value == l.value {
        return Verdict::Match;
    }
    let (lo, hi) = (e.value.min(l.value), e.value.max(l.value));
    if k == Kind::Motion && (lo..=hi).contains(&r.value) {
        return Verdict::Match;
    }
    if lo == hi {
        Verdict::Differs(String::new())
    } else {
        Verdict::Differs(format!("the virtual value went from {} to {} over the read's window", e.value, l.value))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tmclsim_protocol::{Request, Status};

    fn reply(status: u8, op: u8, value: i32) -> [u8; FRAME_LEN] {
        Reply { host: 2, module: 1, status, opcode: op, value }.encode()
    }

    #[test]
    fn lines_are_written_and_read_back() {
        let frame = Request::new(1, Instruction::new(6, 1, 0, 0)).encode();
        let line = format_line(12_300_000, Dir::Host, &frame);
        assert_eq!(line, r#"{"t": 0.012300, "dir": "host", "frame": "01 06 01 00 00 00 00 00 08"}"#);
        assert_eq!(parse_line(&line), Ok((12_300_000, Dir::Host, frame)));
        // Lower case, one run of digits, other keys.
        let (t, dir, f) = parse_line(r#"{"t": 1, "dir": "module", "frame": "020164060000000071", "note": "x"}"#).unwrap();
        assert_eq!((t, dir, f[2]), (1_000_000_000, Dir::Module, 0x64));
        assert_eq!(parse_frame("01 06 01 00 00 00 00 00 0a").unwrap()[8], 10);
    }

    #[test]
    fn bad_lines_say_what_is_wrong() {
        let e = |s: &str| parse_line(s).unwrap_err().to_string();
        assert!(e("hello").starts_with("not a JSON object"), "{}", e("hello"));
        assert!(e("[1]").starts_with("not a JSON object"));
        assert_eq!(e(r#"{"dir": "host", "frame": ""}"#), "no \"t\" (seconds since the start of the recording)");
        assert_eq!(e(r#"{"t": "1", "dir": "host", "frame": ""}"#), "\"t\" is \"1\", not a number of seconds");
        assert_eq!(e(r#"{"t": -1, "dir": "host", "frame": ""}"#), "\"t\" is -1: seconds since the start, 0…10000000");
        assert_eq!(e(r#"{"t": 1, "dir": "hots", "frame": ""}"#), "\"dir\" is \"hots\"; write \"host\" or \"module\"");
        assert_eq!(e(r#"{"t": 1, "dir": "host", "frame": "01 06 01 00 00 00 00 08"}"#), "\"frame\" has 8 bytes; a TMCL frame has 9");
        assert!(e(r#"{"t": 1, "dir": "host", "frame": "01 06 01 00 00 00 00 00 0G"}"#).contains("'0G' is not a byte in hex"));
        assert_eq!(e(r#"{"t": 1, "dir": "host", "frame": 5}"#), "\"frame\" is 5, not a string of hex bytes");
        assert!(e(&format!("{}1{}", "[".repeat(200), "]".repeat(200))).starts_with("not a JSON object"));
    }

    #[test]
    fn reading_checks_lines_times_and_lengths() {
        let good = "{\"t\": 0.1, \"dir\": \"host\", \"frame\": \"01 06 01 00 00 00 00 00 08\"}\n\n\
                    {\"t\": 0.2, \"dir\": \"module\", \"frame\": \"02 01 64 06 00 00 00 00 6D\"}\r\n";
        let entries = read(good.as_bytes(), "t.jsonl").unwrap();
        assert_eq!(
            entries.iter().map(|e| (e.line, e.t_ns, e.dir)).collect::<Vec<_>>(),
            [(1, 100_000_000, Dir::Host), (3, 200_000_000, Dir::Module)]
        );
        let back = good.replace("0.2", "0.05");
        assert_eq!(read(back.as_bytes(), "t.jsonl").unwrap_err(), "t.jsonl:3: \"t\" goes back in time (0.050000 after 0.100000)");
        let long = format!("{}\n", "x".repeat(MAX_LINE_BYTES + 1));
        assert_eq!(read(long.as_bytes(), "t.jsonl").unwrap_err(), "t.jsonl:1: line longer than 4096 bytes");
        assert!(read(&b"\xff\n"[..], "t.jsonl").unwrap_err().starts_with("t.jsonl:1: not UTF-8"));
        // A JSON error: the file's line, and the column in it (counted in
        // characters, the indent included), not the parser's "line 1".
        let bad = "{\"t\": 0.1, \"dir\": \"host\", \"frame\": \"01 06 01 00 00 00 00 00 08\"}\n\t{\"t\": 0.2, \"dir\": \"µ\" \"x\"}\n";
        assert_eq!(read(bad.as_bytes(), "t.jsonl").unwrap_err(), "t.jsonl:2:24: not a JSON object: expected `,` or `}`");
        let endless = std::io::repeat(b'\n');
        assert_eq!(read_within(endless, "t.jsonl", 1 << 20).unwrap_err(), "t.jsonl: larger than 1 MiB, the limit for a trace");
        assert_eq!(size_text(MAX_TRACE_BYTES), "256 MiB");
    }

    #[test]
    fn the_writer_keeps_time_going_forward_and_stops_at_the_limit() {
        let mut w = Writer::new(Vec::new());
        let f = [0u8; FRAME_LEN];
        assert!(w.write(2000, Dir::Host, &f).unwrap());
        assert!(w.write(1000, Dir::Module, &f).unwrap());
        w.entries = MAX_ENTRIES;
        assert!(!w.write(3000, Dir::Host, &f).unwrap());
        let text = String::from_utf8(w.out).unwrap();
        assert_eq!(read(text.as_bytes(), "w").unwrap().iter().map(|e| e.t_ns).collect::<Vec<_>>(), [2000, 2000]);
    }

    #[test]
    fn replies_are_compared_by_kind() {
        let gap = |kind| Instruction::new(opcode::GAP, kind, 0, 0);
        let ok = Status::Ok.code();
        let (a, b, c) = (reply(ok, 6, 100), reply(ok, 6, 150), reply(ok, 6, 200));
        // Positions: anywhere over the window.
        assert_eq!(compare(gap(1), Some(&b), Some(&a), Some(&c)), Verdict::Match);
        assert!(matches!(compare(gap(1), Some(&c), Some(&a), Some(&b)), Verdict::Differs(n) if n.contains("from 100 to 150")));
        // Exact values: one end or the other.
        assert_eq!(compare(gap(8), Some(&c), Some(&a), Some(&c)), Verdict::Match);
        assert!(matches!(compare(gap(8), Some(&b), Some(&a), Some(&c)), Verdict::Differs(_)));
        // Not comparable, even when equal; but a status is compared.
        assert!(matches!(compare(gap(206), Some(&a), Some(&a), Some(&a)), Verdict::NotComparable(_)));
        let refused = reply(3, 6, 0);
        assert!(matches!(compare(gap(206), Some(&refused), Some(&a), Some(&a)), Verdict::Differs(_)));
        // A missing reply on either side.
        assert!(matches!(compare(gap(1), None, Some(&a), Some(&a)), Verdict::Differs(_)));
        assert!(matches!(compare(gap(1), Some(&a), None, None), Verdict::Differs(_)));
        assert_eq!(compare(gap(1), None, None, None), Verdict::Match);
        // The version string, byte for byte.
        let v = Instruction::new(opcode::FIRMWARE_VERSION, 0, 0, 0);
        let s = tmclsim_protocol::frame::version_string_reply(2, b"1141V146");
        let t = tmclsim_protocol::frame::version_string_reply(2, b"1141V145");
        assert_eq!(compare(v, Some(&s), Some(&s), Some(&s)), Verdict::Match);
        assert!(matches!(compare(v, Some(&t), Some(&s), Some(&s)), Verdict::Differs(_)));
    }

    #[test]
    fn events_are_told_from_replies() {
        assert!(is_event(&reply(128, 138, 1)));
        assert!(!is_event(&reply(100, 138, 1)));
        assert!(!is_event(&reply(128, 6, 1)));
    }
}
