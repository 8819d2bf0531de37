//! The world control protocol (docs/world.md) on any module: the server's
//! own `control::execute` does the work, so the commands and their answers
//! are the same as on a served module's control socket.
//!
//! `control::execute` works on a `SharedModule`. For a module that is not
//! the first one of a served link (or not served at all), the module is
//! lent for the command to a private `SharedModule` in stepped time, where
//! time stands still, and taken back afterwards.

use std::sync::Arc;
use tmclsim_firmware::Module;
use tmclsim_server::{SharedModule, control};

/// Whether a control line changes the link rather than a module's world.
fn is_link_command(line: &str) -> bool {
    matches!(line.split_whitespace().next(), Some("link") | Some("help"))
}

/// Runs one control line on a module that has no pending events (the
/// private link would drop them).
pub fn on_module(module: &mut Module, line: &str) -> Result<String, String> {
    if line.split_whitespace().next() == Some("link") {
        return Err("link faults need a link: serve the module and use the server's world() or link_faults()".into());
    }
    debug_assert!(!module.has_events());
    let private = SharedModule::new(Module::new(module.profile().clone()), None);
    private.set_stepped(true);
    private.with(|lent| std::mem::swap(lent, module));
    let answer = control::execute(&private, line);
    private.with(|lent| std::mem::swap(lent, module));
    answer
}

/// Runs one control line on module `index` of a served link.
pub fn on_served(shared: &Arc<SharedModule>, index: usize, line: &str) -> Result<String, String> {
    if index == 0 || is_link_command(line) {
        return control::execute(shared, line);
    }
    loop {
        // Events that are due go out on the link first (the server sends
        // them when the closure returns); then the module is lent.
        let done = shared.with_module(index, |m| if m.has_events() { None } else { Some(on_module(m, line)) });
        if let Some(answer) = done {
            return answer;
        }
    }
}
