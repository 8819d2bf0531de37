//! `tmclsim firmware`: firmware images for a module's bootloader
//! (docs/behaviour.md rules 99–103).

use std::path::PathBuf;
use std::process::ExitCode;
use tmclsim_firmware::Profile;

#[derive(clap::Args)]
pub struct FirmwareArgs {
    #[command(subcommand)]
    pub command: FirmwareCommand,
}

#[derive(clap::Subcommand)]
pub enum FirmwareCommand {
    /// Write an Intel HEX firmware image that a module's bootloader takes (PyTrinamic's tmclfwupload, TMCL-IDE): after the update the module reports the image's version; its behaviour stays its profile's.
    Image(ImageArgs),
}

#[derive(clap::Args)]
pub struct ImageArgs {
    /// The module the image is for.
    #[arg(long, default_value = "tmcm-1141")]
    pub module: String,
    /// The firmware version the image carries, e.g. 1.47 (default: the profile's).
    #[arg(long, value_name = "V")]
    pub version: Option<String>,
    /// The file to write (Intel HEX).
    #[arg(short = 'o', long = "out", value_name = "FILE.hex")]
    pub out: PathBuf,
}

pub fn run(args: FirmwareArgs) -> Result<ExitCode, String> {
    match args.command {
        FirmwareCommand::Image(a) => image(a),
    }
}

fn image(args: ImageArgs) -> Result<ExitCode, String> {
    let profile = Profile::built_in(&args.module)?;
    let Some(facts) = profile.bootloader.as_ref() else {
        let with: Vec<&str> = Profile::names().into_iter().filter(|n| Profile::built_in(n).is_ok_and(|p| p.bootloader.is_some())).collect();
        return Err(format!(
            "the {} profile has no bootloader, so there is no firmware image for it (modules with one: {})",
            profile.module.name,
            with.join(", ")
        ));
    };
    let version = match &args.version {
        Some(text) => parse_version(text)?,
        None => profile.module.firmware,
    };
    let bytes = tmclsim_firmware::bootloader::image(facts, version);
    let text = tmclsim_host::intel_hex::encode(facts.flash_start, &bytes);
    std::fs::write(&args.out, text).map_err(|e| format!("{}: {e}", args.out.display()))?;
    println!(
        "{}: firmware image for the {}, version {} ({} bytes from {:#010X}); the module's behaviour stays its profile's",
        args.out.display(),
        profile.module.name,
        facts.image_version_text(version),
        bytes.len(),
        facts.flash_start
    );
    Ok(ExitCode::SUCCESS)
}

/// `1.47` (or `V1.47`) → [1, 47]: one digit, a point, up to two digits, as
/// a version string holds them.
fn parse_version(text: &str) -> Result<[u8; 2], String> {
    let bad = || format!("--version {text}: write MAJOR.MINOR, e.g. 1.47 (major 0…9, minor 0…99)");
    let (major, minor) = text.trim_start_matches(['V', 'v']).split_once('.').ok_or_else(bad)?;
    let major: u8 = major.parse().ok().filter(|m| *m <= 9).ok_or_else(bad)?;
    let minor: u8 = minor.parse().ok().filter(|m| *m <= 99).ok_or_else(bad)?;
    Ok([major, minor])
}

#[cfg(test)]
mod tests {
    #[test]
    fn versions_as_they_are_written() {
        assert_eq!(super::parse_version("1.47"), Ok([1, 47]));
        assert_eq!(super::parse_version("V4.5"), Ok([4, 5]));
        assert!(super::parse_version("147").is_err());
        assert!(super::parse_version("10.1").is_err());
        assert!(super::parse_version("1.100").is_err());
    }
}
