//! Reading the files a user hands tmclsim (world files, fleet files,
//! program binaries, symbol files) with a size limit: a file larger than
//! its limit, or one that never ends (`/dev/zero`), is refused with a
//! message instead of being read into memory (docs/robustness.md lists
//! the limits). The firmware parses what is read here and reads nothing
//! itself.

use std::io::Read;
use std::path::Path;
use tmclsim_firmware::World;

/// Configuration files: world, fleet and symbol files.
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;
/// Program binaries (8 bytes per instruction; far more than any module's
/// program memory).
pub const MAX_BINARY_BYTES: u64 = 1 << 20;

/// Reads at most `limit` bytes of a file; `what` names the kind of file in
/// the message when it is larger.
pub fn read_limited(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    if bytes.len() as u64 > limit {
        return Err(format!("{}: larger than {}, the limit for {what}", path.display(), size_text(limit)));
    }
    Ok(bytes)
}

/// [`read_limited`] for a text file (UTF-8).
pub fn read_text_limited(path: &Path, limit: u64, what: &str) -> Result<String, String> {
    let bytes = read_limited(path, limit, what)?;
    String::from_utf8(bytes).map_err(|e| format!("{}: not UTF-8 text ({e})", path.display()))
}

/// The world a front end names: `stage` (the built-in linear stage),
/// `free` (no switches, no end stops), TOML text (anything with a line
/// break) or the path of a TOML file.
pub fn world_named(spec: &str, axes: usize) -> Result<World, String> {
    if let Some(world) = World::built_in(spec, axes) {
        return Ok(world);
    }
    match spec {
        text if text.contains('\n') => World::from_toml(text, axes),
        path if !Path::new(path).exists() => {
            Err(format!("{path}: no such world file; the built-in worlds are stage (the default) and free"))
        }
        path => load_world(Path::new(path), axes),
    }
}

/// Reads a world file (at most [`MAX_CONFIG_BYTES`]) for a module with
/// `axes` axes; the errors name the file.
pub fn load_world(path: &Path, axes: usize) -> Result<World, String> {
    let text = read_text_limited(path, MAX_CONFIG_BYTES, "a world file")?;
    World::from_toml(&text, axes).map_err(|e| format!("{}: {e}", path.display()))
}

/// A byte count for messages: "1 MiB", "512 KiB", "100 bytes".
pub fn size_text(bytes: u64) -> String {
    if bytes >= 1 << 20 && bytes.is_multiple_of(1 << 20) {
        format!("{} MiB", bytes >> 20)
    } else if bytes >= 1 << 10 && bytes.is_multiple_of(1 << 10) {
        format!("{} KiB", bytes >> 10)
    } else {
        format!("{bytes} bytes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_within_its_limit_is_read_whole() {
        let dir = std::env::temp_dir().join(format!("tmclsim-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("w.toml");
        std::fs::write(&path, b"0123456789").unwrap();
        assert_eq!(read_limited(&path, 10, "a test file").unwrap(), b"0123456789");
        let e = read_limited(&path, 9, "a test file").unwrap_err();
        assert!(e.ends_with("w.toml: larger than 9 bytes, the limit for a test file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_endless_file_is_refused_not_read() {
        let e = read_text_limited(Path::new("/dev/zero"), MAX_CONFIG_BYTES, "a world file").unwrap_err();
        assert_eq!(e, "/dev/zero: larger than 1 MiB, the limit for a world file");
        assert!(read_limited(Path::new("/nonexistent/x"), 10, "x").unwrap_err().starts_with("/nonexistent/x: "));
    }

    #[test]
    fn a_world_by_name_text_or_file() {
        assert_eq!(world_named("stage", 1).unwrap(), World::stage(1));
        assert_eq!(world_named("free", 3).unwrap(), World::free(3));
        assert_eq!(world_named("supply = 12.5\n", 1).unwrap().supply_decivolts, 125);
        let e = world_named("/nonexistent/w.toml", 1).unwrap_err();
        assert_eq!(e, "/nonexistent/w.toml: no such world file; the built-in worlds are stage (the default) and free");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("w.toml");
        std::fs::write(&path, "supply = 30\n").unwrap();
        assert_eq!(world_named(path.to_str().unwrap(), 1).unwrap().supply_decivolts, 300);
        std::fs::write(&path, "supply = 1000\n").unwrap();
        assert!(load_world(&path, 1).unwrap_err().starts_with(&format!("{}: ", path.display())));
    }

    #[test]
    fn sizes_read_as_people_write_them() {
        assert_eq!(size_text(1 << 20), "1 MiB");
        assert_eq!(size_text(4096), "4 KiB");
        assert_eq!(size_text(100), "100 bytes");
    }
}
