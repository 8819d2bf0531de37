//! Intel HEX text, the form firmware images travel in (update tools read
//! it): data records of 16 bytes, an extended linear address record
//! whenever the upper 16 bits of the address change, the end record.

/// `bytes` placed at `start`, as Intel HEX text.
pub fn encode(start: u32, bytes: &[u8]) -> String {
    let mut out = String::new();
    let mut upper = None;
    for (i, chunk) in bytes.chunks(16).enumerate() {
        let at = start.wrapping_add(16 * i as u32);
        if upper != Some(at >> 16) {
            upper = Some(at >> 16);
            record(&mut out, 0, 4, &((at >> 16) as u16).to_be_bytes());
        }
        record(&mut out, (at & 0xFFFF) as u16, 0, chunk);
    }
    record(&mut out, 0, 1, &[]);
    out
}

/// One record: `:`, length, address, type, data, checksum (the two's
/// complement of the sum of the bytes before it).
fn record(out: &mut String, address: u16, kind: u8, data: &[u8]) {
    let mut bytes = vec![data.len() as u8];
    bytes.extend_from_slice(&address.to_be_bytes());
    bytes.push(kind);
    bytes.extend_from_slice(data);
    let sum = bytes.iter().fold(0u8, |s, b| s.wrapping_add(*b));
    bytes.push(sum.wrapping_neg());
    out.push(':');
    for b in bytes {
        out.push_str(&format!("{b:02X}"));
    }
    out.push('\n');
}

#[cfg(test)]
mod tests {
    use super::encode;

    #[test]
    fn records_as_the_format_defines_them() {
        // As Python's intelhex writes the same bytes: the second record
        // starts a new 64 KiB segment.
        let text = encode(0x0800_FFF0, &[0x11; 20]);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], ":020000040800F2");
        assert_eq!(lines[1], ":10FFF00011111111111111111111111111111111F1");
        assert_eq!(lines[2], ":020000040801F1");
        assert_eq!(lines[3], ":0400000011111111B8");
        assert_eq!(lines[4], ":00000001FF");
        assert_eq!(lines.len(), 5);
    }
}
