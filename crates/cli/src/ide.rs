//! `tmclsim ide`: the browser IDE against modules on a TMCL link (a real
//! module's serial port, a serial-to-Ethernet bridge, or a tmclsim server),
//! polled over TMCL as a host polls them. `tmclsim serve --web` serves the
//! same app beside virtual modules.

use std::process::ExitCode;
use std::sync::Arc;

#[derive(clap::Args)]
pub struct IdeArgs {
    #[command(flatten)]
    pub link: crate::client::Link,
    /// The module addresses on the link (an RS485 bus has several); those that do not answer are named and left out.
    #[arg(long, value_name = "A,B,…", default_value = "1", value_delimiter = ',', conflicts_with = "scan")]
    pub bus_addresses: Vec<u8>,
    /// Ask every address 1…255 (136) and list each module that answers.
    #[arg(long)]
    pub scan: bool,
    /// Where the app listens.
    #[arg(long, value_name = "ADDR", default_value = tmclsim_web::DEFAULT_ADDR, value_parser = crate::socket_address)]
    pub web: std::net::SocketAddr,
    /// Allow --web on a non-loopback address; every request then needs the token printed at start.
    #[arg(long)]
    pub web_public: bool,
    /// How long to wait for each reply, in milliseconds.
    #[arg(long, value_name = "MS", default_value_t = 1000)]
    pub timeout: u64,
}

pub fn run(args: IdeArgs) -> Result<ExitCode, String> {
    let probe = if args.scan { tmclsim_web::Probe::Scan } else { tmclsim_web::Probe::Addresses(&args.bus_addresses) };
    let target = tmclsim_web::LinkTarget::open(
        args.link.tcp.as_deref(),
        args.link.port.as_deref(),
        args.link.baud,
        probe,
        crate::millis(args.timeout),
    )?;
    for a in target.missing() {
        eprintln!("tmclsim ide: no module answered at address {a}: left out");
    }
    use tmclsim_web::Target;
    let names: Vec<String> = target.modules().iter().map(|m| format!("{} at address {}", m.firmware, m.address)).collect();
    let link = target.describe();
    let signals = crate::signal::Signals::install()?;
    let web = start(target, args.web, args.web_public)?;
    println!("tmclsim ide: {} on {link}", names.join(", "));
    println!("open: {}", web.url());
    use std::io::Write;
    let _ = std::io::stdout().flush();
    signals.wait();
    println!("tmclsim ide: stopping");
    drop(web);
    Ok(ExitCode::SUCCESS)
}

/// Starts the app over `target`, with the warning a public bind deserves.
pub fn start(target: Arc<dyn tmclsim_web::Target>, addr: std::net::SocketAddr, public: bool) -> Result<tmclsim_web::WebHandle, String> {
    let web = tmclsim_web::start(target, tmclsim_web::WebConfig { addr, public, limits: Default::default() }).map_err(|e| e.to_string())?;
    if web.token().is_some() {
        eprintln!(
            "tmclsim: warning: the IDE listens on {}, reachable from other machines; requests need the token in the URL below",
            web.addr()
        );
    }
    Ok(web)
}

/// `--web`: the browser IDE over the served modules; prints its URL.
pub(crate) fn start_web(args: &crate::ServeArgs, links: &[tmclsim_server::LinkHandle]) -> Result<Option<tmclsim_web::WebHandle>, String> {
    let Some(addr) = args.web else { return Ok(None) };
    let target = Arc::new(tmclsim_web::VirtualTarget::new(links).with_frame_log(args.log_frames));
    let web = start(target, addr, args.web_public)?;
    println!("  web: {}  (the browser IDE)", web.url());
    Ok(Some(web))
}
