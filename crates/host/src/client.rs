//! A host's link to any TMCL module: TCP (a tmclsim server or a
//! serial-to-Ethernet bridge) or a serial port (a real module or a tmclsim
//! pty).

use std::io::{Read, Write};
use std::time::{Duration, Instant};
use tmclsim_protocol::{FRAME_LEN, Instruction, Reply, Request};

trait Stream: Read + Write {
    fn set_deadline(&mut self, left: Duration) -> std::io::Result<()>;
    /// Drops whatever was received and not read yet.
    fn discard_input(&mut self) -> std::io::Result<()>;
}

impl Stream for std::net::TcpStream {
    fn set_deadline(&mut self, left: Duration) -> std::io::Result<()> {
        self.set_read_timeout(Some(left.max(Duration::from_millis(1))))
    }

    fn discard_input(&mut self) -> std::io::Result<()> {
        self.set_nonblocking(true)?;
        let mut buf = [0u8; 256];
        let drained = loop {
            match self.read(&mut buf) {
                Ok(0) => break Ok(()),
                Ok(_) => {}
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => break Ok(()),
                Err(e) => break Err(e),
            }
        };
        self.set_nonblocking(false)?;
        drained
    }
}

impl Stream for Box<dyn serialport::SerialPort> {
    fn set_deadline(&mut self, left: Duration) -> std::io::Result<()> {
        self.set_timeout(left.max(Duration::from_millis(1))).map_err(std::io::Error::other)
    }

    fn discard_input(&mut self) -> std::io::Result<()> {
        self.clear(serialport::ClearBuffer::Input).map_err(std::io::Error::other)
    }
}

/// Why a link could not be opened, or a request not answered.
#[derive(Debug)]
pub enum LinkError {
    /// Neither a TCP address nor a serial port was given.
    NoLink,
    /// The TCP connection failed.
    Connect {
        /// The address, `HOST:PORT`.
        addr: String,
        /// Why.
        error: std::io::Error,
    },
    /// The serial port cannot be opened.
    OpenPort {
        /// The device.
        device: String,
        /// Why.
        error: serialport::Error,
    },
    /// The serial port cannot be split into a reading and a writing half.
    BothDirections(serialport::Error),
    /// A setting of the link (timeouts) cannot be made.
    Setup(std::io::Error),
    /// Reading failed.
    Read(std::io::Error),
    /// Writing failed.
    Write(std::io::Error),
    /// The link closed in the middle of a reply.
    Closed,
    /// The timeout passed with this many of the reply's 9 bytes received.
    NoReply {
        /// Bytes received.
        got: usize,
    },
    /// The reply's checksum is wrong.
    Checksum([u8; FRAME_LEN]),
}

impl LinkError {
    /// Whether the module did not answer (in time, in full, or with a
    /// right checksum): a command that failed, as a refused one did, not a
    /// link that failed.
    pub fn is_unanswered(&self) -> bool {
        matches!(self, LinkError::NoReply { .. } | LinkError::Checksum(_))
    }
}

impl std::fmt::Display for LinkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinkError::NoLink => write!(f, "give --tcp HOST:PORT or --port DEVICE"),
            LinkError::Connect { addr, error } => write!(f, "cannot connect to {addr}: {error}"),
            LinkError::OpenPort { device, error } => write!(f, "cannot open {device}: {error}"),
            LinkError::BothDirections(e) => write!(f, "cannot use the port in both directions: {e}"),
            LinkError::Setup(e) => write!(f, "{e}"),
            LinkError::Read(e) => write!(f, "read: {e}"),
            LinkError::Write(e) => write!(f, "write: {e}"),
            LinkError::Closed => write!(f, "the link closed before the reply was complete"),
            LinkError::NoReply { got: 0 } => {
                write!(f, "no reply within the timeout (wrong address, or replies suppressed by GP 255)")
            }
            LinkError::NoReply { got } => write!(f, "only {got} of 9 reply bytes arrived within the timeout"),
            LinkError::Checksum(raw) => write!(f, "the reply {} has a wrong checksum", hex(raw)),
        }
    }
}

impl std::error::Error for LinkError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            LinkError::Connect { error, .. } | LinkError::Setup(error) | LinkError::Read(error) | LinkError::Write(error) => Some(error),
            LinkError::OpenPort { error, .. } | LinkError::BothDirections(error) => Some(error),
            LinkError::NoLink | LinkError::Closed | LinkError::NoReply { .. } | LinkError::Checksum(_) => None,
        }
    }
}

impl From<LinkError> for String {
    fn from(e: LinkError) -> String {
        e.to_string()
    }
}

/// A link to one module address: TCP or a serial port.
pub struct Client {
    stream: Box<dyn Stream + Send>,
    /// The module address every request goes to.
    pub address: u8,
    /// How long a reply may take to arrive completely.
    pub timeout: Duration,
}

impl Client {
    /// Connects to `tcp` (HOST:PORT) or opens the serial port `port`.
    pub fn open(tcp: Option<&str>, port: Option<&str>, baud: u32, address: u8, timeout: Duration) -> Result<Client, LinkError> {
        let stream: Box<dyn Stream + Send> = match open_link(tcp, port, baud, timeout)? {
            Link::Tcp(s) => Box::new(s),
            Link::Serial(s) => Box::new(s),
        };
        Ok(Client { stream, address, timeout })
    }

    /// Sends one instruction and returns the raw reply frame.
    ///
    /// A reply that comes after its request's timeout stays in the link;
    /// taken for the next request's reply, it would put every later reply
    /// one request behind. So what was received before the request is
    /// dropped, and a normal reply whose instruction is not the request's
    /// (a late reply that arrives meanwhile) is skipped. The version text
    /// of 136 type 0 and the stored word of 134 carry no instruction byte
    /// of the request (`reply::shape`): they are taken as they come.
    pub fn exchange(&mut self, ins: Instruction) -> Result<[u8; FRAME_LEN], LinkError> {
        let frame = Request::new(self.address, ins).encode();
        self.stream.discard_input().map_err(LinkError::Read)?;
        self.stream.write_all(&frame).map_err(LinkError::Write)?;
        let start = Instant::now();
        loop {
            let left = self.timeout.saturating_sub(start.elapsed());
            let reply = self.read_frame_within(left)?;
            if tmclsim_ide::reply::shape(ins, self.address, &reply) != tmclsim_ide::reply::Shape::Normal || reply[3] == ins.opcode {
                return Ok(reply);
            }
        }
    }

    /// Sends one instruction and returns the decoded reply.
    pub fn request(&mut self, ins: Instruction) -> Result<Reply, LinkError> {
        let raw = self.exchange(ins)?;
        Reply::decode(&raw).ok_or(LinkError::Checksum(raw))
    }

    /// Sends without waiting for a reply (137).
    pub fn send_only(&mut self, ins: Instruction) -> Result<(), LinkError> {
        let frame = Request::new(self.address, ins).encode();
        self.stream.write_all(&frame).map_err(LinkError::Write)
    }

    /// Reads one frame without sending anything (a late reply), within
    /// the timeout.
    pub fn read_reply(&mut self) -> Result<[u8; FRAME_LEN], LinkError> {
        self.read_frame()
    }

    fn read_frame(&mut self) -> Result<[u8; FRAME_LEN], LinkError> {
        self.read_frame_within(self.timeout)
    }

    fn read_frame_within(&mut self, timeout: Duration) -> Result<[u8; FRAME_LEN], LinkError> {
        let start = Instant::now();
        let mut buf = [0u8; FRAME_LEN];
        let mut got = 0;
        while got < FRAME_LEN {
            let left = timeout.checked_sub(start.elapsed()).ok_or(LinkError::NoReply { got })?;
            self.stream.set_deadline(left).map_err(LinkError::Setup)?;
            match self.stream.read(&mut buf[got..]) {
                Ok(0) => return Err(LinkError::Closed),
                Ok(n) => got += n,
                Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
                Err(e) => return Err(LinkError::Read(e)),
            }
        }
        Ok(buf)
    }
}

enum Link {
    Tcp(std::net::TcpStream),
    Serial(Box<dyn serialport::SerialPort>),
}

fn open_link(tcp: Option<&str>, port: Option<&str>, baud: u32, timeout: Duration) -> Result<Link, LinkError> {
    match (tcp, port) {
        (Some(addr), _) => {
            let s = std::net::TcpStream::connect(addr).map_err(|error| LinkError::Connect { addr: addr.to_string(), error })?;
            s.set_nodelay(true).ok();
            Ok(Link::Tcp(s))
        }
        (None, Some(dev)) => Ok(Link::Serial(
            serialport::new(dev, baud).timeout(timeout).open().map_err(|error| LinkError::OpenPort { device: dev.to_string(), error })?,
        )),
        _ => Err(LinkError::NoLink),
    }
}

/// A link to modules with its two directions apart, for a proxy that
/// forwards a host's frames to the module and the module's frames (replies
/// and events of its own) back at any time.
pub struct RawLink {
    /// Reads wait at most the `poll` given to [`RawLink::open`] and then
    /// fail with `WouldBlock` or `TimedOut`, so a reading thread can look
    /// up now and then.
    pub reader: Box<dyn Read + Send>,
    /// Writes go straight to the link (TCP waits up to 5 s).
    pub writer: Box<dyn Write + Send>,
}

impl RawLink {
    /// Connects to `tcp` (HOST:PORT) or opens the serial port `port`.
    pub fn open(tcp: Option<&str>, port: Option<&str>, baud: u32, poll: Duration) -> Result<RawLink, LinkError> {
        let poll = poll.max(Duration::from_millis(1));
        match open_link(tcp, port, baud, poll)? {
            Link::Tcp(s) => {
                s.set_read_timeout(Some(poll)).map_err(LinkError::Setup)?;
                s.set_write_timeout(Some(Duration::from_secs(5))).map_err(LinkError::Setup)?;
                let writer = s.try_clone().map_err(LinkError::Setup)?;
                Ok(RawLink { reader: Box::new(s), writer: Box::new(writer) })
            }
            Link::Serial(s) => {
                let writer = s.try_clone().map_err(LinkError::BothDirections)?;
                Ok(RawLink { reader: Box::new(s), writer: Box::new(writer) })
            }
        }
    }
}

/// The profile of the module type a 136 type 1 reply names, if tmclsim has
/// one.
pub fn profile_of_version(value: i32) -> Option<std::sync::Arc<tmclsim_profile::Profile>> {
    let type_number = (value as u32) >> 16;
    tmclsim_profile::Profile::built_in(&format!("tmcm-{type_number}")).ok()
}

/// Bytes as upper-case hex pairs separated by spaces (`01 06 …`).
pub fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02X}")).collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::TcpListener;

    /// The reply frame a module at address 1 sends for `opcode` with `value`.
    fn reply(opcode: u8, value: i32) -> [u8; FRAME_LEN] {
        let mut r = [0u8; FRAME_LEN];
        r[..4].copy_from_slice(&[2, 1, 100, opcode]);
        r[4..8].copy_from_slice(&value.to_be_bytes());
        r[8] = r[..8].iter().fold(0u8, |s, b| s.wrapping_add(*b));
        r
    }

    #[test]
    fn a_late_reply_is_never_taken_for_the_next_requests() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        // The host tells the module when it has given up on GAP 1; the
        // module tells the host when the late reply is on its way.
        let (gave_up, host_gave_up) = std::sync::mpsc::channel::<()>();
        let (late_sent, late_reply_sent) = std::sync::mpsc::channel::<()>();
        let module = std::thread::spawn(move || {
            let (mut s, _) = listener.accept().unwrap();
            let mut request = [0u8; FRAME_LEN];
            // GAP 1: answered after the host gave up waiting.
            s.read_exact(&mut request).unwrap();
            host_gave_up.recv().unwrap();
            s.write_all(&reply(6, 111)).unwrap();
            late_sent.send(()).unwrap();
            // SAP 4: answered at once.
            s.read_exact(&mut request).unwrap();
            s.write_all(&reply(5, 222)).unwrap();
            // GGP 0: a late GAP reply comes in between, then its own.
            s.read_exact(&mut request).unwrap();
            s.write_all(&[reply(6, 333), reply(10, 444)].concat()).unwrap();
            // 136 type 0 and 134: replies without the request's
            // instruction byte.
            s.read_exact(&mut request).unwrap();
            s.write_all(b"\x021141V146").unwrap();
            s.read_exact(&mut request).unwrap();
            s.write_all(&[2, 5, 4, 0, 0, 0, 3, 232, 0]).unwrap();
        });
        let mut c = Client::open(Some(&addr), None, 9600, 1, Duration::from_millis(50)).unwrap();
        assert!(c.exchange(Instruction::new(6, 1, 0, 0)).unwrap_err().to_string().starts_with("no reply"));
        gave_up.send(()).unwrap();
        late_reply_sent.recv().unwrap();
        assert_eq!(c.exchange(Instruction::new(5, 4, 0, 222)).unwrap(), reply(5, 222), "the late GAP reply was dropped");
        c.timeout = Duration::from_secs(2);
        assert_eq!(c.exchange(Instruction::new(10, 0, 0, 0)).unwrap(), reply(10, 444), "the late reply skipped");
        assert_eq!(&c.exchange(Instruction::new(136, 0, 0, 0)).unwrap()[1..], b"1141V146");
        let word = c.exchange(Instruction::new(134, 0, 0, 0)).unwrap();
        assert_eq!(tmclsim_ide::reply::memory_word(&word, 1), Ok(Instruction::new(5, 4, 0, 1000)), "SAP 4, 0, 1000 read back");
        module.join().unwrap();
    }
}
