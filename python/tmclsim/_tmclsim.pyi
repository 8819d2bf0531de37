"""Type stubs of the native part of tmclsim (the PyO3 extension).

Use the classes through ``tmclsim`` (``tmclsim.Module`` and
``tmclsim.Server`` add the world convenience methods)."""

import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

_Path = Union[str, "os.PathLike[str]"]
_InstructionLike = Union["Instruction", str, Tuple[int, int, int, int], Sequence[int]]
_ProgramLike = Union["Program", str, bytes, bytearray, "os.PathLike[str]", Sequence[_InstructionLike]]
_Param = Union[int, str]
_Endpoint = Union[str, _Path, bool, None]

def cli_main(argv: List[str]) -> int:
    """Runs the `tmclsim` command with `argv` (program name first); its exit status."""
    ...

def profiles() -> List[str]:
    """The names of the built-in module profiles."""

class Reply:
    """A module's answer to one command (nine bytes, decoded)."""

    def __init__(self, raw: bytes, special: Optional[str] = None) -> None: ...
    @property
    def host(self) -> int:
        """The host address (byte 0)."""
    @property
    def module(self) -> int:
        """The module address the request used (byte 1)."""
    @property
    def status(self) -> int:
        """The TMCL status: 100 ok, 101 loaded, 128 event, 1…6 errors."""
    @property
    def opcode(self) -> int:
        """The opcode the reply answers."""
    @property
    def value(self) -> int:
        """The signed 32-bit value."""
    @property
    def raw(self) -> bytes:
        """The nine bytes as the module sent them."""
    @property
    def special(self) -> bool:
        """True for the special replies of 136 type 0 and 134."""
    @property
    def checksum_ok(self) -> bool:
        """Whether byte 8 is the checksum of bytes 0…7."""
    @property
    def ok(self) -> bool:
        """True when the command succeeded."""
    @property
    def description(self) -> str:
        """The status in words."""
    @property
    def version(self) -> Optional[str]:
        """The text of a 136 type 0 reply (``"1141V146"``), else None."""
    @property
    def instruction(self) -> Optional["Instruction"]:
        """The stored word of a 134 reply, else None."""
    def check(self) -> "Reply":
        """Returns the reply if ok, raises ``TmclError`` otherwise."""
    def __bytes__(self) -> bytes: ...
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...

class Instruction:
    """One TMCL instruction: opcode, type, motor (bank), value."""

    def __init__(self, opcode: int, type: int = 0, motor: int = 0, value: int = 0) -> None: ...
    @staticmethod
    def parse(line: str) -> "Instruction":
        """A command line: ``"MVP ABS, 0, 1000"`` or raw ``"#136 0 0 0"``."""
    @property
    def opcode(self) -> int: ...
    @property
    def type(self) -> int: ...
    @property
    def motor(self) -> int: ...
    @property
    def value(self) -> int: ...
    @property
    def mnemonic(self) -> str:
        """Source text that parses back to this instruction."""
    def to_bytes(self) -> bytes:
        """The seven bytes opcode, type, motor, value."""
    def frame(self, address: int = 1) -> bytes:
        """The 9-byte request frame for ``address``."""
    def __iter__(self) -> Iterator[int]: ...
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...

class Registers:
    """Accumulator, X register and flags of the TMCL interpreter."""

    @property
    def accumulator(self) -> int: ...
    @property
    def x(self) -> int: ...
    @property
    def compare(self) -> str:
        """``"less"``, ``"equal"`` or ``"greater"``."""
    @property
    def errors(self) -> int:
        """Error flags as a bit mask (ETO 2, EAL 4, EDV 8, EPO 16, ESD 32)."""
    @property
    def error_flags(self) -> List[str]:
        """The set error flags by name."""

class Program:
    """An assembled TMCL program."""

    def __init__(self, instructions: Optional[Sequence[_InstructionLike]] = None, symbols: Union[Mapping[str, int], str, None] = None) -> None: ...
    @staticmethod
    def from_binary(data: bytes, symbols: Union[Mapping[str, int], str, None] = None) -> "Program":
        """Reads a binary image (8 bytes per instruction)."""
    @property
    def instructions(self) -> List[Instruction]: ...
    @property
    def symbols(self) -> Dict[str, int]:
        """Labels: name → address."""
    @property
    def constants(self) -> Dict[str, int]: ...
    @property
    def source_map(self) -> List[Tuple[str, int, int, str]]:
        """(file, line, column, text) of every instruction of the source (the appended STOP has none); empty when not assembled from source."""
    @property
    def appended_stop(self) -> bool:
        """Whether the last instruction is the STOP the assembler appended (the source does not end in STOP)."""
    def to_binary(self) -> bytes:
        """The binary image: 8 bytes per instruction."""
    def symbol_file(self) -> str:
        """``label address`` per line."""
    def disassemble(self) -> str:
        """Source text that assembles to the same bytes."""
    def __len__(self) -> int: ...
    def __getitem__(self, index: int) -> Instruction: ...
    def __iter__(self) -> Iterator[Instruction]: ...
    def __eq__(self, other: object) -> bool: ...

def assemble(source: str, profile: Optional[str] = "tmcm-1141", file_name: str = "program.tmc", include_path: Optional[Sequence[_Path]] = None) -> Program:
    """Assembles TMCL source; raises ``AssemblyError`` with the diagnostics."""

def assemble_file(path: _Path, profile: Optional[str] = "tmcm-1141", include_path: Optional[Sequence[_Path]] = None) -> Program:
    """Assembles a TMCL source file."""

def disassemble(program: _ProgramLike, symbols: Union[Mapping[str, int], str, None] = None) -> str:
    """Source text for a binary image, a ``Program`` or instructions."""

class Module:
    """A virtual TMCL module (in process, or reached through its server)."""

    def __init__(self, profile: str = "tmcm-1141", address: Optional[int] = None, eeprom: Optional[_Path] = None, world: Union[str, "os.PathLike[str]", None] = None) -> None: ...
    @property
    def profile(self) -> str:
        """The module's name, e.g. ``"TMCM-1141"``."""
    @property
    def features(self) -> Dict[str, str]:
        """The profile's ``[features]`` table (reference search family, closed loop, CAN ids, …)."""
    @property
    def stall_detection(self) -> str:
        """How the module detects a stall: ``"stallguard2"``, ``"tmc249"`` or ``"none"`` (profile data)."""
    @property
    def axes(self) -> int: ...
    @property
    def address(self) -> int:
        """The module address (GP 66) now."""
    @property
    def version(self) -> str:
        """The version text 136 type 0 answers."""
    @property
    def eeprom_path(self) -> Optional["os.PathLike[str]"]:
        """The EEPROM file this module keeps (a pathlib.Path), or None."""
    @property
    def served(self) -> bool:
        """True while a server holds the module."""
    # commands
    def send(self, command: Union[str, int, Instruction], type: Optional[int] = None, motor: Optional[int] = None, value: Optional[int] = None) -> Optional[Reply]:
        """Sends one command; returns the reply (error statuses included) or None."""
    def send_frame(self, frame: bytes) -> Optional[bytes]:
        """Nine raw bytes in, nine out (or None)."""
    def take_events(self) -> List[Reply]:
        """138 events produced since the last call (in process)."""
    # parameters
    def get_axis_parameter(self, param: _Param, motor: int = 0) -> int:
        """GAP by number or name; raises ``TmclError``."""
    def set_axis_parameter(self, param: _Param, motor: int, value: int) -> None:
        """SAP by number or name; raises ``TmclError``."""
    def get_global_parameter(self, param: _Param, bank: Optional[int] = None) -> int:
        """GGP by number (bank 0 by default) or name; raises ``TmclError``."""
    def set_global_parameter(self, param: _Param, bank: Optional[int], value: int) -> None:
        """SGP by number or name; raises ``TmclError``."""
    def axis_parameters(self) -> List[Dict[str, Any]]:
        """The profile's axis parameters."""
    def global_parameters(self, bank: Optional[int] = None) -> List[Dict[str, Any]]:
        """The profile's global parameters."""
    # state
    def actual_position(self, motor: int = 0) -> int: ...
    def actual_speed(self, motor: int = 0) -> int: ...
    def mechanical_position(self, motor: int = 0) -> float:
        """Where the carriage is, in the world's microsteps."""
    def switches(self, motor: int = 0) -> Tuple[bool, bool, bool]:
        """(left, right, home) as the module reads them."""
    def error_flags(self, motor: int = 0) -> int:
        """AP 207 as it stands, not cleared (GAP 207 clears it)."""
    def at_end_stop(self, motor: int = 0) -> bool:
        """Whether the carriage stands at a mechanical end stop."""
    @property
    def outputs(self) -> int:
        """Digital outputs as a bit vector."""
    def power_cycle(self) -> None:
        """Off and on: factory defaults, then the EEPROM."""
    def eeprom_save(self, path: _Path) -> None:
        """Writes the EEPROM image to a file."""
    # time
    def advance(self, seconds: float) -> None:
        """Moves virtual time on (served: needs stepped time)."""
    @property
    def time(self) -> float:
        """Virtual time in seconds."""
    @property
    def time_ns(self) -> int: ...
    # programs
    def load_program(self, program: _ProgramLike) -> Program:
        """Puts a program into program memory; returns it."""
    def run(self, start: Union[int, str, None] = None) -> None:
        """Starts or continues the program (at a label or address)."""
    def stop(self) -> None:
        """Stops the program (128)."""
    def pause(self) -> None:
        """Pauses the program as a debugger does."""
    def step(self, timeout: float = 10.0) -> bool:
        """Runs one more instruction, then pauses."""
    @property
    def breakpoints(self) -> List[int]: ...
    @breakpoints.setter
    def breakpoints(self, at: Sequence[Union[int, str]]) -> None: ...
    @property
    def hit_breakpoint(self) -> Optional[int]: ...
    @property
    def pc(self) -> int: ...
    @property
    def program_mode(self) -> str:
        """``"stop"``, ``"run"``, ``"step"`` or ``"reset"``."""
    @property
    def waiting(self) -> bool: ...
    @property
    def instructions_executed(self) -> int: ...
    @property
    def registers(self) -> Registers: ...
    @property
    def tracing(self) -> bool: ...
    @tracing.setter
    def tracing(self, on: bool) -> None: ...
    def take_trace(self) -> Dict[str, Any]:
        """Trace columns (numpy arrays, or lists without numpy)."""
    # world
    def world(self, line: str) -> str:
        """One line of the world control protocol."""

class Bus:
    """Several modules on one link."""

    def __init__(self, modules: Sequence[Module]) -> None: ...
    @property
    def modules(self) -> List[Module]: ...
    def module(self, address: int) -> Module: ...
    def send_frame(self, frame: bytes) -> Optional[bytes]: ...
    def send(self, address: int, command: Union[str, int, Instruction], type: Optional[int] = None, motor: Optional[int] = None, value: Optional[int] = None) -> Optional[Reply]: ...
    def advance(self, seconds: float) -> None: ...
    @property
    def time(self) -> float: ...
    def __len__(self) -> int: ...
    def __getitem__(self, index: int) -> Module: ...
    def __iter__(self) -> Iterator[Module]: ...

class Server:
    """Modules served on TCP and/or a pty in a background thread."""

    def __init__(self, target: Union[Module, Bus], tcp: _Endpoint = True, pty: _Endpoint = None, control: _Endpoint = True, stepped: bool = False, wire_timing: bool = False, speed: float = 1) -> None: ...
    @property
    def tcp(self) -> Optional[str]: ...
    @property
    def pty(self) -> Optional[str]: ...
    @property
    def pty_device(self) -> Optional[str]: ...
    @property
    def control(self) -> Optional[str]: ...
    @property
    def pytrinamic_args(self) -> Optional[str]: ...
    @property
    def pytrinamic_pty_args(self) -> Optional[str]: ...
    @property
    def running(self) -> bool: ...
    @property
    def module(self) -> Module: ...
    @property
    def modules(self) -> List[Module]: ...
    @property
    def stepped(self) -> bool: ...
    @stepped.setter
    def stepped(self, stepped: bool) -> None: ...
    @property
    def speed(self) -> float: ...
    @speed.setter
    def speed(self, speed: float) -> None: ...
    def advance(self, seconds: float) -> None: ...
    @property
    def time(self) -> float: ...
    def world(self, line: str, module: int = 0) -> str: ...
    def link_faults(self, drop: Optional[int] = None, corrupt: Optional[int] = None, delay_ms: Optional[int] = None, mute: Optional[bool] = None, clear: bool = False) -> Dict[str, Any]: ...
    def stop(self) -> None: ...
    def __enter__(self) -> "Server": ...
    def __exit__(self, *args: object) -> bool: ...

def status_text(status: int) -> str:
    """A TMCL status code in words, e.g. ``status_text(4) == "invalid value"``."""
