//! The TMCL bootloader's own state while it runs: the flash it writes, its
//! page buffer, and the length and checksum a firmware update finishes with
//! (docs/behaviour.md rules 99–103). The module (`module/boot.rs`) decides
//! when it runs and answers for it; this part knows nothing of the module.

use std::collections::BTreeMap;
use tmclsim_profile::Bootloader as Facts;

/// Flash bytes the bootloader did not write since it erased: a flash cell
/// reads 0xFF when erased.
const ERASED: u8 = 0xFF;

/// What the bootloader holds in RAM while it runs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Session {
    /// The flash was erased (BOOT_ERASE_ALL) in this session. Before that
    /// it holds the old firmware, whose bytes are not modelled: they read
    /// as 0x00, so that writing over them without an erase shows in the
    /// checksum, as programming unerased flash does.
    erased: bool,
    /// Pages written in this session: page address → bytes.
    pages: BTreeMap<u32, Vec<u8>>,
    /// The page buffer that BOOT_WRITE_BUFFER fills.
    buffer: Vec<u8>,
    /// BOOT_WRITE_LENGTH type 0 and type 1.
    length: Option<u32>,
    checksum: Option<u32>,
}

/// Why a bootloader command is refused (status 4 or 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refused {
    /// An address or index outside the flash or the page.
    Value,
    /// A type the command does not have.
    Type,
}

impl Session {
    /// A bootloader that just started; `erased`: the flash holds no
    /// firmware (a previous update was interrupted).
    pub fn new(facts: &Facts, erased: bool) -> Session {
        Session { erased, pages: BTreeMap::new(), buffer: vec![ERASED; facts.page_size as usize], length: None, checksum: None }
    }

    /// BOOT_ERASE_ALL: every page of the firmware reads 0xFF.
    pub fn erase(&mut self, facts: &Facts) {
        *self = Session::new(facts, true);
    }

    /// BOOT_WRITE_BUFFER: word `index` of the page buffer, the first byte
    /// the lowest (as the host sends a little-endian word).
    pub fn write_buffer(&mut self, index: u32, word: u32) -> Result<(), Refused> {
        let at = index as usize * 4;
        let cells = self.buffer.get_mut(at..at + 4).ok_or(Refused::Value)?;
        cells.copy_from_slice(&word.to_le_bytes());
        Ok(())
    }

    /// BOOT_WRITE_PAGE: programs the page at `address` with the buffer
    /// (programming only clears bits, as flash does) and empties the buffer.
    pub fn write_page(&mut self, facts: &Facts, address: u32) -> Result<(), Refused> {
        if !address.is_multiple_of(facts.page_size) || !self.in_flash(facts, address) {
            return Err(Refused::Value);
        }
        let mut page = self.page(facts, address);
        for (cell, b) in page.iter_mut().zip(&self.buffer) {
            *cell &= b;
        }
        self.pages.insert(address, page);
        self.buffer.fill(ERASED);
        Ok(())
    }

    /// BOOT_GET_CHECKSUM: the byte sum of the flash from the firmware's
    /// start through `last`, modulo 2^32.
    pub fn checksum_through(&self, facts: &Facts, last: u32) -> Result<u32, Refused> {
        if !self.in_flash(facts, last) {
            return Err(Refused::Value);
        }
        Ok(self.sum(facts, facts.flash_start, last - facts.flash_start + 1))
    }

    /// BOOT_READ_MEMORY: the flash word at `address` (a multiple of 4).
    pub fn read_word(&self, facts: &Facts, address: u32) -> Result<u32, Refused> {
        if !address.is_multiple_of(4) || !self.in_flash(facts, address) {
            return Err(Refused::Value);
        }
        let page = facts.page_size;
        let bytes = self.page(facts, address / page * page);
        let at = (address % page) as usize;
        Ok(u32::from_le_bytes(bytes[at..at + 4].try_into().expect("four bytes")))
    }

    /// BOOT_WRITE_LENGTH: type 0 the firmware's length in bytes, type 1
    /// its checksum.
    pub fn write_length(&mut self, facts: &Facts, kind: u8, value: u32) -> Result<(), Refused> {
        match kind {
            0 if value == 0 || value > facts.flash_size => Err(Refused::Value),
            0 => {
                self.length = Some(value);
                Ok(())
            }
            1 => {
                self.checksum = Some(value);
                Ok(())
            }
            _ => Err(Refused::Type),
        }
    }

    /// The firmware the flash holds now, if it is complete: a length and a
    /// checksum were written and match the flash, and the bytes carry this
    /// module's version string (`None`: the bootloader does not start it).
    pub fn complete_firmware(&self, facts: &Facts) -> Option<[u8; 2]> {
        let (length, checksum) = (self.length?, self.checksum?);
        if !self.erased || self.sum(facts, facts.flash_start, length) != checksum {
            return None;
        }
        let mut image = Vec::with_capacity(length as usize);
        let page = facts.page_size;
        let mut at = facts.flash_start;
        while at < facts.flash_start + length {
            image.extend_from_slice(&self.page(facts, at / page * page));
            at = at / page * page + page;
        }
        let skip = (facts.flash_start % page) as usize;
        image.drain(..skip);
        image.truncate(length as usize);
        facts.find_version(&image)
    }

    fn in_flash(&self, facts: &Facts, address: u32) -> bool {
        address >= facts.flash_start && address - facts.flash_start < facts.flash_size
    }

    /// The bytes of the page at `address` as the flash holds them.
    fn page(&self, facts: &Facts, address: u32) -> Vec<u8> {
        self.pages.get(&address).cloned().unwrap_or_else(|| vec![if self.erased { ERASED } else { 0 }; facts.page_size as usize])
    }

    /// The byte sum of `len` bytes of flash from `from`.
    fn sum(&self, facts: &Facts, from: u32, len: u32) -> u32 {
        let page = facts.page_size;
        let blank = u32::from(if self.erased { ERASED } else { 0 });
        let mut total = 0u32;
        let mut at = from;
        let end = from.saturating_add(len);
        while at < end {
            let base = at / page * page;
            let upto = (base + page).min(end);
            total = total.wrapping_add(match self.pages.get(&base) {
                Some(bytes) => bytes[(at - base) as usize..(upto - base) as usize].iter().map(|&b| u32::from(b)).sum(),
                None => blank.wrapping_mul(upto - at),
            });
            at = upto;
        }
        total
    }
}

/// Bytes of the firmware images tmclsim makes.
pub const IMAGE_BYTES: usize = 16 * 1024;

/// Where in an image its version string stands.
pub const IMAGE_VERSION_AT: usize = 0x200;

/// A firmware image for the module whose bootloader `facts` describes, of
/// `version`: the bytes from `facts.flash_start` (docs/behaviour.md rule
/// 103). It is not code: bytes that vary (the same for the same version),
/// with the version string as update tools look for it
/// ([`Facts::image_version_text`]) at [`IMAGE_VERSION_AT`].
pub fn image(facts: &Facts, version: [u8; 2]) -> Vec<u8> {
    let mut x = 0x2545_F491u32 ^ (u32::from(version[0]) << 8 | u32::from(version[1]));
    let mut bytes: Vec<u8> = (0..IMAGE_BYTES)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x >> 24) as u8
        })
        .collect();
    let text = facts.image_version_text(version);
    bytes[IMAGE_VERSION_AT..IMAGE_VERSION_AT + text.len()].copy_from_slice(text.as_bytes());
    bytes
}

#[cfg(test)]
mod tests {
    use super::{Refused, Session};
    use tmclsim_profile::Profile;

    fn facts() -> tmclsim_profile::Bootloader {
        Profile::built_in("tmcm-1141").unwrap().bootloader.clone().expect("the TMCM-1141 has a bootloader")
    }

    /// Writes `image` from the firmware's start as an update tool does:
    /// words into the buffer, a page write after each page.
    fn write(s: &mut Session, f: &tmclsim_profile::Bootloader, image: &[u8]) {
        let page = f.page_size as usize;
        for (n, chunk) in image.chunks(page).enumerate() {
            for (i, w) in chunk.chunks(4).enumerate() {
                let mut word = [0u8; 4];
                word[..w.len()].copy_from_slice(w);
                s.write_buffer(i as u32, u32::from_le_bytes(word)).unwrap();
            }
            s.write_page(f, f.flash_start + (n * page) as u32).unwrap();
        }
    }

    #[test]
    fn an_erased_and_written_image_is_complete_when_length_and_checksum_match() {
        let f = facts();
        let mut image = vec![7u8; 5000];
        image[100..108].copy_from_slice(b"1141V147");
        let sum: u32 = image.iter().map(|&b| u32::from(b)).sum();
        let mut s = Session::new(&f, false);
        s.erase(&f);
        write(&mut s, &f, &image);
        assert_eq!(s.checksum_through(&f, f.flash_start + 4999), Ok(sum));
        assert_eq!(s.complete_firmware(&f), None, "no length and checksum yet");
        s.write_length(&f, 0, 5000).unwrap();
        s.write_length(&f, 1, sum.wrapping_add(1)).unwrap();
        assert_eq!(s.complete_firmware(&f), None, "a checksum that does not match");
        s.write_length(&f, 1, sum).unwrap();
        assert_eq!(s.complete_firmware(&f), Some([1, 47]));
        assert_eq!(s.read_word(&f, f.flash_start + 100), Ok(u32::from_le_bytes(*b"1141")));
    }

    #[test]
    fn writing_without_an_erase_does_not_give_the_image() {
        let f = facts();
        let mut image = vec![0xA5u8; 64];
        image[..8].copy_from_slice(b"1141V147");
        let mut s = Session::new(&f, false);
        write(&mut s, &f, &image);
        let sum: u32 = image.iter().map(|&b| u32::from(b)).sum();
        assert_ne!(s.checksum_through(&f, f.flash_start + 63), Ok(sum));
    }

    #[test]
    fn addresses_outside_the_flash_or_the_page_are_refused() {
        let f = facts();
        let mut s = Session::new(&f, true);
        assert_eq!(s.write_buffer(f.page_size / 4, 1), Err(Refused::Value));
        assert_eq!(s.write_page(&f, f.flash_start - f.page_size), Err(Refused::Value));
        assert_eq!(s.write_page(&f, f.flash_start + 4), Err(Refused::Value));
        assert_eq!(s.write_page(&f, f.flash_start + f.flash_size), Err(Refused::Value));
        assert_eq!(s.checksum_through(&f, f.flash_start + f.flash_size), Err(Refused::Value));
        assert_eq!(s.write_length(&f, 0, f.flash_size + 1), Err(Refused::Value));
        assert_eq!(s.write_length(&f, 2, 1), Err(Refused::Type));
        assert_eq!(s.checksum_through(&f, f.flash_start + 9), Ok(10 * 0xFF), "erased flash reads 0xFF");
    }
}
