//! The mailbox: CoE (CANopen over EtherCAT) SDO transfers. TMCL travels
//! in them: an SDO download of 8 bytes to object 0x2000:00 is a TMCL
//! request `[module address][opcode][type][motor/bank][value MSB first]`;
//! an SDO upload of 0x2000:00 returns the reply `[reply address][module
//! address][status][opcode][value MSB first]` (tmcm-1310.md). Every
//! standard master can send SDOs (pysoem: `sdo_write`/`sdo_read`).

/// Mailbox header: length (2), address (2), channel/priority (1),
/// type/counter (1).
pub const HEADER: usize = 6;
pub const TYPE_COE: u8 = 3;

/// Object of the TMCL channel.
pub const TMCL_OBJECT: u16 = 0x2000;

/// SDO abort codes.
pub mod abort {
    pub const OBJECT_MISSING: u32 = 0x0602_0000;
    pub const SUBINDEX_MISSING: u32 = 0x0609_0011;
    pub const READ_ONLY: u32 = 0x0601_0002;
    pub const LENGTH: u32 = 0x0607_0010;
    pub const COMMAND: u32 = 0x0504_0001;
}

/// A decoded SDO request.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Sdo {
    Download { index: u16, subindex: u8, data: Vec<u8> },
    Upload { index: u16, subindex: u8 },
}

/// Parses a mailbox message carrying a CoE SDO request; `Err` carries an
/// abort (index, subindex, code) when it is a CoE message that cannot be
/// served, `Ok(None)` when it is not CoE at all.
pub fn parse(msg: &[u8]) -> Result<Option<(u8, Sdo)>, (u16, u8, u32)> {
    if msg.len() < HEADER + 2 + 8 {
        return Ok(None);
    }
    let len = u16::from_le_bytes([msg[0], msg[1]]) as usize;
    let kind = msg[5] & 0x0F;
    let counter = (msg[5] >> 4) & 0x07;
    if kind != TYPE_COE || len < 10 || HEADER + len > msg.len() {
        return Ok(None);
    }
    let coe = u16::from_le_bytes([msg[6], msg[7]]);
    let service = coe >> 12;
    let body = &msg[HEADER + 2..HEADER + len];
    let command = body[0];
    let index = u16::from_le_bytes([body[1], body[2]]);
    let subindex = body[3];
    if service != 2 {
        return Err((index, subindex, abort::COMMAND));
    }
    let sdo = match command >> 5 {
        1 => {
            let expedited = command & 0x02 != 0;
            if expedited {
                let unused = if command & 0x01 != 0 { ((command >> 2) & 0x03) as usize } else { 0 };
                Sdo::Download { index, subindex, data: body[4..8 - unused].to_vec() }
            } else {
                let size = u32::from_le_bytes([body[4], body[5], body[6], body[7]]) as usize;
                if body.len() < 8 + size {
                    return Err((index, subindex, abort::LENGTH));
                }
                Sdo::Download { index, subindex, data: body[8..8 + size].to_vec() }
            }
        }
        2 => Sdo::Upload { index, subindex },
        _ => return Err((index, subindex, abort::COMMAND)),
    };
    Ok(Some((counter, sdo)))
}

fn message(counter: u8, body: &[u8]) -> Vec<u8> {
    let mut m = Vec::with_capacity(HEADER + 2 + body.len());
    m.extend_from_slice(&((2 + body.len()) as u16).to_le_bytes());
    m.extend_from_slice(&[0, 0, 0, TYPE_COE | (counter & 0x07) << 4]);
    m.extend_from_slice(&(3u16 << 12).to_le_bytes()); // SDO response
    m.extend_from_slice(body);
    m
}

pub fn download_response(counter: u8, index: u16, subindex: u8) -> Vec<u8> {
    let i = index.to_le_bytes();
    message(counter, &[0x60, i[0], i[1], subindex, 0, 0, 0, 0])
}

pub fn upload_response(counter: u8, index: u16, subindex: u8, data: &[u8]) -> Vec<u8> {
    let i = index.to_le_bytes();
    if data.len() <= 4 {
        let mut b = vec![0x43 | ((4 - data.len() as u8) << 2), i[0], i[1], subindex, 0, 0, 0, 0];
        b[4..4 + data.len()].copy_from_slice(data);
        message(counter, &b)
    } else {
        let mut b = vec![0x41, i[0], i[1], subindex];
        b.extend_from_slice(&(data.len() as u32).to_le_bytes());
        b.extend_from_slice(data);
        message(counter, &b)
    }
}

/// An SDO abort: CoE sends it with the "SDO request" service.
pub fn abort_response(counter: u8, index: u16, subindex: u8, code: u32) -> Vec<u8> {
    let i = index.to_le_bytes();
    let c = code.to_le_bytes();
    let mut m = message(counter, &[0x80, i[0], i[1], subindex, c[0], c[1], c[2], c[3]]);
    m[HEADER..HEADER + 2].copy_from_slice(&(2u16 << 12).to_le_bytes());
    m
}

/// An SDO request as a master sends it.
#[cfg(test)]
pub fn request(counter: u8, sdo: &Sdo) -> Vec<u8> {
    let mut body = Vec::new();
    match sdo {
        Sdo::Download { index, subindex, data } => {
            body.push(0x21);
            body.extend_from_slice(&index.to_le_bytes());
            body.push(*subindex);
            body.extend_from_slice(&(data.len() as u32).to_le_bytes());
            body.extend_from_slice(data);
        }
        Sdo::Upload { index, subindex } => {
            body.push(0x40);
            body.extend_from_slice(&index.to_le_bytes());
            body.push(*subindex);
            body.extend_from_slice(&[0; 4]);
        }
    }
    let mut m = message(counter, &body);
    m[HEADER..HEADER + 2].copy_from_slice(&(2u16 << 12).to_le_bytes());
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_parse_back() {
        for sdo in
            [Sdo::Download { index: 0x2000, subindex: 0, data: vec![1, 2, 3, 4, 5, 6, 7, 8] }, Sdo::Upload { index: 0x1018, subindex: 1 }]
        {
            let mut m = request(3, &sdo);
            m.resize(128, 0);
            assert_eq!(parse(&m), Ok(Some((3, sdo))));
        }
        let up = upload_response(1, 0x1018, 1, &[0x86, 0x02, 0, 0]);
        assert_eq!(up[HEADER + 2], 0x43);
        let big = upload_response(1, 0x2000, 0, &[0; 8]);
        assert_eq!(big[HEADER + 2], 0x41);
    }
}
