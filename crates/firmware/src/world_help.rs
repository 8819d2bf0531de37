//! The commands of the world control protocol (docs/world.md) in words:
//! what `help` answers and what an unknown command's error lists.

/// The `help` answer of the control protocol: every world and link command.
pub const HELP: &str = "commands: [@ADDRESS] input N 0|1 | analog N VALUE | supply VOLTS | temperature CELSIUS | \
switch AXIS left|right|home press|release|auto | place AXIS left|right POSITION [WIDTH] | place AXIS home FROM TO | \
place AXIS carriage POSITION | reset | power cycle | travel AXIS FROM TO | load AXIS TORQUE [FROM TO] | fault AXIS short-a|short-b|open-a|open-b on|off | \
link drop N | link corrupt N | link delay MS | link mute on|off | link clear | show [AXIS] | help";

/// The commands of [`HELP`], one per item, without the `[@ADDRESS]`
/// that any of them may start with (for a help page that lists them a
/// line each).
pub fn help_items() -> impl Iterator<Item = &'static str> {
    HELP.trim_start_matches("commands: [@ADDRESS] ").split(" | ")
}
