//! `tmclsim send`: one command to any TMCL module, the reply decoded.

use crate::SendArgs;
use std::io::{Read, Write};
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tmclsim_protocol::{mnemonic, opcode, Reply, Request, Status, FRAME_LEN};

pub fn run(args: SendArgs) -> Result<ExitCode, String> {
    let line = args.command.join(" ");
    let ins = mnemonic::parse_line(&line).map_err(|e| format!("{line}: {e}"))?;
    let frame = Request::new(args.address, ins).encode();
    let timeout = crate::millis(args.timeout);
    let mut link: Box<dyn Link> = match (&args.tcp, &args.port) {
        (Some(addr), _) => {
            let s = std::net::TcpStream::connect(addr).map_err(|e| format!("cannot connect to {addr}: {e}"))?;
            s.set_nodelay(true).ok();
            Box::new(s)
        }
        (None, Some(dev)) => Box::new(
            serialport::new(dev, args.baud).timeout(timeout).open().map_err(|e| format!("cannot open {dev}: {e}"))?,
        ),
        _ => unreachable!("clap requires --tcp or --port"),
    };
    println!("request: {}  ({})", hex(&frame), mnemonic::format(ins));
    link.write_all(&frame).map_err(|e| format!("write: {e}"))?;
    if ins.opcode == opcode::FACTORY_DEFAULTS {
        println!("(137 sends no reply)");
        return Ok(ExitCode::SUCCESS);
    }
    let reply = read_frame(&mut *link, timeout)?;
    println!("reply:   {}", hex(&reply));
    if ins.opcode == opcode::FIRMWARE_VERSION && ins.kind == 0 {
        println!("version: {}", String::from_utf8_lossy(&reply[1..]));
        return Ok(ExitCode::SUCCESS);
    }
    let Some(r) = Reply::decode(&reply) else {
        println!("the reply's checksum is wrong");
        return Ok(ExitCode::from(1));
    };
    let status = Status::from_code(r.status).map_or(format!("{} (unknown)", r.status), |s| s.to_string());
    println!("host {} module {} status {status} opcode {} ({}) value {}", r.host, r.module, r.opcode, opcode::name(r.opcode), r.value);
    Ok(if r.status < 100 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

trait Link: Read + Write {
    fn set_deadline(&mut self, left: Duration) -> std::io::Result<()>;
}

impl Link for std::net::TcpStream {
    fn set_deadline(&mut self, left: Duration) -> std::io::Result<()> {
        self.set_read_timeout(Some(left.max(Duration::from_millis(1))))
    }
}

impl Link for Box<dyn serialport::SerialPort> {
    fn set_deadline(&mut self, left: Duration) -> std::io::Result<()> {
        self.set_timeout(left.max(Duration::from_millis(1))).map_err(std::io::Error::other)
    }
}

fn read_frame(link: &mut dyn Link, timeout: Duration) -> Result<[u8; FRAME_LEN], String> {
    let start = Instant::now();
    let mut buf = [0u8; FRAME_LEN];
    let mut got = 0;
    while got < FRAME_LEN {
        let left = timeout.checked_sub(start.elapsed()).ok_or_else(|| no_reply(got))?;
        link.set_deadline(left).map_err(|e| e.to_string())?;
        match link.read(&mut buf[got..]) {
            Ok(0) => return Err("the link closed before the reply was complete".into()),
            Ok(n) => got += n,
            Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
            Err(e) => return Err(format!("read: {e}")),
        }
    }
    Ok(buf)
}

fn no_reply(got: usize) -> String {
    if got == 0 {
        "no reply within the timeout (wrong address, or replies suppressed by GP 255)".into()
    } else {
        format!("only {got} of 9 reply bytes arrived within the timeout")
    }
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02X}")).collect::<Vec<_>>().join(" ")
}
