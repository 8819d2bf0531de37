//! The assembler and disassembler: `Program`, `assemble`, `disassemble`.

use crate::errors::{assembly_error, value_error};
use crate::types::{Instruction, instruction_from};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes, PyString};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use tmclsim_asm::Program as AsmProgram;
use tmclsim_firmware::Profile;
use tmclsim_server::sources::FileResolver;

/// An assembled TMCL program: its instructions (one per program memory
/// word, from address 0; assembled from source, they end with a STOP), its
/// labels and its constants.
///
/// ``Program(instructions=(), symbols=None)`` makes one from instructions
/// (``Instruction`` objects, command lines or 4-tuples).
#[pyclass(module = "tmclsim", name = "Program")]
pub struct Program {
    pub inner: AsmProgram,
}

fn profile_by_name(name: Option<&str>) -> PyResult<Option<Arc<Profile>>> {
    name.map(|n| Profile::built_in(n).map_err(value_error)).transpose()
}

fn resolver(include_path: Option<Vec<PathBuf>>) -> FileResolver {
    include_path.into_iter().flatten().fold(FileResolver::new(), tmclsim_server::sources::FileResolver::with_search_dir)
}

fn instructions_from(seq: &Bound<'_, PyAny>) -> PyResult<Vec<tmclsim_protocol::Instruction>> {
    seq.try_iter()?.map(|item| instruction_from(&item?)).collect()
}

fn symbols_from(obj: Option<&Bound<'_, PyAny>>) -> PyResult<BTreeMap<String, u32>> {
    let Some(obj) = obj else { return Ok(BTreeMap::new()) };
    if obj.is_none() {
        return Ok(BTreeMap::new());
    }
    if let Ok(text) = obj.cast::<PyString>() {
        return AsmProgram::parse_symbol_file(&text.to_cow()?).map_err(|e| value_error(format!("symbol file: {e}")));
    }
    obj.extract()
}

/// A program from what Python passes: a `Program`, source text, a binary
/// image, a path of a source file, or a sequence of instructions.
pub fn program_from(obj: &Bound<'_, PyAny>, profile: Option<&Arc<Profile>>) -> PyResult<AsmProgram> {
    let py = obj.py();
    if let Ok(p) = obj.cast::<Program>() {
        return Ok(p.borrow().inner.clone());
    }
    if let Ok(text) = obj.cast::<PyString>() {
        let text = text.to_cow()?;
        return tmclsim_asm::assemble(&text, "program.tmc", &FileResolver::new(), profile.map(AsRef::as_ref))
            .map_err(|d| assembly_error(py, &d));
    }
    if obj.is_instance_of::<PyBytes>() || obj.is_instance_of::<PyByteArray>() {
        let bytes: Vec<u8> = obj.extract()?;
        let instructions = AsmProgram::from_binary(&bytes).map_err(|e| value_error(format!("binary image: {e}")))?;
        return Ok(AsmProgram { instructions, ..AsmProgram::default() });
    }
    if py.import("os")?.getattr("PathLike").and_then(|c| obj.is_instance(&c))? {
        let path: PathBuf = obj.extract()?;
        return tmclsim_server::sources::assemble_file(&path, profile.map(AsRef::as_ref)).map_err(|d| assembly_error(py, &d));
    }
    Ok(AsmProgram { instructions: instructions_from(obj)?, ..AsmProgram::default() })
}

#[pymethods]
impl Program {
    #[new]
    #[pyo3(signature = (instructions=None, symbols=None))]
    fn py_new(instructions: Option<&Bound<'_, PyAny>>, symbols: Option<&Bound<'_, PyAny>>) -> PyResult<Program> {
        let instructions = match instructions {
            Some(seq) => instructions_from(seq)?,
            None => Vec::new(),
        };
        Ok(Program {
            inner: AsmProgram { instructions, symbols: symbols_from(symbols)?, constants: BTreeMap::new(), ..Default::default() },
        })
    }

    /// from_binary(data: bytes, symbols=None) -> Program
    /// --
    ///
    /// Reads a binary image (8 bytes per instruction: opcode, type, motor,
    /// value, checksum), with labels from a dict or a symbol file's text.
    #[staticmethod]
    #[pyo3(signature = (data, symbols=None))]
    fn from_binary(data: Vec<u8>, symbols: Option<&Bound<'_, PyAny>>) -> PyResult<Program> {
        let instructions = AsmProgram::from_binary(&data).map_err(|e| value_error(format!("binary image: {e}")))?;
        Ok(Program {
            inner: AsmProgram { instructions, symbols: symbols_from(symbols)?, constants: BTreeMap::new(), ..Default::default() },
        })
    }

    /// The instructions, one per program memory word.
    #[getter]
    fn instructions(&self) -> Vec<Instruction> {
        self.inner.instructions.iter().map(|i| Instruction(*i)).collect()
    }

    /// Labels: name → address.
    #[getter]
    fn symbols(&self) -> BTreeMap<String, u32> {
        self.inner.symbols.clone()
    }

    /// Constants: name → value (those of included files too).
    #[getter]
    fn constants(&self) -> BTreeMap<String, i64> {
        self.inner.constants.clone()
    }

    /// The source of every instruction, same index as `instructions`:
    /// (file, line, column, text); none for the STOP the assembler appends
    /// (docs/behaviour.md rule 93); empty for a program not assembled here.
    #[getter]
    fn source_map(&self) -> Vec<(String, u32, u32, String)> {
        self.inner.source_map.iter().map(|s| (s.file.to_string(), s.line, s.column, s.text.clone())).collect()
    }

    /// Whether the last instruction is the STOP the assembler appended
    /// after the source's last instruction (the source does not end in
    /// STOP; docs/behaviour.md rule 93).
    #[getter]
    fn appended_stop(&self) -> bool {
        self.inner.appended_stop
    }

    /// to_binary() -> bytes
    /// --
    ///
    /// The binary image: 8 bytes per instruction, a TMCL request frame
    /// without the address byte (what ``tmclsim asm`` writes).
    fn to_binary(&self) -> Vec<u8> {
        self.inner.to_binary()
    }

    /// symbol_file() -> str
    /// --
    ///
    /// The symbol file: one ``label address`` line per label.
    fn symbol_file(&self) -> String {
        self.inner.symbol_file()
    }

    /// disassemble() -> str
    /// --
    ///
    /// Source text for the program, with its own labels; it assembles to
    /// the same bytes.
    fn disassemble(&self) -> String {
        self.inner.disassemble()
    }

    fn __len__(&self) -> usize {
        self.inner.instructions.len()
    }

    fn __getitem__(&self, index: isize) -> PyResult<Instruction> {
        let n = self.inner.instructions.len() as isize;
        let i = if index < 0 { index + n } else { index };
        if (0..n).contains(&i) {
            Ok(Instruction(self.inner.instructions[i as usize]))
        } else {
            Err(pyo3::exceptions::PyIndexError::new_err("program address out of range"))
        }
    }

    fn __iter__(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let list = pyo3::types::PyList::new(py, self.instructions())?;
        Ok(list.try_iter()?.into_any().unbind())
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<Program>().is_ok_and(|o| o.borrow().inner == self.inner)
    }

    fn __repr__(&self) -> String {
        format!("<tmclsim.Program {} instructions, {} labels>", self.inner.instructions.len(), self.inner.symbols.len())
    }
}

/// assemble(source, profile="tmcm-1141", file_name="program.tmc", include_path=None) -> Program
/// --
///
/// Assembles TMCL source (the TMCL-IDE syntax: labels, constants,
/// expressions, ``#include``). ``profile`` checks that the module has every
/// instruction, parameter, motor, bank and port the program uses (None:
/// no checks). ``file_name`` names the source in diagnostics, and includes
/// are found relative to it, then in ``include_path`` (a list of
/// directories), then among the shipped include files. Raises
/// ``AssemblyError`` with every diagnostic.
#[pyfunction]
#[pyo3(signature = (source, profile=Some("tmcm-1141"), file_name="program.tmc", include_path=None))]
pub fn assemble(
    py: Python<'_>,
    source: &str,
    profile: Option<&str>,
    file_name: &str,
    include_path: Option<Vec<PathBuf>>,
) -> PyResult<Program> {
    let profile = profile_by_name(profile)?;
    let inner =
        tmclsim_asm::assemble(source, file_name, &resolver(include_path), profile.as_deref()).map_err(|d| assembly_error(py, &d))?;
    Ok(Program { inner })
}

/// assemble_file(path, profile="tmcm-1141", include_path=None) -> Program
/// --
///
/// Assembles a source file; see ``assemble``.
#[pyfunction]
#[pyo3(signature = (path, profile=Some("tmcm-1141"), include_path=None))]
pub fn assemble_file(py: Python<'_>, path: PathBuf, profile: Option<&str>, include_path: Option<Vec<PathBuf>>) -> PyResult<Program> {
    let profile = profile_by_name(profile)?;
    let name = path.display().to_string();
    let source = tmclsim_server::sources::read_source(&path).map_err(|e| crate::errors::os_error(format!("{name}: {e}")))?;
    let inner = tmclsim_asm::assemble(&source, &name, &resolver(include_path), profile.as_deref()).map_err(|d| assembly_error(py, &d))?;
    Ok(Program { inner })
}

/// disassemble(program, symbols=None) -> str
/// --
///
/// Source text for a binary image (bytes), a ``Program`` or a list of
/// instructions. Labels come from ``symbols`` (a dict or a symbol file's
/// text), from the ``Program``, or are made up (``L12``) for jump targets.
#[pyfunction]
#[pyo3(signature = (program, symbols=None))]
pub fn disassemble(program: &Bound<'_, PyAny>, symbols: Option<&Bound<'_, PyAny>>) -> PyResult<String> {
    let mut p = program_from(program, None)?;
    let given = symbols_from(symbols)?;
    if !given.is_empty() {
        p.symbols = given;
    }
    Ok(tmclsim_asm::disassemble(&p.instructions, Some(&p.symbols)))
}
