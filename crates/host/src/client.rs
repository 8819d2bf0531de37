//! A host's link to any TMCL module: TCP (a tmclsim server or a
//! serial-to-Ethernet bridge) or a serial port (a real module or a tmclsim
//! pty).

use std::io::{Read, Write};
use std::time::{Duration, Instant};
use tmclsim_protocol::{FRAME_LEN, Instruction, Reply, Request};

trait Stream: Read + Write {
    fn set_deadline(&mut self, left: Duration) -> std::io::Result<()>;
}

impl Stream for std::net::TcpStream {
    fn set_deadline(&mut self, left: Duration) -> std::io::Result<()> {
        self.set_read_timeout(Some(left.max(Duration::from_millis(1))))
    }
}

impl Stream for Box<dyn serialport::SerialPort> {
    fn set_deadline(&mut self, left: Duration) -> std::io::Result<()> {
        self.set_timeout(left.max(Duration::from_millis(1))).map_err(std::io::Error::other)
    }
}

/// A link to one module address: TCP or a serial port.
pub struct Client {
    stream: Box<dyn Stream + Send>,
    pub address: u8,
    pub timeout: Duration,
}

impl Client {
    /// Connects to `tcp` (HOST:PORT) or opens the serial port `port`.
    pub fn open(tcp: Option<&str>, port: Option<&str>, baud: u32, address: u8, timeout: Duration) -> Result<Client, String> {
        let stream: Box<dyn Stream + Send> = match open_link(tcp, port, baud, timeout)? {
            Link::Tcp(s) => Box::new(s),
            Link::Serial(s) => Box::new(s),
        };
        Ok(Client { stream, address, timeout })
    }

    /// Sends one instruction and returns the raw reply frame.
    pub fn exchange(&mut self, ins: Instruction) -> Result<[u8; FRAME_LEN], String> {
        let frame = Request::new(self.address, ins).encode();
        self.stream.write_all(&frame).map_err(|e| format!("write: {e}"))?;
        self.read_frame()
    }

    /// Sends one instruction and returns the decoded reply.
    pub fn request(&mut self, ins: Instruction) -> Result<Reply, String> {
        let raw = self.exchange(ins)?;
        Reply::decode(&raw).ok_or_else(|| format!("the reply {} has a wrong checksum", hex(&raw)))
    }

    /// Sends without waiting for a reply (137).
    pub fn send_only(&mut self, ins: Instruction) -> Result<(), String> {
        let frame = Request::new(self.address, ins).encode();
        self.stream.write_all(&frame).map_err(|e| format!("write: {e}"))
    }

    /// Reads one frame without sending anything (a late reply), within
    /// the timeout.
    pub fn read_reply(&mut self) -> Result<[u8; FRAME_LEN], String> {
        self.read_frame()
    }

    fn read_frame(&mut self) -> Result<[u8; FRAME_LEN], String> {
        let start = Instant::now();
        let mut buf = [0u8; FRAME_LEN];
        let mut got = 0;
        while got < FRAME_LEN {
            let left = self.timeout.checked_sub(start.elapsed()).ok_or_else(|| no_reply(got))?;
            self.stream.set_deadline(left).map_err(|e| e.to_string())?;
            match self.stream.read(&mut buf[got..]) {
                Ok(0) => return Err("the link closed before the reply was complete".into()),
                Ok(n) => got += n,
                Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
                Err(e) => return Err(format!("read: {e}")),
            }
        }
        Ok(buf)
    }
}

enum Link {
    Tcp(std::net::TcpStream),
    Serial(Box<dyn serialport::SerialPort>),
}

fn open_link(tcp: Option<&str>, port: Option<&str>, baud: u32, timeout: Duration) -> Result<Link, String> {
    match (tcp, port) {
        (Some(addr), _) => {
            let s = std::net::TcpStream::connect(addr).map_err(|e| format!("cannot connect to {addr}: {e}"))?;
            s.set_nodelay(true).ok();
            Ok(Link::Tcp(s))
        }
        (None, Some(dev)) => {
            Ok(Link::Serial(serialport::new(dev, baud).timeout(timeout).open().map_err(|e| format!("cannot open {dev}: {e}"))?))
        }
        _ => Err("give --tcp HOST:PORT or --port DEVICE".into()),
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
    pub writer: Box<dyn Write + Send>,
}

impl RawLink {
    /// Connects to `tcp` (HOST:PORT) or opens the serial port `port`.
    pub fn open(tcp: Option<&str>, port: Option<&str>, baud: u32, poll: Duration) -> Result<RawLink, String> {
        let poll = poll.max(Duration::from_millis(1));
        match open_link(tcp, port, baud, poll)? {
            Link::Tcp(s) => {
                s.set_read_timeout(Some(poll)).map_err(|e| e.to_string())?;
                s.set_write_timeout(Some(Duration::from_secs(5))).map_err(|e| e.to_string())?;
                let writer = s.try_clone().map_err(|e| e.to_string())?;
                Ok(RawLink { reader: Box::new(s), writer: Box::new(writer) })
            }
            Link::Serial(s) => {
                let writer = s.try_clone().map_err(|e| format!("cannot use the port in both directions: {e}"))?;
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

fn no_reply(got: usize) -> String {
    if got == 0 {
        "no reply within the timeout (wrong address, or replies suppressed by GP 255)".into()
    } else {
        format!("only {got} of 9 reply bytes arrived within the timeout")
    }
}

pub fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02X}")).collect::<Vec<_>>().join(" ")
}
