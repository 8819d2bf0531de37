//! EtherCAT frames: an Ethernet header of EtherType 0x88A4, a 2-byte
//! EtherCAT header (length, type 1) and datagrams. Each datagram: command,
//! index, address (4), length/more (2), interrupt (2), data, working
//! counter (2); little endian.

/// The EtherType of EtherCAT frames.
pub const ETHERTYPE: u16 = 0x88A4;
/// Ethernet header.
pub const ETH_HEADER: usize = 14;
/// Datagram header before the data.
pub const DATAGRAM_HEADER: usize = 10;

/// A datagram inside a frame, by offsets (the frame is edited in place).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Datagram {
    /// The command (APRD, FPWR, LRW, …).
    pub command: u8,
    /// Offset of the datagram header in the frame.
    pub at: usize,
    /// Length of the data in bytes.
    pub len: usize,
}

impl Datagram {
    /// Offset of the 4-byte address in the frame.
    pub fn address_offset(&self) -> usize {
        self.at + 2
    }

    /// Where the data lie in the frame.
    pub fn data(&self) -> std::ops::Range<usize> {
        self.at + DATAGRAM_HEADER..self.at + DATAGRAM_HEADER + self.len
    }

    /// Offset of the 2-byte working counter in the frame.
    pub fn wkc_offset(&self) -> usize {
        self.at + DATAGRAM_HEADER + self.len
    }
}

/// Finds the datagrams of an EtherCAT frame; `None` for anything that is
/// not one, or is truncated (it is then ignored, as an ESC drops it).
pub fn datagrams(frame: &[u8]) -> Option<Vec<Datagram>> {
    if frame.len() < ETH_HEADER + 2 || u16::from_be_bytes([frame[12], frame[13]]) != ETHERTYPE {
        return None;
    }
    let header = u16::from_le_bytes([frame[ETH_HEADER], frame[ETH_HEADER + 1]]);
    let length = (header & 0x07FF) as usize;
    let kind = header >> 12;
    if kind != 1 || ETH_HEADER + 2 + length > frame.len() {
        return None;
    }
    let end = ETH_HEADER + 2 + length;
    let mut at = ETH_HEADER + 2;
    let mut out = Vec::new();
    loop {
        if at + DATAGRAM_HEADER + 2 > end {
            return None;
        }
        let len_field = u16::from_le_bytes([frame[at + 6], frame[at + 7]]);
        let len = (len_field & 0x07FF) as usize;
        let more = len_field & 0x8000 != 0;
        if at + DATAGRAM_HEADER + len + 2 > end {
            return None;
        }
        out.push(Datagram { command: frame[at], at, len });
        at += DATAGRAM_HEADER + len + 2;
        if !more {
            return Some(out);
        }
        if out.len() > 64 {
            return None;
        }
    }
}

/// Builds a frame of datagrams (for tests and tools): (command, address,
/// data) each.
pub fn build(datagrams: &[(u8, u32, Vec<u8>)]) -> Vec<u8> {
    let mut f = vec![0xFF; 6];
    f.extend_from_slice(&[0x01, 0x01, 0x01, 0x01, 0x01, 0x01]);
    f.extend_from_slice(&ETHERTYPE.to_be_bytes());
    let body: usize = datagrams.iter().map(|(_, _, d)| DATAGRAM_HEADER + d.len() + 2).sum();
    f.extend_from_slice(&((body as u16) | 0x1000).to_le_bytes());
    for (i, (cmd, addr, data)) in datagrams.iter().enumerate() {
        f.push(*cmd);
        f.push(i as u8);
        f.extend_from_slice(&addr.to_le_bytes());
        let more = if i + 1 < datagrams.len() { 0x8000 } else { 0 };
        f.extend_from_slice(&((data.len() as u16) | more).to_le_bytes());
        f.extend_from_slice(&[0, 0]);
        f.extend_from_slice(data);
        f.extend_from_slice(&[0, 0]);
    }
    while f.len() < 60 {
        f.push(0);
    }
    f
}

/// The working counter of datagram `n` of a frame.
pub fn wkc(frame: &[u8], n: usize) -> Option<u16> {
    let d = *datagrams(frame)?.get(n)?;
    Some(u16::from_le_bytes([frame[d.wkc_offset()], frame[d.wkc_offset() + 1]]))
}

/// The data of datagram `n` of a frame.
pub fn data(frame: &[u8], n: usize) -> Option<Vec<u8>> {
    let d = *datagrams(frame)?.get(n)?;
    Some(frame[d.data()].to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn build_and_parse() {
        let f = build(&[(7, 0x0000_0000, vec![0; 2]), (4, 0x0130_03E9, vec![0; 4])]);
        let d = datagrams(&f).unwrap();
        assert_eq!(d.len(), 2);
        assert_eq!((d[0].command, d[0].len, d[1].command, d[1].len), (7, 2, 4, 4));
        assert!(datagrams(&f[..20]).is_none(), "truncated");
        let mut bad = f.clone();
        bad[12] = 0x08;
        assert!(datagrams(&bad).is_none(), "not EtherCAT");
    }
}
