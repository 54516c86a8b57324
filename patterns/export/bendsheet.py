"""The bend sheet (CSV) for the press brake, and the sequence numbers on a drawing's bend labels.

``patterns.write(blank, "bends.csv")`` (the ``bends`` profile; ``patterns
unfold PART -o blank.dxf --bend-sheet bends.csv``) writes one row per bend of
every blank in the drawing, in the order to bend them
(:func:`patterns.bendsheet.sequence`), with the bend line's ends where the DXF
of the same drawing draws it.  :func:`sequenced` numbers a blank's bend labels
the same way (``1 UP 90.0 DEG R3``) for the DXF, the SVG and the report; a
blank of one bend has no order to give, and its label stays as it was.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, replace

from ..bendsheet import COLUMNS, bend_rows, sequence
from ..errors import InputError
from ..files import atomic_output
from ..pieces import Drawing, Piece
from ..pieces.piece import BendLine
from ..units import Unit
from .options import WriteOptions

__all__ = ["SequencedBend", "rows_of", "sequenced", "write"]


@dataclass(frozen=True, eq=False)
class SequencedBend(BendLine):
    """A blank's bend line with its place in the bending sequence: its label starts with the number.

    Attributes
    ----------
    sequence : int
        1 for the first bend to make.
    of : int
        How many bends the blank has (a blank of one bend has no order to give: its label has no number).
    """

    sequence: int = 0
    of: int = 0

    @property
    def label(self) -> str:
        """``1 UP 90.0 DEG R3`` (``UP 90.0 DEG R3`` for the one bend of a blank)."""
        plain = BendLine.label.fget(self)
        return f"{self.sequence} {plain}" if self.of > 1 else plain


def _blank_bends(piece: Piece) -> bool:
    return piece.source.kind == "blank" and bool(piece.bends)


def sequenced(piece: Piece) -> Piece:
    """The piece with each bend numbered in the bending sequence, when it is a blank (its labels numbered when it
    has two bends or more)."""
    if not _blank_bends(piece) or isinstance(piece.bends[0], SequencedBend):
        return piece
    order = sequence(piece.polygon, [b.line for b in piece.bends])
    rank = {i: k for k, i in enumerate(order, start=1)}
    bends = tuple(SequencedBend(b.line, b.angle, b.direction, b.inside_radius, b.k_factor, b.allowance,
                                sequence=rank[i], of=len(piece.bends)) for i, b in enumerate(piece.bends))
    return replace(piece, bends=bends)


def rows_of(drawing: Drawing, unit: Unit = Unit.MM) -> list:
    """Every blank's bend rows (:class:`patterns.bendsheet.BendRow`), piece by piece, lengths in ``unit``."""
    rows = []
    for piece in drawing.pieces:
        if _blank_bends(piece):
            rows += bend_rows(piece.name, piece.polygon, piece.bends, scale=1.0 / unit.mm)
    return rows


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.4f}".rstrip("0").rstrip(".") if abs(value) < 1e9 else repr(value)
    return str(value)


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
    out.writerow(header)
    for row in rows_of(drawing, unit):
        out.writerow([_cell(v) for v in row.to_dict().values()])
    with atomic_output(path, what="bend sheet") as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")
