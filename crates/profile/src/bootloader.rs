//! The `[bootloader]` table of a profile: what the module's TMCL
//! bootloader says of itself and where it puts the firmware
//! (docs/behaviour.md rules 99–103).

use serde::Deserialize;

/// A module's bootloader facts. Values no public source gives are marked
/// assumed in the profile (its `sources`).
#[derive(Clone, Debug, Deserialize, PartialEq, Eq)]
#[serde(deny_unknown_fields)]
pub struct Bootloader {
    /// The 8 characters of its 136 type 0 reply: the module number, `B`,
    /// the bootloader's version (`1141B106`; `351B1.02` on a module with a
    /// three-digit number).
    pub version_text: String,
    /// Bytes of a flash page (BOOT_GET_INFO type 0).
    pub page_size: u32,
    /// Where the firmware starts in flash (BOOT_GET_INFO type 1).
    pub flash_start: u32,
    /// Bytes of flash for the firmware (BOOT_GET_INFO type 2).
    pub flash_size: u32,
    /// The module address the bootloader answers, whatever GP 66 says.
    pub address: u8,
    /// The baud rate of its serial interfaces, whatever GP 65 says.
    pub baud: u32,
    /// Where each value comes from.
    pub sources: String,
}

impl Bootloader {
    /// Why these facts cannot be used, if they cannot.
    pub fn problem(&self) -> Option<String> {
        if self.version_text.len() != 8 || !self.version_text.is_ascii() || !self.version_text.contains('B') {
            return Some(format!("bootloader.version_text '{}' is not 8 ASCII characters with a B", self.version_text));
        }
        if !self.page_size.is_power_of_two() || self.page_size < 4 {
            return Some(format!("bootloader.page_size {} is not a power of two of at least 4", self.page_size));
        }
        if !self.flash_start.is_multiple_of(self.page_size) || !self.flash_size.is_multiple_of(self.page_size) || self.flash_size == 0 {
            return Some("bootloader.flash_start and flash_size are whole pages, and the flash has at least one".into());
        }
        if self.flash_start.checked_add(self.flash_size).is_none() {
            return Some("bootloader.flash_start + flash_size passes 2^32".into());
        }
        None
    }

    /// The digits that name the module in the bootloader's text (`1141`,
    /// `351`): what precedes the `B`.
    pub fn module_digits(&self) -> &str {
        self.version_text.split('B').next().unwrap_or_default()
    }

    /// The version string a firmware image for this module carries, as
    /// update tools look for it (the bootloader's form: `1141V147` beside
    /// `1141B106`, `351V4.45` beside `351B1.02`).
    pub fn image_version_text(&self, version: [u8; 2]) -> String {
        let digits = self.module_digits();
        if digits.len() == 4 {
            format!("{digits}V{}{:02}", version[0] % 10, version[1] % 100)
        } else {
            format!("{digits}V{}.{:02}", version[0] % 10, version[1] % 100)
        }
    }

    /// The firmware version an image's bytes carry: the first version
    /// string of this module's form found in them (`None`: the image is
    /// not this module's firmware).
    pub fn find_version(&self, image: &[u8]) -> Option<[u8; 2]> {
        let head = self.module_digits().as_bytes();
        let four = head.len() == 4;
        let len = head.len() + if four { 4 } else { 5 };
        image.windows(len).find_map(|w| {
            let tail = &w[head.len()..];
            if &w[..head.len()] != head || tail[0] != b'V' {
                return None;
            }
            let d = |b: u8| b.is_ascii_digit().then(|| b - b'0');
            if four {
                Some([d(tail[1])?, d(tail[2])? * 10 + d(tail[3])?])
            } else {
                (tail[2] == b'.').then_some(())?;
                Some([d(tail[1])?, d(tail[3])? * 10 + d(tail[4])?])
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::Bootloader;

    fn facts(text: &str) -> Bootloader {
        Bootloader {
            version_text: text.into(),
            page_size: 2048,
            flash_start: 0x0800_4000,
            flash_size: 0x1_C000,
            address: 1,
            baud: 115_200,
            sources: String::new(),
        }
    }

    #[test]
    fn the_image_carries_the_version_in_the_form_of_the_bootloaders_text() {
        assert_eq!(facts("1141B106").image_version_text([1, 47]), "1141V147");
        assert_eq!(facts("351B1.02").image_version_text([4, 45]), "351V4.45");
        assert_eq!(facts("1310B100").image_version_text([1, 5]), "1310V105");
    }

    #[test]
    fn the_version_is_found_anywhere_in_an_image_of_this_module_only() {
        let b = facts("1141B106");
        assert_eq!(b.find_version(b"\x00\xffxx1141V147yy"), Some([1, 47]));
        assert_eq!(b.find_version(b"1141V1x7 1141V200"), Some([2, 0]));
        assert_eq!(b.find_version(b"6110V147"), None, "another module's image");
        let b = facts("351B1.02");
        assert_eq!(b.find_version(b"..351V4.45.."), Some([4, 45]));
        assert_eq!(b.find_version(b"351V.445"), None, "not the form update tools look for");
    }

    #[test]
    fn unusable_facts_are_named() {
        assert!(facts("1141V106").problem().unwrap().contains("with a B"));
        assert!(Bootloader { page_size: 1000, ..facts("1141B106") }.problem().unwrap().contains("power of two"));
        assert!(Bootloader { flash_start: 0x0800_4001, ..facts("1141B106") }.problem().unwrap().contains("whole pages"));
        assert_eq!(facts("1141B106").problem(), None);
    }
}
