//! `tmclsim serve`.

use crate::ServeArgs;
use std::process::ExitCode;
use std::sync::Arc;
use tmclsim_firmware::{Eeprom, Module, Profile};
use tmclsim_server::ServerConfig;
use tmclsim_server::eeprom_file::EepromFile;

/// `PROFILE@ADDRESS,…` → modules on one link, in the world given.
fn bus(spec: &str, world: &str) -> Result<Vec<Module>, String> {
    let mut modules = Vec::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (name, address) = item.split_once('@').ok_or_else(|| format!("'{item}': write PROFILE@ADDRESS"))?;
        let address: u8 = address.parse().ok().filter(|a| *a >= 1).ok_or_else(|| format!("'{item}': the address is 1…255"))?;
        let profile = Profile::built_in(name)?;
        let w = crate::load_world(world, profile.module.axes as usize)?;
        let mut m = Module::with_world(profile.clone(), Eeprom::new(&profile.module.name), w);
        Module::set_address(&mut m, address);
        modules.push(m);
    }
    if modules.is_empty() {
        return Err("--bus names no module".into());
    }
    if let Some(a) = tmclsim_firmware::bus::duplicate_address(modules.iter().map(Module::address)) {
        return Err(format!("--bus: two modules at address {a} (each module of a bus has its own address)"));
    }
    Ok(modules)
}

pub fn run(args: ServeArgs) -> Result<ExitCode, String> {
    check_args(&args)?;
    if let Some(path) = &args.fleet {
        return crate::fleet::serve(path, &args);
    }
    if let Some(iface) = &args.ethercat {
        return ethercat(iface, &args);
    }
    if let Some(spec) = &args.bus {
        let modules = bus(spec, &args.world)?;
        return serve(args_links(&args), modules, None, "factory defaults for every module of the bus".into(), &args);
    }
    let profile = Profile::built_in(&args.module)?;
    let key = profile.module.name.to_ascii_lowercase();
    let (tcp, pty) = match (args.tcp, args.pty.clone()) {
        (None, None) if args.serial.is_empty() => (Some("127.0.0.1:1141".parse().unwrap()), default_pty(format!("tmclsim-{key}"))),
        other => other,
    };
    let world = crate::load_world(&args.world, profile.module.axes as usize)?;
    // The file is this server's until it stops: a second one is refused.
    let file = args.eeprom.as_deref().map(EepromFile::open).transpose()?.map(Arc::new);
    // `existed`: the file was there (only a missing file means factory
    // defaults; any other error reading it stops the start, rule 89).
    let (image, existed, eeprom_note) = match &file {
        Some(f) => match f.load_for(&profile)? {
            (image, true) => (image, true, format!("restored from {}{}", f.named().display(), read_only_note(f))),
            (image, false) => (image, false, format!("factory defaults; changes are kept in {} (new)", f.named().display())),
        },
        None => (Eeprom::new(&profile.module.name), false, "factory defaults; changes are lost at exit (no --eeprom FILE)".to_string()),
    };
    let module = Module::with_world(profile.clone(), image, world);
    let mut module = module;
    if let Some(a) = args.address {
        Module::set_address(&mut module, a);
    }
    if let Some(f) = &file {
        // Write the file at once so a fresh one exists from the start.
        if !existed {
            f.save(module.eeprom()).map_err(|e| format!("{}: {e}", f.named().display()))?;
        }
    }
    serve((tcp, pty), vec![module], file, eeprom_note, &args)
}

/// Refusals before anything is opened (docs/robustness.md).
fn check_args(args: &ServeArgs) -> Result<(), String> {
    if args.web.is_some() && args.ethercat.is_some() {
        return Err(
            "--web cannot serve EtherCAT slaves: the IDE reaches modules by TMCL requests, and EtherCAT slaves answer their master; \
                    serve the module on --tcp/--pty with --web, or run `tmclsim ide` against a TMCL link"
                .into(),
        );
    }
    if args.max_connections == 0 {
        return Err("--max-connections 0 would serve no client: give 1 or more".into());
    }
    if !args.control.ip().is_loopback() && !args.control_public {
        return Err(format!(
            "--control {}: not a loopback address; the control socket changes the world, mutes links and injects faults, \
             so it is opened to other machines only with --control-public (clients then need the token printed at start)",
            args.control
        ));
    }
    // What this system cannot serve (a pty, SLCAN and EtherCAT on Windows).
    crate::platform::check_serve(args)?;
    Ok(())
}

/// A fresh random token for the control socket (128 bits, hex).
fn control_token() -> Result<String, String> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).map_err(|e| format!("cannot make a control token: {e}"))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// EtherCAT: TMCM-1310 slaves on a network interface.
fn ethercat(iface: &str, args: &ServeArgs) -> Result<ExitCode, String> {
    let profile = Profile::built_in(&args.module)?;
    // Refused before any EEPROM file is opened.
    tmclsim_ethercat::Identity::required(&profile)?;
    if args.slaves == 0 || args.slaves > 256 {
        return Err("--slaves takes 1…256".into());
    }
    // --eeprom FILE: the one slave's EEPROM, or FILE.1, FILE.2, … for several.
    let eeproms: Vec<Option<std::path::PathBuf>> = (0..args.slaves)
        .map(|i| {
            args.eeprom
                .as_ref()
                .map(|f| if args.slaves == 1 { f.clone() } else { std::path::PathBuf::from(format!("{}.{}", f.display(), i + 1)) })
        })
        .collect();
    let eeproms = eeproms.iter().map(|p| p.as_deref().map(EepromFile::open).transpose()).collect::<Result<Vec<_>, _>>()?;
    let modules = eeproms
        .iter()
        .map(|file| {
            let world = crate::load_world(&args.world, 1)?;
            let image = match file {
                Some(f) => {
                    let image = f.load_for(&profile)?.0;
                    // The warning; EtherCAT prints no EEPROM line to add the note to.
                    let _ = read_only_note(f);
                    image
                }
                None => Eeprom::new(&profile.module.name),
            };
            Ok(Module::with_world(profile.clone(), image, world))
        })
        .collect::<Result<Vec<_>, String>>()?;
    let mut segment = tmclsim_ethercat::Segment::new(modules)?;
    segment.bus.set_speed(args.speed);
    let signals = crate::signal::Signals::install()?;
    let handle = tmclsim_server::ethercat::serve(iface, segment, eeproms).map_err(|e| format!("cannot serve EtherCAT on {iface}: {e}"))?;
    println!("tmclsim: {} virtual {} EtherCAT slave(s) on {iface}", args.slaves, profile.module.name);
    println!("connect with: an EtherCAT master on {iface}'s peer, e.g. pysoem: master.open(\"<peer interface>\")");
    use std::io::Write;
    let _ = std::io::stdout().flush();
    signals.wait();
    println!("tmclsim: stopping");
    handle.stop();
    Ok(ExitCode::SUCCESS)
}

/// A read-only EEPROM file is served, never replaced (docs/behaviour.md
/// rule 89): a warning on stderr, and a note for the banner ("" for a
/// file tmclsim may write).
fn read_only_note(file: &EepromFile) -> String {
    let Some(why) = file.read_only() else { return String::new() };
    eprintln!(
        "tmclsim: warning: {}: {why}; EEPROM writes are answered with status 5 and the file is left as it is \
         (make it writable to keep changes)",
        file.named().display()
    );
    " (read-only: EEPROM writes answer status 5, the file stays as it is)".to_string()
}

/// The pty served when no link is named: `NAME` in the directory for
/// temporary files, where there are ptys (not on Windows: TCP only).
fn default_pty(name: String) -> Option<std::path::PathBuf> {
    crate::platform::PTY_REFUSED.is_none().then(|| std::env::temp_dir().join(name))
}

/// The links to serve: both defaults when no link is named.
fn args_links(args: &ServeArgs) -> (Option<std::net::SocketAddr>, Option<std::path::PathBuf>) {
    match (args.tcp, args.pty.clone()) {
        (None, None) if args.serial.is_empty() => (Some("127.0.0.1:1141".parse().unwrap()), default_pty("tmclsim-bus".into())),
        other => other,
    }
}

fn serve(
    (tcp, pty): (Option<std::net::SocketAddr>, Option<std::path::PathBuf>),
    modules: Vec<Module>,
    eeprom: Option<Arc<EepromFile>>,
    eeprom_note: String,
    args: &ServeArgs,
) -> Result<ExitCode, String> {
    let config = ServerConfig {
        tcp,
        pty,
        serial: args.serial.iter().map(|device| tmclsim_server::SerialLine { device: device.clone(), baud: args.baud }).collect(),
        eeprom,
        inter_byte_timeout: crate::millis(args.inter_byte_timeout),
        max_connections: args.max_connections,
        bad_frame_limit: args.bad_frame_limit,
        control: Some(args.control),
        control_token: if args.control_public { Some(control_token()?) } else { None },
        wire_timing: args.wire_timing,
        speed: args.speed,
        slcan: args.slcan.clone(),
        log_frames: args.log_frames,
        ..ServerConfig::default()
    };
    let token = config.control_token.clone();
    let names: Vec<String> = modules.iter().map(|m| format!("{} (address {})", m.profile().module.name, m.address())).collect();
    let addresses: Vec<(u8, String)> = modules.iter().map(|m| (m.address(), m.profile().module.name.clone())).collect();
    let signals = crate::signal::Signals::install()?;
    let server = tmclsim_server::start_bus(modules, config).map_err(|e| format!("cannot serve: {e}"))?;
    let ep = server.endpoints().clone();
    println!("tmclsim: virtual {} is serving", names.join(", "));
    println!("  EEPROM: {eeprom_note}");
    for line in tmclsim_server::bootloader_lines(server.links()) {
        println!("  {line}");
    }
    if let Some(addr) = ep.tcp {
        println!("  tcp: {addr}");
    }
    if let Some((link, device)) = &ep.pty {
        println!("  pty: {} -> {}", link.display(), device.display());
    }
    for (device, baud) in &ep.serial {
        println!("  serial: {device} at {baud} baud, 8N1 (host software opens the other end of the line)");
    }
    if let Some((link, device)) = &ep.slcan {
        println!("  slcan: {} -> {}  (CAN adapter: python-can interface \"slcan\")", link.display(), device.display());
    }
    println!("  world: {}{}", args.world, if args.wire_timing { "; wire timing on" } else { "" });
    if args.speed != tmclsim_firmware::Speed::REAL_TIME {
        println!("  time: {} times as fast as the wall clock", args.speed.factor());
    }
    match (ep.control, &token) {
        (Some(addr), None) => println!("  control: {addr}  (tmclsim world --control {addr} help)"),
        (Some(addr), Some(t)) => {
            println!("  control: {addr}  token {t}  (send \"auth {t}\" first: tmclsim world --control {addr} auth {t} help)");
        }
        (None, _) => {}
    }
    if let Some(path) = &args.endpoints {
        write_endpoints(path, &ep, token.as_deref())?;
    }
    if let Some((link, _)) = &ep.slcan {
        let (first, _) = &addresses[0];
        println!(
            "  over CAN: pytrinamic ConnectionManager(\"--interface slcan_tmcl --port {} --data-rate 1000000 --module-id {first}\")",
            link.display()
        );
    }
    if addresses.len() > 1 {
        let (a, _) = &addresses[1];
        println!(
            "  a bus: each module answers its own address; PyTrinamic reaches module {a} with --module-id {a} in the ConnectionManager arguments, or module_id={a} in its module class"
        );
    }
    let web = crate::ide::start_web(args, server.links())?;
    if let Some(a) = ep.pytrinamic_args() {
        println!("connect with: pytrinamic ConnectionManager(\"{a}\")  (or: tmclsim send {} GAP 1, 0)", send_target(&ep));
    } else if let Some(hint) = ep.serial_hint() {
        println!("connect with: {hint}");
    }
    use std::io::Write;
    let _ = std::io::stdout().flush();
    signals.wait();
    drop(web);
    if let Some(path) = &args.endpoints {
        let _ = std::fs::remove_file(path);
    }
    println!("tmclsim: stopping");
    server.stop();
    Ok(ExitCode::SUCCESS)
}

fn send_target(ep: &tmclsim_server::Endpoints) -> String {
    match (&ep.tcp, &ep.pty) {
        (Some(a), _) => format!("--tcp {a}"),
        (None, Some((link, _))) => format!("--port {}", link.display()),
        _ => String::new(),
    }
}

/// `--endpoints FILE`: where the server listens, as TOML, for scripts.
fn write_endpoints(path: &std::path::Path, ep: &tmclsim_server::Endpoints, token: Option<&str>) -> Result<(), String> {
    let mut table = toml::Table::new();
    let mut put = |key: &str, value: Option<String>| {
        if let Some(v) = value {
            table.insert(key.into(), v.into());
        }
    };
    put("tcp", ep.tcp.map(|a| a.to_string()));
    put("pty", ep.pty.as_ref().map(|(link, _)| link.display().to_string()));
    put("slcan", ep.slcan.as_ref().map(|(link, _)| link.display().to_string()));
    put("control", ep.control.map(|a| a.to_string()));
    put("control_token", token.map(str::to_string));
    if !ep.serial.is_empty() {
        table.insert("serial".into(), ep.serial.iter().map(|(device, _)| toml::Value::from(device.as_str())).collect::<Vec<_>>().into());
    }
    std::fs::write(path, table.to_string()).map_err(|e| format!("{}: {e}", path.display()))
}
