//! The serial-line CAN adapter protocol (Lawicel "SLCAN"): ASCII lines
//! ended by a carriage return. A host opens the channel (`S6`, `O`),
//! transmits frames (`t1237` + data in hex) and receives them as the same
//! kind of line. Answers: carriage return for OK, BEL for an error, `z`
//! before the carriage return for a transmitted standard frame, `Z` for an
//! extended one.

/// One command line from the host.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SlcanCommand {
    /// `S0`…`S8`: a standard bit rate.
    Bitrate(u8),
    /// `sxxyy`: bit timing registers.
    BitTiming,
    /// `O` (or `L`, listen only).
    Open {
        /// `L`: receive only.
        listen_only: bool,
    },
    /// `C`.
    Close,
    /// `t`/`T`: a data frame; `r`/`R`: a remote frame.
    Transmit {
        /// The CAN identifier.
        id: u32,
        /// A 29-bit identifier (`T`, `R`).
        extended: bool,
        /// A remote frame (`r`, `R`).
        remote: bool,
        /// The data bytes (none for a remote frame).
        data: Vec<u8>,
    },
    /// `V`, `v`: version.
    Version,
    /// `N`: serial number.
    SerialNumber,
    /// `F`: status flags.
    Status,
    /// `Z0`/`Z1` timestamps, `M`/`m` acceptance filters, `X`, `W`, `Q`:
    /// accepted and ignored.
    Setting,
}

/// Why a line is not a command.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SlcanError(pub String);

fn hex(s: &str) -> Result<u32, SlcanError> {
    u32::from_str_radix(s, 16).map_err(|_| SlcanError(format!("'{s}' is not hexadecimal")))
}

/// Parses one line (without its carriage return).
pub fn parse(line: &str) -> Result<SlcanCommand, SlcanError> {
    let mut chars = line.chars();
    let Some(c) = chars.next() else { return Err(SlcanError("empty line".into())) };
    let rest = chars.as_str();
    Ok(match c {
        'S' => {
            let n: u8 = rest.parse().map_err(|_| SlcanError(format!("bad bit rate '{rest}'")))?;
            if n > 8 {
                return Err(SlcanError(format!("no bit rate S{n}")));
            }
            SlcanCommand::Bitrate(n)
        }
        's' => SlcanCommand::BitTiming,
        'O' => SlcanCommand::Open { listen_only: false },
        'L' => SlcanCommand::Open { listen_only: true },
        'C' => SlcanCommand::Close,
        'V' | 'v' => SlcanCommand::Version,
        'N' => SlcanCommand::SerialNumber,
        'F' => SlcanCommand::Status,
        'Z' | 'M' | 'm' | 'X' | 'W' | 'Q' | 'U' => SlcanCommand::Setting,
        't' | 'T' | 'r' | 'R' => {
            let extended = c.is_ascii_uppercase();
            let remote = c == 'r' || c == 'R';
            let id_len = if extended { 8 } else { 3 };
            if rest.len() < id_len + 1 || !rest.is_ascii() {
                return Err(SlcanError(format!("frame line '{line}' is too short")));
            }
            let id = hex(&rest[..id_len])?;
            if (!extended && id > 0x7FF) || id > 0x1FFF_FFFF {
                return Err(SlcanError(format!("identifier {id:X} is out of range")));
            }
            let dlc = hex(&rest[id_len..id_len + 1])? as usize;
            if dlc > 8 {
                return Err(SlcanError(format!("length {dlc} is above 8")));
            }
            let body = &rest[id_len + 1..];
            let data = if remote {
                Vec::new()
            } else {
                if body.len() < 2 * dlc {
                    return Err(SlcanError(format!("frame line '{line}' has fewer than {dlc} data bytes")));
                }
                (0..dlc).map(|i| hex(&body[2 * i..2 * i + 2]).map(|b| b as u8)).collect::<Result<_, _>>()?
            };
            SlcanCommand::Transmit { id, extended, remote, data }
        }
        other => return Err(SlcanError(format!("unknown command '{other}'"))),
    })
}

/// The line an adapter sends for a received standard data frame.
pub fn received(id: u32, data: &[u8]) -> String {
    let mut s = format!("t{:03X}{}", id & 0x7FF, data.len().min(8));
    for b in data.iter().take(8) {
        s.push_str(&format!("{b:02X}"));
    }
    s.push('\r');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_both_ways() {
        assert_eq!(
            parse("t00180601000000000008").unwrap(),
            SlcanCommand::Transmit { id: 1, extended: false, remote: false, data: vec![6, 1, 0, 0, 0, 0, 0, 8] }
        );
        assert_eq!(received(2, &[1, 100, 6, 0, 0, 3, 0xE8]), "t0027016406000003E8\r");
        assert_eq!(parse("S8").unwrap(), SlcanCommand::Bitrate(8));
        assert_eq!(parse("O").unwrap(), SlcanCommand::Open { listen_only: false });
        assert!(parse("t12").is_err());
        assert!(parse("t8001").is_err(), "standard identifiers are 11 bits");
        assert!(parse("t0012AB").is_err(), "two bytes announced, one given");
        assert!(parse("S9").is_err());
        assert!(parse("q").is_err());
    }
}
