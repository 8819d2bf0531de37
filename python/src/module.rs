//! `Module`: one virtual TMCL module.
//!
//! The module lives on a bus (`tmclsim_host::SharedBus`, a bus of one
//! unless it was put on a `Bus`), as every front end's module does: the
//! bus's clock is stepped in process (virtual time stands still between
//! `advance` calls) and follows the wall clock while a `Server` serves it
//! in real time; the bus writes the EEPROM file.

use crate::advance::advance_in_slices;
use crate::asm::{Program, program_from};
use crate::errors::{catch, guard, internal_error, os_error, tmcl_error, value_error};
use crate::types::{Registers, Reply, ReplyKind, command_from};
use crate::world;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyInt, PyList, PyString};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use tmclsim_firmware::Bus;
use tmclsim_firmware::module::gp::SERIAL_ADDRESS;
use tmclsim_firmware::profile::Parameter;
use tmclsim_firmware::program::RunMode;
use tmclsim_firmware::{Eeprom, Module as FwModule, Profile, World};
use tmclsim_host::SharedBus;
use tmclsim_host::eeprom_file::{EepromFile, LoadError, resolve};
use tmclsim_host::names::{Names, snake};
use tmclsim_host::observe;
use tmclsim_protocol::{FRAME_LEN, Instruction as Ins, Request, Status, opcode};

/// A virtual TMCL module (a TMCM-1141 by default).
///
/// ``Module(profile="tmcm-1141", address=None, eeprom=None, world=None)``
///
/// - ``profile``: a built-in module profile (see ``tmclsim.profiles()``).
/// - ``address``: the module address (GP 66); None keeps the module's own
///   (1 from the factory, or what the EEPROM file holds).
/// - ``eeprom``: path of an EEPROM file (JSON). It is read when it exists
///   and rewritten atomically on every EEPROM write, as ``tmclsim serve
///   --eeprom`` does; None starts from factory defaults and keeps nothing.
///   The file is the module's while it lives: a second module or server on
///   it is refused (``OSError``). A file that cannot be read raises
///   ``OSError`` (only a missing one means factory defaults); one that
///   holds what the module never stores (a value outside its parameter's
///   range, a motor it lacks, …) raises ``ValueError`` naming the entries.
///   A read-only file is used and never replaced: EEPROM writes are
///   answered with status 5, with a ``UserWarning`` at the start.
/// - ``world``: ``"stage"`` (the built-in linear stage, the default),
///   ``"free"`` (no switches, no end stops), the path of a TOML world file,
///   or the TOML text itself (a string with a line break).
///
/// Virtual time stands still until ``advance(seconds)``: an hour of motion
/// costs milliseconds.
#[pyclass(subclass, module = "tmclsim", name = "Module")]
pub struct Module {
    /// The bus the module is on, and its place there.
    pub shared: Arc<SharedBus>,
    pub index: usize,
    /// A server serves the bus.
    pub served: bool,
    pub profile: Arc<Profile>,
    names: Names,
    pub eeprom_path: Option<PathBuf>,
    /// The EEPROM file, held (locked) while the module lives.
    pub eeprom_file: Option<Arc<EepromFile>>,
    /// Labels of the last program loaded (for breakpoints and `run`).
    symbols: BTreeMap<String, u32>,
}

impl Module {
    /// Runs `f` on the module, brought up to the bus's now; the bus then
    /// carries out what changed (EEPROM file, events).
    /// A panic inside becomes `InternalError`, never a `PanicException`.
    pub fn with<R>(&mut self, f: impl FnOnce(&mut FwModule) -> R) -> PyResult<R> {
        let (shared, index) = (&self.shared, self.index);
        catch(|| shared.with_module(index, f)).map_err(|m| Python::attach(|py| internal_error(py, m)))
    }

    pub fn is_served(&self) -> bool {
        self.served
    }

    /// Moves the module onto another bus (a `Bus` was made of it).
    pub fn move_to(&mut self, shared: Arc<SharedBus>, index: usize) {
        self.shared = shared;
        self.index = index;
    }

    /// Sends one instruction to the module's own address.
    pub fn send_instruction(&mut self, ins: Ins) -> PyResult<Option<Reply>> {
        let address = self.address_now()?;
        let reply = self.handle_frame(&Request::new(address, ins).encode())?;
        Ok(reply.map(|raw| Reply::new(raw, tmclsim_host::reply::shape(ins, address, &raw))))
    }

    /// A frame for this module; a write the EEPROM file did not take is
    /// answered with status 5 (docs/behaviour.md rule 82).
    pub fn handle_frame(&mut self, frame: &[u8; FRAME_LEN]) -> PyResult<Option<[u8; FRAME_LEN]>> {
        Ok(self.shared.module_frame(self.index, frame))
    }

    pub fn now_ns(&mut self) -> PyResult<u64> {
        self.with(|m| m.now_ns())
    }

    pub fn address_now(&mut self) -> PyResult<u8> {
        self.with(|m| m.address())
    }

    /// Moves virtual time on (in process, or a served link in stepped time).
    pub fn advance_ns(&mut self, py: Python<'_>, ns: u64) -> PyResult<()> {
        if !self.shared.is_stepped() {
            return Err(PyRuntimeError::new_err(
                "the module is served in real time: set server.stepped = True to move virtual time by hand",
            ));
        }
        advance_in_slices(py, &self.shared.clone(), ns)
    }

    fn axis_number(&self, param: &Bound<'_, PyAny>) -> PyResult<u8> {
        if let Ok(name) = param.cast::<PyString>() {
            return self.names.axis(&name.to_cow()?).map_err(value_error);
        }
        byte(param, "parameter number")
    }

    fn global_number(&self, param: &Bound<'_, PyAny>, bank: Option<u8>) -> PyResult<(u8, u8)> {
        if let Ok(name) = param.cast::<PyString>() {
            return self.names.global(&name.to_cow()?, bank).map_err(value_error);
        }
        Ok((bank.unwrap_or(0), byte(param, "parameter number")?))
    }

    /// A parameter command that failed, as `TmclError` with the reason.
    fn failed(&self, py: Python<'_>, ins: Ins, status: Status) -> PyErr {
        tmcl_error(py, status, tmclsim_host::reply::explain(ins, status, Some(&self.profile)))
    }

    fn resolve_address(&self, at: &Bound<'_, PyAny>) -> PyResult<u16> {
        if let Ok(label) = at.cast::<PyString>() {
            let label = label.to_cow()?;
            return self
                .symbols
                .get(label.as_ref())
                .map(|a| *a as u16)
                .ok_or_else(|| value_error(format!("'{label}' is not a label of the program loaded last")));
        }
        at.extract::<u16>().map_err(|_| value_error("a program address is a label or a number 0…65535"))
    }

    fn program_instruction(&mut self, py: Python<'_>, ins: Ins) -> PyResult<i32> {
        let outcome = self.with(|m| m.execute(ins))?;
        if outcome.status.is_error() {
            return Err(tmcl_error(
                py,
                outcome.status,
                format!("{}: {} (status {})", tmclsim_protocol::mnemonic::format(ins), outcome.status.describe(), outcome.status.code()),
            ));
        }
        Ok(outcome.value)
    }
}

pub fn served_error() -> PyErr {
    PyRuntimeError::new_err("the module is served: reach it through its server (or stop the server first)")
}

/// A byte from an int, with a readable error.
fn byte(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<u8> {
    if !obj.is_instance_of::<PyInt>() {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!("a {what} is an int or a name, not {}", obj.get_type().name()?)));
    }
    obj.extract::<u8>().map_err(|_| value_error(format!("a {what} is 0…255, not {obj}")))
}

/// The world a module is made with.
fn world_from(world: Option<&Bound<'_, PyAny>>, axes: usize) -> PyResult<World> {
    let Some(world) = world else { return Ok(World::stage(axes)) };
    if world.is_none() {
        return Ok(World::stage(axes));
    }
    if let Ok(text) = world.cast::<PyString>() {
        return tmclsim_server::files::world_named(&text.to_cow()?, axes).map_err(|e| value_error(format!("world: {e}")));
    }
    let path: PathBuf = world.extract().map_err(|_| value_error("world is \"stage\", \"free\", a path or TOML text"))?;
    tmclsim_server::files::load_world(&path, axes).map_err(|e| value_error(format!("world: {e}")))
}

fn parameter_dict<'py>(py: Python<'py>, p: &Parameter, bank: Option<u8>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("number", p.number)?;
    if let Some(b) = bank {
        d.set_item("bank", b)?;
    }
    d.set_item("name", &p.name)?;
    d.set_item("snake_name", snake(&p.name))?;
    d.set_item("access", p.access.to_string())?;
    d.set_item("min", p.min)?;
    d.set_item("max", p.max)?;
    d.set_item("default", p.default)?;
    d.set_item("unit", p.unit.as_deref())?;
    Ok(d)
}

/// A trace column: a numpy array when numpy is there, else a list.
fn column<'py>(py: Python<'py>, numpy: Option<&Bound<'py, PyModule>>, values: Vec<i64>) -> PyResult<Bound<'py, PyAny>> {
    match numpy {
        Some(np) => {
            let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
            np.call_method1("frombuffer", (PyBytes::new(py, &bytes), "<i8"))?.call_method0("copy")
        }
        None => Ok(PyList::new(py, values)?.into_any()),
    }
}

fn float_column<'py>(py: Python<'py>, numpy: Option<&Bound<'py, PyModule>>, values: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    match numpy {
        Some(np) => {
            let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
            np.call_method1("frombuffer", (PyBytes::new(py, &bytes), "<f8"))?.call_method0("copy")
        }
        None => Ok(PyList::new(py, values)?.into_any()),
    }
}

#[pymethods]
impl Module {
    #[new]
    #[pyo3(signature = (profile="tmcm-1141", address=None, eeprom=None, world=None))]
    fn py_new(
        py: Python<'_>,
        profile: &str,
        address: Option<u8>,
        eeprom: Option<PathBuf>,
        world: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Module> {
        let profile = Profile::built_in(profile).map_err(value_error)?;
        // An address GP 66 does not take would be stored in the EEPROM
        // file, and the file refused at the next start (rule 88).
        if let (Some(a), Some(p)) = (address, profile.global_parameter(0, SERIAL_ADDRESS))
            && !p.accepts(i32::from(a))
        {
            return Err(value_error(format!("address {a}: a {} takes {} (GP 66)", profile.module.name, p.range_text())));
        }
        // The file is this module's while it lives: a second holder, in
        // this process or another, is refused.
        let file = eeprom.as_deref().map(EepromFile::open).transpose().map_err(os_error)?.map(Arc::new);
        let (image, existed) = match &file {
            Some(f) => f.load_for(&profile).map_err(|e| match e {
                LoadError::Unreadable(m) => os_error(m),
                LoadError::Refused(m) => value_error(m),
            })?,
            None => (Eeprom::new(&profile.module.name), false),
        };
        let read_only = file.as_ref().and_then(|f| f.read_only());
        if let (Some(f), Some(why)) = (&file, &read_only) {
            // Served, never replaced (rule 89).
            let message = format!(
                "{}: {why}; EEPROM writes are answered with status 5 and the file is left as it is (make it writable to keep changes)",
                f.named().display()
            );
            let message = std::ffi::CString::new(message).map_err(|e| value_error(e.to_string()))?;
            PyErr::warn(py, &py.get_type::<pyo3::exceptions::PyUserWarning>(), &message, 1)?;
        }
        let world = world_from(world, profile.module.axes as usize)?;
        let mut module = FwModule::with_world(profile.clone(), image, world);
        if let Some(a) = address
            && a != module.address()
        {
            module.set_address(a);
        }
        if let Some(f) = &file
            && (!existed || (address.is_some() && read_only.is_none()))
        {
            f.save(module.eeprom()).map_err(|e| os_error(format!("cannot write the EEPROM file {}: {e}", f.named().display())))?;
        }
        let shared = Arc::new(SharedBus::new(Bus::single(module), vec![file.clone()]));
        Ok(Module {
            shared,
            index: 0,
            served: false,
            names: Names::new(&profile),
            profile,
            eeprom_path: eeprom,
            eeprom_file: file,
            symbols: BTreeMap::new(),
        })
    }

    /// The module's name, e.g. ``"TMCM-1141"``.
    #[getter]
    fn profile(&self) -> String {
        self.profile.module.name.clone()
    }

    /// What makes this module differ from the others, as its profile's
    /// ``[features]`` table says: ``{"reference_search": "tmc429",
    /// "closed_loop": "false", …}`` (values as ``tmclsim profile`` prints
    /// them).
    #[getter]
    fn features(&self) -> BTreeMap<&'static str, String> {
        self.profile.features.list().into_iter().collect()
    }

    /// How the module detects a stall, as its profile's data names it:
    /// ``"stallguard2"``, ``"tmc249"`` or ``"none"``.
    #[getter]
    fn stall_detection(&self) -> &'static str {
        self.profile.features.stall_detection.name()
    }

    /// How many motors the module has.
    #[getter]
    fn axes(&self) -> u8 {
        self.profile.module.axes
    }

    /// The module address (GP 66) now.
    #[getter]
    fn address(&mut self) -> PyResult<u8> {
        self.address_now()
    }

    /// The firmware version text that 136 type 0 answers (``"1141V146"``).
    #[getter]
    fn version(&self) -> String {
        String::from_utf8_lossy(&self.profile.version_text()).into_owned()
    }

    /// The EEPROM file this module keeps, or None.
    #[getter]
    fn eeprom_path(&self) -> Option<PathBuf> {
        self.eeprom_path.clone()
    }

    /// True while a server holds the module.
    #[getter]
    fn served(&self) -> bool {
        self.is_served()
    }

    // ----- commands ---------------------------------------------------

    /// send(command, type=None, motor=None, value=None) -> Reply | None
    /// --
    ///
    /// Sends one command to the module's address and returns its decoded
    /// reply, or None when the module sends none (137, GP 255, …).
    ///
    /// ``command`` is a command line (``"GAP 1, 0"``, ``"MVP ABS, 0,
    /// 1000"``, raw ``"#136 0 0 0"``), an ``Instruction``, or an opcode
    /// followed by ``type``, ``motor`` and ``value``. Error statuses are
    /// returned in the reply, not raised (``reply.check()`` raises).
    #[pyo3(signature = (command, r#type=None, motor=None, value=None))]
    fn send(&mut self, command: &Bound<'_, PyAny>, r#type: Option<u8>, motor: Option<u8>, value: Option<i64>) -> PyResult<Option<Reply>> {
        let ins = command_from(command, r#type, motor, value)?;
        self.send_instruction(ins)
    }

    /// send_frame(frame: bytes) -> bytes | None
    /// --
    ///
    /// Hands nine raw bytes to the module as a serial link does (address
    /// filter, checksum, download mode) and returns the nine bytes it
    /// answers, or None.
    fn send_frame(&mut self, frame: Cow<'_, [u8]>) -> PyResult<Option<[u8; FRAME_LEN]>> {
        let frame: &[u8; FRAME_LEN] =
            frame.as_ref().try_into().map_err(|_| value_error(format!("a frame is {FRAME_LEN} bytes, not {}", frame.len())))?;
        self.handle_frame(frame)
    }

    /// take_events() -> list[Reply]
    /// --
    ///
    /// The unsolicited replies (138 "target reached" events) the module
    /// produced since the last call. A served module sends them on its link
    /// instead.
    fn take_events(&mut self) -> PyResult<Vec<Reply>> {
        // Carry out what is due first; events no link received wait on the bus.
        self.with(|_| ())?;
        let frames = self.shared.take_unclaimed_events(self.index);
        Ok(frames.into_iter().map(|f| Reply::new(f, ReplyKind::Normal)).collect())
    }

    // ----- parameters ---------------------------------------------------

    /// get_axis_parameter(param, motor=0) -> int
    /// --
    ///
    /// Reads an axis parameter (GAP) by number or by name (the profile's
    /// name, any case, or its snake_case: ``"Maximum positioning speed"``,
    /// ``"maximum_positioning_speed"``). Raises ``TmclError`` with the
    /// status the module answers (3: no such parameter, 4: no such motor).
    #[pyo3(signature = (param, motor=0))]
    fn get_axis_parameter(&mut self, param: &Bound<'_, PyAny>, motor: u8) -> PyResult<i32> {
        let number = self.axis_number(param)?;
        match self.with(|m| m.get_axis_parameter(number, motor))? {
            Ok(v) => Ok(v),
            Err(status) => Err(self.failed(param.py(), Ins::new(opcode::GAP, number, motor, 0), status)),
        }
    }

    /// set_axis_parameter(param, motor, value) -> None
    /// --
    ///
    /// Writes an axis parameter (SAP) by number or by name. Raises
    /// ``TmclError`` (3: no such parameter or read-only, 4: value out of
    /// range or no such motor).
    fn set_axis_parameter(&mut self, param: &Bound<'_, PyAny>, motor: u8, value: i64) -> PyResult<()> {
        let number = self.axis_number(param)?;
        let word = crate::types::wire_value(value)?;
        match self.with(|m| m.set_axis_parameter(number, motor, word))? {
            Ok(()) => Ok(()),
            Err(status) => Err(self.failed(param.py(), Ins::new(opcode::SAP, number, motor, word), status)),
        }
    }

    /// get_global_parameter(param, bank=None) -> int
    /// --
    ///
    /// Reads a global parameter (GGP) by number (bank None means 0) or by
    /// name (the bank comes with the name). Raises ``TmclError``.
    #[pyo3(signature = (param, bank=None))]
    fn get_global_parameter(&mut self, param: &Bound<'_, PyAny>, bank: Option<u8>) -> PyResult<i32> {
        let (bank, number) = self.global_number(param, bank)?;
        match self.with(|m| m.get_global_parameter(number, bank))? {
            Ok(v) => Ok(v),
            Err(status) => Err(self.failed(param.py(), Ins::new(opcode::GGP, number, bank, 0), status)),
        }
    }

    /// set_global_parameter(param, bank, value) -> None
    /// --
    ///
    /// Writes a global parameter (SGP). ``bank`` may be None when the
    /// parameter is given by name. Raises ``TmclError``.
    fn set_global_parameter(&mut self, param: &Bound<'_, PyAny>, bank: Option<u8>, value: i64) -> PyResult<()> {
        let (bank, number) = self.global_number(param, bank)?;
        let word = crate::types::wire_value(value)?;
        match self.with(|m| m.set_global_parameter(number, bank, word))? {
            Ok(()) => Ok(()),
            Err(status) => Err(self.failed(param.py(), Ins::new(opcode::SGP, number, bank, word), status)),
        }
    }

    /// _axis_number(name: str) -> int
    /// --
    ///
    /// The number of the axis parameter with this name (the lookup
    /// ``get_axis_parameter`` makes); ``ValueError`` when there is none.
    fn _axis_number(&self, name: &Bound<'_, PyString>) -> PyResult<u8> {
        self.axis_number(name.as_any())
    }

    /// _global_number(name: str, bank=None) -> tuple[int, int]
    /// --
    ///
    /// The bank and number of the global parameter with this name (the
    /// lookup ``get_global_parameter`` makes); ``ValueError`` when there
    /// is none.
    #[pyo3(signature = (name, bank=None))]
    fn _global_number(&self, name: &Bound<'_, PyString>, bank: Option<u8>) -> PyResult<(u8, u8)> {
        self.global_number(name.as_any(), bank)
    }

    /// axis_parameters() -> list[dict]
    /// --
    ///
    /// The profile's axis parameters: number, name, snake_name, access
    /// (letters R W E A as the manual prints them), min, max, default, unit.
    fn axis_parameters<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.profile.axis_parameters().map(|p| parameter_dict(py, p, None)).collect()
    }

    /// global_parameters(bank=None) -> list[dict]
    /// --
    ///
    /// The profile's global parameters of one bank (None: all banks), with
    /// the same keys as ``axis_parameters()`` plus ``bank``.
    #[pyo3(signature = (bank=None))]
    fn global_parameters<'py>(&self, py: Python<'py>, bank: Option<u8>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let banks: Vec<u8> = match bank {
            Some(b) => vec![b],
            None => (0..tmclsim_firmware::profile::BANKS as u8).collect(),
        };
        let mut out = Vec::new();
        for b in banks {
            for p in self.profile.global_parameters(b) {
                out.push(parameter_dict(py, p, Some(b))?);
            }
        }
        Ok(out)
    }

    // ----- state ---------------------------------------------------------

    /// actual_position(motor=0) -> int
    /// --
    ///
    /// The position counter (AP 1) in microsteps.
    #[pyo3(signature = (motor=0))]
    fn actual_position(&mut self, motor: usize) -> PyResult<i32> {
        self.check_motor(motor)?;
        self.with(|m| m.actual_position(motor))
    }

    /// actual_speed(motor=0) -> int
    /// --
    ///
    /// The actual speed (AP 3) in internal units.
    #[pyo3(signature = (motor=0))]
    fn actual_speed(&mut self, motor: usize) -> PyResult<i32> {
        self.check_motor(motor)?;
        self.with(|m| m.actual_speed(motor))
    }

    /// mechanical_position(motor=0) -> float
    /// --
    ///
    /// Where the carriage is, in the world's microsteps (differs from the
    /// position counter after homing, SAP 1 or lost steps).
    #[pyo3(signature = (motor=0))]
    fn mechanical_position(&mut self, motor: usize) -> PyResult<f64> {
        self.check_motor(motor)?;
        self.with(|m| m.mechanical_position(motor))
    }

    /// switches(motor=0) -> tuple[bool, bool, bool]
    /// --
    ///
    /// The (left, right, home) switch states the module reads now.
    #[pyo3(signature = (motor=0))]
    fn switches(&mut self, motor: usize) -> PyResult<(bool, bool, bool)> {
        self.check_motor(motor)?;
        self.with(|m| m.switches(motor))
    }

    /// error_flags(motor=0) -> int
    /// --
    ///
    /// AP 207 (extended error flags: 1 stall stop, 2 deviation, 4 encoder
    /// lost) as it stands, without clearing it as GAP 207 does: an observer
    /// (a sweep) that reads it does not change what the program will read.
    #[pyo3(signature = (motor=0))]
    fn error_flags(&mut self, motor: usize) -> PyResult<i32> {
        self.check_motor(motor)?;
        self.with(|m| observe::extended_error_flags(m, motor as u8))
    }

    /// at_end_stop(motor=0) -> bool
    /// --
    ///
    /// Whether the carriage stands at one of the world's mechanical end
    /// stops (`travel`; never in a world without them).
    #[pyo3(signature = (motor=0))]
    fn at_end_stop(&mut self, motor: usize) -> PyResult<bool> {
        self.check_motor(motor)?;
        self.with(|m| observe::at_end_stop(m, motor))
    }

    /// The digital outputs as a bit vector (OUT0 = bit 0).
    #[getter]
    fn outputs(&mut self) -> PyResult<u32> {
        self.with(|m| m.outputs())
    }

    /// power_cycle() -> None
    /// --
    ///
    /// Switches the module off and on: RAM from factory defaults, then
    /// what the EEPROM holds (as 255 does). The carriage stays where it is.
    fn power_cycle(&mut self) -> PyResult<()> {
        self.with(tmclsim_firmware::Module::reset)
    }

    /// eeprom_save(path) -> None
    /// --
    ///
    /// Writes the module's EEPROM image to a file (JSON, atomically); a
    /// ``Module(eeprom=path)`` powers up from it. A file another module
    /// or server keeps is refused (``OSError``).
    fn eeprom_save(&mut self, path: PathBuf) -> PyResult<()> {
        let image = self.with(|m| m.eeprom().clone())?;
        let cannot = |e: std::io::Error| os_error(format!("cannot write the EEPROM file {}: {e}", path.display()));
        match &self.eeprom_file {
            Some(own) if resolve(&path).is_ok_and(|p| p == own.path()) => own.save(&image).map_err(cannot),
            _ => EepromFile::open(&path).map_err(os_error)?.save(&image).map_err(cannot),
        }
    }

    // ----- time ----------------------------------------------------------

    /// advance(seconds: float) -> None
    /// --
    ///
    /// Moves virtual time on: the motors move, a program runs, interrupts
    /// and events fire, each at its own moment. For a served module this
    /// needs stepped time (``server.stepped = True``) and moves every
    /// module of the link.
    fn advance(&mut self, py: Python<'_>, seconds: f64) -> PyResult<()> {
        let ns = crate::advance::seconds_to_ns(seconds)?;
        self.advance_ns(py, ns)
    }

    /// Virtual time in seconds since the module was made.
    #[getter]
    fn time(&mut self) -> PyResult<f64> {
        Ok(self.now_ns()? as f64 * 1e-9)
    }

    /// Virtual time in nanoseconds.
    #[getter]
    fn time_ns(&mut self) -> PyResult<u64> {
        self.now_ns()
    }

    // ----- standalone programs -----------------------------------------

    /// load_program(program) -> Program
    /// --
    ///
    /// Puts a TMCL program into the module's program memory from address 0
    /// (and its EEPROM), as a download does, and resets the interpreter.
    /// ``program`` is TMCL source text (assembled for this module), a
    /// ``Program``, a binary image (bytes, 8 per instruction), a
    /// ``pathlib.Path`` of a source file, or a list of instructions.
    /// Returns the program, whose labels ``run``, ``breakpoints`` accept.
    fn load_program(&mut self, program: &Bound<'_, PyAny>) -> PyResult<Program> {
        let py = program.py();
        let program = program_from(program, Some(&self.profile))?;
        let capacity = self.profile.module.program_memory;
        let loaded = self.with(|m| m.load_program(&program.instructions))?;
        if loaded.is_err() {
            let message =
                format!("the program has {} instructions; the {} holds {capacity}", program.instructions.len(), self.profile.module.name);
            return Err(tmcl_error(py, Status::InvalidValue, message));
        }
        self.program_instruction(py, Ins::new(opcode::RESET_APPLICATION, 0, 0, 0))?;
        self.symbols = program.symbols.clone();
        Ok(Program { inner: program })
    }

    /// run(start=None) -> None
    /// --
    ///
    /// Starts the program: without ``start`` it continues where it is
    /// (address 0 after ``load_program``); with a label or an address it
    /// starts there afresh (129 type 1).
    #[pyo3(signature = (start=None))]
    fn run(&mut self, start: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        match start {
            None => self.with(tmclsim_firmware::Module::start_program),
            Some(at) => {
                let address = self.resolve_address(at)?;
                self.program_instruction(at.py(), Ins::new(opcode::RUN_APPLICATION, 1, 0, i32::from(address))).map(|_| ())
            }
        }
    }

    /// stop() -> None
    /// --
    ///
    /// Stops the program (128).
    fn stop(&mut self, py: Python<'_>) -> PyResult<()> {
        self.program_instruction(py, Ins::new(opcode::STOP_APPLICATION, 0, 0, 0)).map(|_| ())
    }

    /// pause() -> None
    /// --
    ///
    /// Pauses a running program as a debugger does; ``run()`` or ``step()``
    /// go on from there.
    fn pause(&mut self) -> PyResult<()> {
        self.with(tmclsim_firmware::Module::pause_program)
    }

    /// step(timeout=10.0) -> bool
    /// --
    ///
    /// Runs exactly one more instruction (a WAIT in progress first ends,
    /// virtual time moving as needed), then pauses. Returns False when
    /// ``timeout`` seconds of virtual time passed first. Needs an
    /// in-process module (stop its server first).
    #[pyo3(signature = (timeout=10.0))]
    fn step(&mut self, py: Python<'_>, timeout: f64) -> PyResult<bool> {
        let limit = crate::advance::seconds_to_ns(timeout)?;
        if !self.shared.is_stepped() {
            return Err(PyRuntimeError::new_err(
                "the module is served in real time: step needs stepped time (stop the server or set server.stepped = True)",
            ));
        }
        let (shared, index) = (self.shared.clone(), self.index);
        py.detach(|| {
            catch(|| {
                shared.with_bus(|bus| {
                    let end = bus.now_ns().saturating_add(limit);
                    bus.step_instruction(index, end, 10_000_000)
                })
            })
        })
        .map_err(|m| internal_error(py, m))
    }

    /// Breakpoints: addresses (or labels of the program loaded last)
    /// before which a running program pauses.
    #[getter]
    fn breakpoints(&mut self) -> PyResult<Vec<u16>> {
        self.with(|m| m.program().breakpoints.clone())
    }

    #[setter]
    fn set_breakpoints(&mut self, at: Vec<Bound<'_, PyAny>>) -> PyResult<()> {
        let addresses = at.iter().map(|a| self.resolve_address(a)).collect::<PyResult<Vec<u16>>>()?;
        self.with(|m| m.set_breakpoints(&addresses))
    }

    /// The address of the breakpoint the program paused at, or None.
    #[getter]
    fn hit_breakpoint(&mut self) -> PyResult<Option<u16>> {
        self.with(|m| m.program().hit_breakpoint)
    }

    /// The program counter.
    #[getter]
    fn pc(&mut self) -> PyResult<u16> {
        self.with(|m| m.program().pc)
    }

    /// What the interpreter does: "stop", "run", "step" (paused) or "reset".
    #[getter]
    fn program_mode(&mut self) -> PyResult<&'static str> {
        self.with(|m| match m.program().mode {
            RunMode::Stop => "stop",
            RunMode::Run => "run",
            RunMode::Step => "step",
            RunMode::Reset => "reset",
        })
    }

    /// True while the program waits in a WAIT.
    #[getter]
    fn waiting(&mut self) -> PyResult<bool> {
        self.with(|m| m.program().wait.is_some())
    }

    /// Program instructions executed since power-up.
    #[getter]
    fn instructions_executed(&mut self) -> PyResult<u64> {
        self.with(|m| m.program().executed)
    }

    /// The interpreter's accumulator, X register and flags.
    #[getter]
    fn registers(&mut self) -> PyResult<Registers> {
        self.with(|m| Registers::new(m.registers()))
    }

    /// Whether the program's instruction trace is recorded.
    #[getter]
    fn tracing(&mut self) -> PyResult<bool> {
        self.with(|m| m.program().trace.is_some())
    }

    #[setter]
    fn set_tracing(&mut self, on: bool) -> PyResult<()> {
        self.with(|m| m.set_trace(on))
    }

    /// take_trace() -> dict[str, array]
    /// --
    ///
    /// The instructions the program executed since the last call (set
    /// ``tracing = True`` first), as columns of equal length: ``time``
    /// (seconds), ``pc``, ``opcode``, ``type``, ``motor``, ``value``,
    /// ``accumulator``, ``x``, ``failed`` (the status of a command that
    /// failed and was skipped, else 0), and per motor n ``position_n`` and
    /// ``speed_n`` after the instruction. numpy arrays when numpy is
    /// installed, lists otherwise.
    fn take_trace<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let records = self.with(tmclsim_firmware::Module::take_trace)?;
        let axes = self.profile.module.axes as usize;
        let numpy = py.import("numpy").ok();
        let np = numpy.as_ref();
        let ints = |f: &dyn Fn(&tmclsim_firmware::program::TraceRecord) -> i64| records.iter().map(f).collect::<Vec<i64>>();
        let d = PyDict::new(py);
        d.set_item("time", float_column(py, np, records.iter().map(|r| r.time_ns as f64 * 1e-9).collect())?)?;
        d.set_item("pc", column(py, np, ints(&|r| i64::from(r.pc)))?)?;
        d.set_item("opcode", column(py, np, ints(&|r| i64::from(r.instruction.opcode)))?)?;
        d.set_item("type", column(py, np, ints(&|r| i64::from(r.instruction.kind)))?)?;
        d.set_item("motor", column(py, np, ints(&|r| i64::from(r.instruction.motor)))?)?;
        d.set_item("value", column(py, np, ints(&|r| i64::from(r.instruction.value)))?)?;
        d.set_item("accumulator", column(py, np, ints(&|r| i64::from(r.registers.accumulator)))?)?;
        d.set_item("x", column(py, np, ints(&|r| i64::from(r.registers.x)))?)?;
        d.set_item("failed", column(py, np, ints(&|r| i64::from(r.failed.unwrap_or(0))))?)?;
        for a in 0..axes {
            d.set_item(format!("position_{a}"), column(py, np, ints(&|r| i64::from(r.axes.get(a).map_or(0, |x| x.0))))?)?;
            d.set_item(format!("speed_{a}"), column(py, np, ints(&|r| i64::from(r.axes.get(a).map_or(0, |x| x.1))))?)?;
        }
        Ok(d)
    }

    // ----- the world -----------------------------------------------------

    /// world(line: str) -> str
    /// --
    ///
    /// Runs one command of the world control protocol (docs/world.md) on
    /// this module: ``"input 2 1"``, ``"analog 0 1234"``, ``"switch 0 home
    /// press"``, ``"load 0 50"``, ``"fault 0 open-a on"``, ``"show"``…
    /// Returns what the control socket prints after ``ok``; raises
    /// ``ValueError`` with its error. ``link …`` commands need a served
    /// module.
    fn world(&mut self, py: Python<'_>, line: &str) -> PyResult<String> {
        let (shared, index, served) = (&self.shared, self.index, self.served);
        guard(py, || world::run(shared, index, line, served))?.map_err(value_error)
    }

    fn __repr__(&mut self) -> String {
        let place = if self.is_served() { "served" } else { "in process" };
        match self.with(|m| (m.address(), m.now_ns())) {
            Ok((address, ns)) => {
                format!("<tmclsim.Module {} address {address}, {place}, t = {:.6} s>", self.profile.module.name, ns as f64 * 1e-9)
            }
            Err(_) => format!("<tmclsim.Module {}>", self.profile.module.name),
        }
    }
}

impl Module {
    fn check_motor(&self, motor: usize) -> PyResult<()> {
        if motor < self.profile.module.axes as usize {
            Ok(())
        } else {
            Err(value_error(format!(
                "motor {motor} does not exist on the {} ({} axis)",
                self.profile.module.name, self.profile.module.axes
            )))
        }
    }
}

/// _time_core(module, operation, calls) -> float
/// --
///
/// For python/bench.py: seconds per call of ``operation`` ("send_frame",
/// "get_axis_parameter", "set_axis_parameter", "get_global_parameter")
/// done ``calls`` times in Rust on an in-process module, without Python in
/// between: the core's share of a call through the binding.
#[pyfunction]
pub fn _time_core(module: &Bound<'_, Module>, operation: &str, calls: u32) -> PyResult<f64> {
    let this = module.try_borrow_mut()?;
    guard(module.py(), || {
        this.shared.with_module(this.index, |m| {
            let frame = Request::new(m.address(), Ins::new(opcode::GAP, 4, 0, 0)).encode();
            let started = std::time::Instant::now();
            let mut sink = 0i64;
            for n in 0..calls {
                sink += match operation {
                    "send_frame" => std::hint::black_box(m.handle_frame(std::hint::black_box(&frame))).map_or(0, |r| i64::from(r[7])),
                    "get_axis_parameter" => i64::from(m.get_axis_parameter(std::hint::black_box(4), 0).unwrap_or(0)),
                    "set_axis_parameter" => m.set_axis_parameter(4, 0, std::hint::black_box(1000 + (n % 2) as i32)).map_or(0, |_| 1),
                    "get_global_parameter" => i64::from(m.get_global_parameter(std::hint::black_box(66), 0).unwrap_or(0)),
                    other => return Err(value_error(format!("unknown operation '{other}'"))),
                };
            }
            std::hint::black_box(sink);
            Ok(started.elapsed().as_secs_f64() / f64::from(calls.max(1)))
        })
    })?
}
