"""The exceptions plant raises (docs/api.md, Python) and the diagnostics they carry."""

from dataclasses import dataclass
from typing import List, Optional


@dataclass(frozen=True)
class Diagnostic:
    """One error or warning: where it is (file, 1-based line and column) and what it says.

    ``rendered`` is the text plant prints for it: ``file:line:col: error: ...``, the line and a caret.
    """

    severity: str
    file: Optional[str]
    line: int
    column: int
    message: str
    rendered: str

    def __str__(self):
        return self.rendered


class Error(Exception):
    """Every error plant raises. ``str(error)`` is the diagnostics as plant prints them
    (``file:line:col: error: message``, the source line and a caret); ``diagnostics`` holds them
    as :class:`Diagnostic` objects (empty for an error that points at no grammar text)."""

    def __init__(self, message: str, diagnostics: Optional[List[Diagnostic]] = None):
        super().__init__(message)
        self.message = message
        self.diagnostics = list(diagnostics or [])

    def __str__(self):
        return self.message.rstrip("\n")

    @property
    def file(self):
        """The file of the first diagnostic, or None."""
        return self.diagnostics[0].file if self.diagnostics else None

    @property
    def line(self):
        """The line of the first diagnostic (1-based), or 0."""
        return self.diagnostics[0].line if self.diagnostics else 0

    @property
    def column(self):
        """The column of the first diagnostic (1-based), or 0."""
        return self.diagnostics[0].column if self.diagnostics else 0


class CompileError(Error):
    """The grammar cannot be read or compiled (``plant check`` would exit 65 or 66)."""


class DeriveError(Error):
    """Deriving, interpreting or meshing failed (a runtime error: ``plant run`` would exit 70)."""


class ExportError(Error):
    """A file cannot be written, or its format cannot be told from its name."""
