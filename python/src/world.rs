//! The world control protocol (docs/world.md) on a module of a bus: the
//! line is parsed into a typed world command and applied through the bus,
//! exactly as the control socket of a served link does.

use tmclsim_firmware::world_command::Addressed;
use tmclsim_host::SharedBus;
use tmclsim_host::shared::execute;

/// Runs one control line on module `index` of a bus (`@ADDRESS` picks
/// another module of the same bus). `link …` needs a served link.
pub fn run(shared: &SharedBus, index: usize, line: &str, served: bool) -> Result<String, String> {
    match line.split_whitespace().next() {
        Some("link") if !served => Err("link faults need a link: serve the module and use the server's world() or link_faults()".into()),
        Some("link" | "help") | None => execute(shared, line).map_err(String::from),
        Some(_) => {
            let Addressed { address, command } = Addressed::parse(line)?;
            match address {
                Some(_) => shared.apply_world(address, &command).map_err(String::from),
                None => shared.with_module(index, |m| command.apply(m)).map_err(String::from),
            }
        }
    }
}
