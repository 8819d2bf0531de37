//! `Bus`: several modules on one link, as on an RS485 bus — a firmware
//! `Bus` shared with the modules' objects (and a server, when served).

use crate::advance::seconds_to_ns;
use crate::errors::{guard, value_error};
use crate::module::{Module, served_error};
use crate::types::{Reply, command_from};
use pyo3::prelude::*;
use std::borrow::Cow;
use std::sync::Arc;
use tmclsim_firmware::Bus as FwBus;
use tmclsim_host::SharedBus;
use tmclsim_protocol::{FRAME_LEN, Request};

/// Several modules on one link: every frame reaches every module, the
/// addressed one answers.
///
/// ``Bus([Module(address=1), Module(address=2)])``. The modules stay
/// usable on their own; they now live on the bus, at one virtual time, and
/// move together with ``advance``. ``tmclsim.serve(bus)`` serves the whole
/// bus on one TCP port and pty.
#[pyclass(module = "tmclsim", name = "Bus")]
pub struct Bus {
    pub shared: Arc<SharedBus>,
    pub modules: Vec<Py<Module>>,
}

#[pymethods]
impl Bus {
    #[new]
    fn py_new(py: Python<'_>, modules: Vec<Py<Module>>) -> PyResult<Bus> {
        if modules.is_empty() {
            return Err(value_error("a bus needs at least one module"));
        }
        let mut addresses = Vec::new();
        for m in &modules {
            let mut m = m.bind(py).try_borrow_mut()?;
            if m.is_served() {
                return Err(served_error());
            }
            if m.shared.len() != 1 {
                return Err(value_error("the module is on a bus already"));
            }
            addresses.push(m.address_now()?);
        }
        if let Some(address) = tmclsim_firmware::bus::duplicate_address(addresses) {
            return Err(value_error(format!("two modules have address {address}: give each its own (Module(address=…))")));
        }
        // Each module leaves its bus of one for the new bus, with its
        // EEPROM file; the firmware bus brings them to one time.
        let mut fw = Vec::new();
        let mut eeproms = Vec::new();
        for m in &modules {
            let m = m.bind(py).try_borrow_mut()?;
            fw.extend(m.shared.take_modules());
            eeproms.push(m.eeprom_file.clone());
        }
        let shared = Arc::new(SharedBus::new(FwBus::new(fw), eeproms));
        for (i, m) in modules.iter().enumerate() {
            m.bind(py).try_borrow_mut()?.move_to(shared.clone(), i);
        }
        Ok(Bus { shared, modules })
    }

    /// The modules, in the order given.
    #[getter]
    fn modules(&self, py: Python<'_>) -> Vec<Py<Module>> {
        self.modules.iter().map(|m| m.clone_ref(py)).collect()
    }

    /// module(address: int) -> Module
    /// --
    ///
    /// The module that answers to ``address`` now (GP 66).
    fn module(&self, py: Python<'_>, address: u8) -> PyResult<Py<Module>> {
        match guard(py, || self.shared.with_bus(|b| b.index_of(address)))? {
            Some(i) => Ok(self.modules[i].clone_ref(py)),
            None => Err(value_error(format!("no module on the bus answers to address {address}"))),
        }
    }

    /// send_frame(frame: bytes) -> bytes | None
    /// --
    ///
    /// Puts nine bytes on the bus: every module sees them, the addressed
    /// one answers (None: nobody answered).
    fn send_frame(&self, py: Python<'_>, frame: Cow<'_, [u8]>) -> PyResult<Option<[u8; FRAME_LEN]>> {
        let frame: &[u8; FRAME_LEN] =
            frame.as_ref().try_into().map_err(|_| value_error(format!("a frame is {FRAME_LEN} bytes, not {}", frame.len())))?;
        Ok(guard(py, || self.shared.frame(frame))?.into_iter().next())
    }

    /// send(address, command, type=None, motor=None, value=None) -> Reply | None
    /// --
    ///
    /// Sends one command to ``address`` on the bus; ``command`` as in
    /// ``Module.send``.
    #[pyo3(signature = (address, command, r#type=None, motor=None, value=None))]
    fn send(
        &self,
        address: u8,
        command: &Bound<'_, PyAny>,
        r#type: Option<u8>,
        motor: Option<u8>,
        value: Option<i64>,
    ) -> PyResult<Option<Reply>> {
        let ins = command_from(command, r#type, motor, value)?;
        let frame = Request::new(address, ins).encode();
        let reply = self.send_frame(command.py(), Cow::Borrowed(&frame))?;
        Ok(reply.map(|raw| Reply::new(raw, tmclsim_host::reply::shape(ins, address, &raw))))
    }

    /// advance(seconds: float) -> None
    /// --
    ///
    /// Moves every module on by the same virtual time.
    fn advance(&self, py: Python<'_>, seconds: f64) -> PyResult<()> {
        let ns = seconds_to_ns(seconds)?;
        self.modules[0].bind(py).try_borrow_mut()?.advance_ns(py, ns)
    }

    /// Virtual time in seconds.
    #[getter]
    fn time(&self) -> f64 {
        self.shared.now_ns() as f64 * 1e-9
    }

    fn __len__(&self) -> usize {
        self.modules.len()
    }

    fn __getitem__(&self, py: Python<'_>, index: isize) -> PyResult<Py<Module>> {
        let n = self.modules.len() as isize;
        let i = if index < 0 { index + n } else { index };
        if (0..n).contains(&i) {
            Ok(self.modules[i as usize].clone_ref(py))
        } else {
            Err(pyo3::exceptions::PyIndexError::new_err("bus index out of range"))
        }
    }

    fn __iter__(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let list = pyo3::types::PyList::new(py, self.modules(py))?;
        Ok(list.try_iter()?.into_any().unbind())
    }

    fn __repr__(&self) -> String {
        let addresses: Vec<String> = self.shared.with_bus(|b| b.modules().iter().map(|m| m.address().to_string()).collect());
        format!("<tmclsim.Bus addresses {}>", addresses.join(", "))
    }
}
