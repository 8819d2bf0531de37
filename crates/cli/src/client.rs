//! Where a module is, as the command line names it: `--tcp` or `--port`,
//! and its address. The link itself is `tmclsim_host::Client`.

use std::sync::Arc;
use std::time::Duration;
use tmclsim_firmware::Profile;
pub use tmclsim_host::{Client, LinkError, hex};
use tmclsim_protocol::{Instruction, opcode};

/// A link to modules (a tmclsim server or real ones): TCP or a serial port.
#[derive(clap::Args)]
pub struct Link {
    /// TCP address of the module (a tmclsim server or a serial-to-Ethernet bridge).
    #[arg(long, value_name = "HOST:PORT", conflicts_with = "port", required_unless_present = "port")]
    pub tcp: Option<String>,
    /// Serial port of the module (e.g. /dev/ttyACM0, or a tmclsim pty).
    #[arg(long, value_name = "DEV")]
    pub port: Option<String>,
    /// Baud rate for --port.
    #[arg(long, default_value_t = 9600)]
    pub baud: u32,
}

/// Where a module is: the link, and its address.
#[derive(clap::Args)]
pub struct LinkArgs {
    #[command(flatten)]
    pub link: Link,
    /// Module address.
    #[arg(long, default_value_t = 1)]
    pub address: u8,
}

impl LinkArgs {
    pub fn open(&self, timeout: Duration) -> Result<Client, LinkError> {
        let l = &self.link;
        Client::open(l.tcp.as_deref(), l.port.as_deref(), l.baud, self.address, timeout)
    }
}

/// The profile named, or the one of the type the module reports.
pub fn profile(client: &mut Client, named: Option<&str>) -> Result<Option<Arc<Profile>>, String> {
    if let Some(name) = named {
        return Ok(Some(Profile::built_in(name)?));
    }
    let reply = client.request(Instruction::new(opcode::FIRMWARE_VERSION, 1, 0, 0))?;
    let type_number = (reply.value as u32) >> 16;
    match Profile::built_in(&format!("tmcm-{type_number}")) {
        Ok(p) => Ok(Some(p)),
        Err(_) => {
            println!("module type {type_number} has no profile in tmclsim: parameters by number only (--module names one)");
            Ok(None)
        }
    }
}
