"""The exceptions of tmclsim.

``TmclError`` carries the TMCL status code a module answered with;
``AssemblyError`` carries the assembler's diagnostics; ``InternalError``
reports a failure inside the simulator itself.
"""

from typing import List, NamedTuple

class TmclError(Exception):
    """A module answered a command with an error status.

    ``status`` is the TMCL status code (1 wrong checksum, 2 invalid command,
    3 wrong type, 4 invalid value, 5 EEPROM locked, 6 not available);
    ``message`` says which command failed and why.
    """

    def __init__(self, status: int, message: str) -> None:
        super().__init__(status, message)
        self.status = status
        self.message = message

    @property
    def description(self) -> str:
        """The status in words, e.g. ``"invalid value"``."""
        from ._tmclsim import status_text

        return status_text(self.status)

    def __str__(self) -> str:
        return self.message


class Diagnostic(NamedTuple):
    """One error the assembler found: where it is and what is wrong.

    ``line`` and ``column`` are 1-based; 0 when the error belongs to the
    whole file.
    """

    file: str
    line: int
    column: int
    message: str

    def __str__(self) -> str:
        if self.line == 0:
            return f"{self.file}: error: {self.message}"
        if self.column == 0:
            return f"{self.file}:{self.line}: error: {self.message}"
        return f"{self.file}:{self.line}:{self.column}: error: {self.message}"


class AssemblyError(Exception):
    """TMCL source did not assemble. ``diagnostics`` lists every error;
    ``str()`` prints them one per line, as a compiler does."""

    def __init__(self, diagnostics: List[Diagnostic]) -> None:
        self.diagnostics = list(diagnostics)
        super().__init__(str(self))

    def __str__(self) -> str:
        return "\n".join(str(d) for d in self.diagnostics)


class InternalError(RuntimeError):
    """The simulator failed inside (a bug in tmclsim, not in the caller's
    program): the call did not complete and the module may be left in an
    inconsistent state. The message is the internal one; please report it.
    """
