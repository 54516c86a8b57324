"""The exception tree of `patterns`.

Every error a user can cause is a :class:`PatternsError`.  Each class is also the
builtin exception a Python programmer would expect (``InputError`` is a
``ValueError``, ``MissingFileError`` also a ``FileNotFoundError``, ``ExportError`` an
``OSError``), so ``except ValueError`` keeps
working in code that does not know about `patterns`.

Geometry findings (strain over a limit, an overlap) are *not* exceptions: they are
reported on the result.
"""

from __future__ import annotations

__all__ = [
    "CadError",
    "ExportError",
    "FlattenError",
    "InputError",
    "LayoutError",
    "MeshTopologyError",
    "MissingFileError",
    "PatternsError",
    "Terminated",
]


class PatternsError(Exception):
    """Base class of every error raised by `patterns`."""


class InputError(PatternsError, ValueError):
    """Bad input: wrong array shape, NaN/inf coordinates, out-of-range indices,
    degenerate faces, an option out of range."""


class MeshTopologyError(InputError):
    """A mesh whose topology cannot be flattened as given: closed, non-manifold,
    several pieces, inconsistently wound, or not a planar domain."""


class MissingFileError(InputError, FileNotFoundError):
    """An input file that is not there: also the ``FileNotFoundError`` Python code expects (and, as every
    bad input, a ``ValueError``)."""


class CadError(PatternsError):
    """An unreadable or empty CAD file, or a tessellation that failed."""


class FlattenError(PatternsError):
    """The flattening could not be completed within the limits asked for."""


class ExportError(PatternsError, OSError):
    """An output file could not be written."""


class LayoutError(PatternsError):
    """The panels cannot be laid out as asked (a panel wider than the roll in every allowed orientation)."""


class Terminated(BaseException):
    """The process was asked to stop (SIGTERM), raised where it was: every ``finally`` runs, so
    temporary files are removed and worker processes stopped.  Not an error of the input."""
