"""The piece model: what a cutter cuts and marks, in mm at 1:1, independent of any file format.

Layers point down: patterns and blanks (:mod:`patterns.pattern`,
:mod:`patterns.blank`) -> pieces -> the nester, the writers and the report.

* :class:`Piece`: outline and holes as exact lines and arcs, sew lines,
  notches, drill holes, grain, bend lines, seam sides, title, provenance,
  strain and findings (:mod:`~patterns.pieces.piece`);
* :func:`pieces_of`: a pattern's panels or a blank as pieces, with
  :class:`PieceOptions` (seam allowance, notches, rulings, arcs, text height);
* :class:`Drawing`, :func:`drawing_of`: pieces laid out in the one frame a
  file's every writer uses (:mod:`~patterns.pieces.drawing`);
* :class:`Labels`: a piece's labels, placed once inside it clear of each other
  when the piece is made, kept on it and moved with it; a writer reads them
  with :func:`~patterns.pieces.labels.piece_labels`.
"""

from .build import blank_piece, pieces_of
from .drawing import MARGIN, Drawing, arrange, drawing_of
from .labels import piece_labels
from .options import PieceOptions, check_marks
from .piece import BendLine, Label, Labels, Notch, Piece, SeamSide, Source, StrainMap

__all__ = ["MARGIN", "BendLine", "Drawing", "Label", "Labels", "Notch", "Piece", "PieceOptions", "SeamSide", "Source",
           "StrainMap", "arrange", "blank_piece", "check_marks", "drawing_of", "piece_labels", "pieces_of"]
