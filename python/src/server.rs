//! `Server`: modules served on TCP and a pty in a background thread.
//!
//! The server serves the very bus the `Module` objects (or the `Bus`)
//! hold: nothing moves. While it runs in real time the bus's clock follows
//! the wall clock; when it stops (also when garbage collected) the clock is
//! stepped again.

use crate::advance::{advance_in_slices, seconds_to_ns};
use crate::bus::Bus;
use crate::errors::{guard, os_error, value_error};
use crate::module::{Module, served_error};
use crate::world;
use pyo3::exceptions::{PyRuntimeError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};
use std::net::{SocketAddr, ToSocketAddrs};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;
use tmclsim_firmware::Speed;
use tmclsim_host::{LinkFaults, SharedBus};
use tmclsim_server::{Endpoints, ServerConfig, ServerHandle};

/// An endpoint argument: `True` (the default place), `False`/`None` (off),
/// or an address / path.
pub enum Endpoint {
    Off,
    On,
    At(PathBuf),
}

impl<'a, 'py> FromPyObject<'a, 'py> for Endpoint {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if obj.is_none() {
            return Ok(Endpoint::Off);
        }
        if let Ok(b) = obj.cast::<PyBool>() {
            return Ok(if b.is_true() { Endpoint::On } else { Endpoint::Off });
        }
        let at: PathBuf = obj.extract().map_err(|_| PyTypeError::new_err("an endpoint is True, False, None, an address or a path"))?;
        Ok(Endpoint::At(at))
    }
}

fn socket_address(endpoint: &Endpoint, what: &str) -> PyResult<Option<SocketAddr>> {
    let text = match endpoint {
        Endpoint::Off => return Ok(None),
        Endpoint::On => "127.0.0.1:0".to_string(),
        Endpoint::At(a) => a.to_string_lossy().into_owned(),
    };
    let mut found = text.to_socket_addrs().map_err(|e| value_error(format!("{what} address '{text}': {e}")))?;
    found.next().map(Some).ok_or_else(|| value_error(format!("{what} address '{text}' names no address")))
}

static NEXT_PTY: AtomicU64 = AtomicU64::new(1);

fn pty_path(endpoint: Endpoint, module_name: &str) -> Option<PathBuf> {
    match endpoint {
        Endpoint::Off => None,
        Endpoint::On => {
            let n = NEXT_PTY.fetch_add(1, Ordering::Relaxed);
            let name = format!("tmclsim-{}-{}-{n}", module_name.to_ascii_lowercase(), std::process::id());
            Some(std::env::temp_dir().join(name))
        }
        Endpoint::At(p) => Some(p),
    }
}

/// Modules served on loopback TCP and/or a pty, in a background thread.
///
/// ``Server(target, tcp=True, pty=None, control=True, stepped=False,
/// wire_timing=False, speed=1)`` (``tmclsim.serve`` makes one):
///
/// - ``target``: a ``Module`` or a ``Bus``; its modules move into the server
///   until it stops, and the ``Module`` objects reach them through it.
/// - ``tcp``: an address (``"127.0.0.1:1141"``), True for a free port on
///   127.0.0.1, None for no TCP. An address other machines reach
///   (``"0.0.0.0:1141"``) works with a ``UserWarning``: anyone on the
///   network can then drive the motors.
/// - ``pty``: a path for the symlink to a pty (the serial port a host
///   opens), True for one in the temporary directory, None for no pty.
/// - ``control``: the control socket of docs/world.md (True: a free port on
///   127.0.0.1); only on loopback (it mutes links and injects faults).
/// - ``stepped``: virtual time moves only by ``advance`` (default: paced by
///   the wall clock).
/// - ``wire_timing``: replies take as long as the bytes take at the
///   module's baud rate (GP 65).
/// - ``speed``: virtual time runs this many times as fast as the wall
///   clock while it is paced by it (0.001…100000; ``.speed`` reads
///   and sets it while served); ``tmclsim.clock`` puts the host's own
///   clocks on the same scale.
///
/// Stops with ``stop()``, at the end of a ``with`` block, or when garbage
/// collected.
#[pyclass(subclass, module = "tmclsim", name = "Server")]
pub struct Server {
    handle: Option<ServerHandle>,
    shared: Arc<SharedBus>,
    modules: Vec<Py<Module>>,
    endpoints: Endpoints,
}

impl Server {
    fn live(&self) -> PyResult<&Arc<SharedBus>> {
        if self.handle.is_some() { Ok(&self.shared) } else { Err(PyRuntimeError::new_err("the server is stopped")) }
    }

    /// Stops serving; the modules are in process again, in stepped time
    /// at the wall clock's own speed.
    fn shutdown(&mut self, py: Python<'_>) {
        let Some(handle) = self.handle.take() else { return };
        handle.stop();
        self.shared.set_stepped(true);
        self.shared.with_bus(|b| b.set_speed(Speed::REAL_TIME));
        for m in &self.modules {
            if let Ok(mut m) = m.bind(py).try_borrow_mut() {
                m.served = false;
            }
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        if self.handle.is_some() {
            Python::attach(|py| self.shutdown(py));
        }
    }
}

#[pymethods]
impl Server {
    #[new]
    #[pyo3(signature = (target, tcp=Endpoint::On, pty=Endpoint::Off, control=Endpoint::On, stepped=false, wire_timing=false, speed=1.0))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        py: Python<'_>,
        target: &Bound<'_, PyAny>,
        tcp: Endpoint,
        pty: Endpoint,
        control: Endpoint,
        stepped: bool,
        wire_timing: bool,
        speed: f64,
    ) -> PyResult<Server> {
        let speed = Speed::new(speed).map_err(|e| value_error(e.to_string()))?;
        let (shared, modules): (Arc<SharedBus>, Vec<Py<Module>>) = if let Ok(m) = target.cast::<Module>() {
            let shared = m.borrow().shared.clone();
            if shared.len() != 1 {
                return Err(value_error("the module is on a bus: serve the Bus"));
            }
            (shared, vec![m.clone().unbind()])
        } else if let Ok(bus) = target.cast::<Bus>() {
            let bus = bus.borrow();
            (bus.shared.clone(), bus.modules.iter().map(|m| m.clone_ref(py)).collect())
        } else {
            return Err(PyTypeError::new_err(format!("serve takes a Module or a Bus, not {}", target.get_type().name()?)));
        };
        let mut refs = Vec::new();
        for m in &modules {
            let r = m.bind(py).try_borrow_mut()?;
            if r.is_served() {
                return Err(served_error());
            }
            refs.push(r);
        }
        if matches!(tcp, Endpoint::Off) && matches!(pty, Endpoint::Off) {
            return Err(value_error("serve needs tcp, pty or both"));
        }
        let config = ServerConfig {
            tcp: socket_address(&tcp, "tcp")?,
            pty: pty_path(pty, &refs[0].profile.module.name),
            control: socket_address(&control, "control")?,
            wire_timing,
            // Warned about below, the Python way.
            warn_exposure: false,
            ..ServerConfig::default()
        };
        shared.with_bus(|b| {
            b.set_wire_timing(wire_timing);
            b.set_speed(speed);
        });
        let handle = tmclsim_server::start_shared(shared.clone(), config).map_err(|e| os_error(format!("cannot serve: {e}")))?;
        // An address other machines reach: say so (a warnings filter that
        // turns warnings into errors stops the server again).
        for w in tmclsim_server::exposure_warnings(std::slice::from_ref(handle.endpoints())) {
            let message = std::ffi::CString::new(w).map_err(|e| value_error(e.to_string()))?;
            let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
            PyErr::warn(py, &category, &message, 1)?;
        }
        for r in &mut refs {
            r.served = true;
        }
        shared.set_stepped(stepped);
        let endpoints = handle.endpoints().clone();
        Ok(Server { handle: Some(handle), shared, modules, endpoints })
    }

    /// The TCP address (``"127.0.0.1:PORT"``), or None.
    #[getter]
    fn tcp(&self) -> Option<String> {
        self.endpoints.tcp.map(|a| a.to_string())
    }

    /// The pty's path (a symlink to its serial device) that a host opens
    /// as a serial port, or None.
    #[getter]
    fn pty(&self) -> Option<String> {
        self.endpoints.pty.as_ref().map(|(link, _)| link.display().to_string())
    }

    /// The pty's serial device (``/dev/pts/N``), or None.
    #[getter]
    fn pty_device(&self) -> Option<String> {
        self.endpoints.pty.as_ref().map(|(_, device)| device.display().to_string())
    }

    /// The control socket's address, or None.
    #[getter]
    fn control(&self) -> Option<String> {
        self.endpoints.control.map(|a| a.to_string())
    }

    /// PyTrinamic ``ConnectionManager`` arguments for the TCP endpoint
    /// (``"--interface socket_serial_tmcl --port 127.0.0.1:PORT"``), or the
    /// pty's when there is no TCP.
    #[getter]
    fn pytrinamic_args(&self) -> Option<String> {
        self.endpoints.pytrinamic_args()
    }

    /// PyTrinamic ``ConnectionManager`` arguments for the pty, or None.
    #[getter]
    fn pytrinamic_pty_args(&self) -> Option<String> {
        self.endpoints.pty.as_ref().map(|(link, _)| format!("--interface serial_tmcl --port {}", link.display()))
    }

    /// True until the server is stopped.
    #[getter]
    fn running(&self) -> bool {
        self.handle.is_some()
    }

    /// The first served module.
    #[getter]
    fn module(&self, py: Python<'_>) -> Py<Module> {
        self.modules[0].clone_ref(py)
    }

    /// The served modules, in bus order.
    #[getter]
    fn modules(&self, py: Python<'_>) -> Vec<Py<Module>> {
        self.modules.iter().map(|m| m.clone_ref(py)).collect()
    }

    /// Stepped virtual time: True stops the clock, and only ``advance``
    /// moves time; False goes back to the wall clock from where the modules
    /// are.
    #[getter]
    fn stepped(&self) -> bool {
        self.shared.is_stepped()
    }

    #[setter]
    fn set_stepped(&self, stepped: bool) -> PyResult<()> {
        self.live()?.set_stepped(stepped);
        Ok(())
    }

    /// How many times as fast as the wall clock virtual time runs while it
    /// is paced by the wall clock (0.001…100000; settable while
    /// served, from the modules' now on).
    #[getter]
    fn speed(&self) -> f64 {
        self.shared.with_bus(|b| b.speed().factor())
    }

    #[setter]
    fn set_speed(&self, speed: f64) -> PyResult<()> {
        let speed = Speed::new(speed).map_err(|e| value_error(e.to_string()))?;
        self.live()?.with_bus(|b| b.set_speed(speed));
        Ok(())
    }

    /// advance(seconds: float) -> None
    /// --
    ///
    /// Stepped time: moves every served module on (events go out on the
    /// link as they become due).
    fn advance(&self, py: Python<'_>, seconds: f64) -> PyResult<()> {
        let shared = self.live()?.clone();
        if !shared.is_stepped() {
            return Err(PyRuntimeError::new_err("advance needs stepped time: set stepped = True first"));
        }
        let ns = seconds_to_ns(seconds)?;
        advance_in_slices(py, &shared, ns)
    }

    /// Virtual time of the served modules, in seconds.
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.live()?.now_ns() as f64 * 1e-9)
    }

    /// world(line: str, module: int = 0) -> str
    /// --
    ///
    /// Runs one command of the control protocol (docs/world.md) on served
    /// module ``module`` (an index in bus order), as the control socket
    /// does: inputs, switches, loads, faults, ``link …`` faults, ``show``.
    /// Returns what the socket prints after ``ok``; raises ``ValueError``.
    #[pyo3(signature = (line, module=0))]
    fn world(&self, py: Python<'_>, line: &str, module: usize) -> PyResult<String> {
        let shared = self.live()?;
        if module >= self.modules.len() {
            return Err(value_error(format!("module {module}: the server has {}", self.modules.len())));
        }
        guard(py, || world::run(shared, module, line, true))?.map_err(value_error)
    }

    /// link_faults(drop=None, corrupt=None, delay_ms=None, mute=None, clear=False) -> dict
    /// --
    ///
    /// Changes the link faults (for testing a host's error handling):
    /// ``drop`` the next N replies, ``corrupt`` the checksum of the next N,
    /// ``delay_ms`` every reply, ``mute`` all replies; ``clear`` first
    /// removes every fault. Returns the faults in force.
    #[pyo3(signature = (drop=None, corrupt=None, delay_ms=None, mute=None, clear=false))]
    fn link_faults<'py>(
        &self,
        py: Python<'py>,
        drop: Option<u32>,
        corrupt: Option<u32>,
        delay_ms: Option<u64>,
        mute: Option<bool>,
        clear: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let shared = self.live()?;
        let mut f = if clear { LinkFaults::default() } else { shared.link_faults() };
        if let Some(n) = drop {
            f.drop = n;
        }
        if let Some(n) = corrupt {
            f.corrupt = n;
        }
        if let Some(ms) = delay_ms {
            f.delay = Duration::from_millis(ms);
        }
        if let Some(m) = mute {
            f.mute = m;
        }
        shared.set_link_faults(f);
        let d = PyDict::new(py);
        d.set_item("drop", f.drop)?;
        d.set_item("corrupt", f.corrupt)?;
        d.set_item("delay_ms", f.delay.as_millis() as u64)?;
        d.set_item("mute", f.mute)?;
        Ok(d)
    }

    /// stop() -> None
    /// --
    ///
    /// Stops serving, closes the links, removes the pty symlink and gives
    /// the modules back to their ``Module`` objects (at the virtual time
    /// they reached). Stopping twice is harmless.
    fn stop(&mut self, py: Python<'_>) {
        self.shutdown(py);
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_args))]
    fn __exit__(&mut self, py: Python<'_>, _args: &Bound<'_, pyo3::types::PyTuple>) -> bool {
        self.shutdown(py);
        false
    }

    fn __repr__(&self) -> String {
        let mut parts = Vec::new();
        if let Some(t) = self.tcp() {
            parts.push(format!("tcp {t}"));
        }
        if let Some(p) = self.pty() {
            parts.push(format!("pty {p}"));
        }
        if let Some(c) = self.control() {
            parts.push(format!("control {c}"));
        }
        let state = if self.handle.is_none() {
            "stopped"
        } else if self.shared.is_stepped() {
            "stepped"
        } else {
            "real time"
        };
        format!("<tmclsim.Server {} module(s), {}, {state}>", self.modules.len(), parts.join(", "))
    }
}
