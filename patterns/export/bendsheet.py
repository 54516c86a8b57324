"""The bend sheet (CSV) for the press brake.

``patterns.write(blank, "bends.csv")`` (the ``bends`` profile; ``patterns
unfold PART -o blank.dxf --bend-sheet bends.csv``) writes one row per bend of
every blank in the drawing, in the order to bend them
(:func:`patterns.bendsheet.sequence`: the numbers the blank gave its bends when
it was made, the same its bend labels start with), with the bend line's ends
where the DXF of the same drawing draws it.
"""

from __future__ import annotations

import csv
import io
import numbers

from ..bendsheet import COLUMNS, bend_rows
from ..errors import InputError
from ..files import atomic_output
from ..pieces import Drawing, Piece
from ..text import spreadsheet_cell
from ..units import Unit
from .options import WriteOptions

__all__ = ["rows_of", "write"]


def _blank_bends(piece: Piece) -> bool:
    return piece.source.kind == "blank" and bool(piece.bends)


def rows_of(drawing: Drawing, unit: Unit = Unit.MM) -> list:
    """Every blank's bend rows (:class:`patterns.bendsheet.BendRow`), piece by piece, lengths in ``unit``."""
    rows = []
    for piece in drawing.pieces:
        if _blank_bends(piece):
            rows += bend_rows(piece.name, piece.bends, scale=1.0 / unit.mm)
    return rows


def _cell(value) -> str:
    """A number as a number; any text safe to open in a spreadsheet (:func:`patterns.text.spreadsheet_cell`:
    a part named ``=cmd|...`` is shown, never run)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, float):
        return f"{value:.4f}".rstrip("0").rstrip(".") if abs(value) < 1e9 else repr(value)
    if isinstance(value, numbers.Integral):
        return str(int(value))
    return spreadsheet_cell(str(value))


def write(drawing: Drawing, path, options: WriteOptions) -> None:
    """Write the drawing's bend sheet as CSV (atomically): a header, then a row per bend (see
    :data:`patterns.bendsheet.COLUMNS`; lengths in the drawing's unit, the columns named for it)."""
    if not any(p.source.kind == "blank" for p in drawing.pieces):
        raise InputError(f"{path}: a bend sheet lists the bends of a blank (patterns.unfold); "
                         f"{drawing.name} has none")
    unit = Unit(options.units)
    header = [c.replace("_mm", f"_{unit.value}") for c in COLUMNS]
    buffer = io.StringIO()
    out = csv.writer(buffer, lineterminator="\n")
    out.writerow([spreadsheet_cell(c) for c in header])
    for row in rows_of(drawing, unit):
        out.writerow([_cell(v) for v in row.to_dict().values()])
    with atomic_output(path, what="bend sheet") as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")
