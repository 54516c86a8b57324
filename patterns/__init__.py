"""patterns: 3D surfaces to accurate, cutter-ready 2D patterns at true scale.

The public API, all importable from the top level::

    import patterns
    model = patterns.load("duct.step")                # or a mesh file, or a build123d shape
    pattern = patterns.flatten(model)                 # every panel flat, 1:1, seams kept
    pattern.panels[0].uv, pattern.seams[0].flat_lengths

    result = patterns.flatten_mesh(vertices, faces)   # (n, 3), (m, 3) arrays in
    result.uv                                         # (n, 2) flat positions, 1:1
    result.overlap.one_to_one, result.distortion.strain_rms

    blank = patterns.unfold("bracket.step", k_factor=0.44)   # bent sheet metal: one flat blank
    patterns.write(blank, "bracket.dxf")               # outline, holes, bend lines; or .svg, .json
    patterns.write(pattern, "cup.dxf", seam_allowance=10)
    nest = patterns.layout([pattern, blank], sheet=(2500, 1250))   # pieces of both on sheets
    patterns.write(nest, "marker.dxf")

    result = patterns.batch("parts/", "out/", jobs=2)  # a folder of parts: a row each
"""

from . import deprecated  # noqa: F401 - 0.1.0's Pattern.to_dxf, Pattern.layout, Report.to_json: warn, work, go in 0.3.0
from .audit import CheckOptions, DartReport, PanelReport, Report, SeamReport, check
from .batching import BatchOptions, BatchResult, Row, batch
from .blank import Bend, Blank
from .bundle import Bundle
from .comparison import BlankComparison, compare_blank, read_flat_pattern
from .cut import Cut, cut_to_disk
from .errors import (
    CadError,
    ExportError,
    FlattenError,
    InputError,
    LayoutError,
    MeshTopologyError,
    PatternsError,
)
from .export import WriteOptions, heat_map, preview_dxf, write
from .findings import Code, Finding, Severity
from .flattening import METHODS, Flattening, FlattenOptions, flatten, flatten_mesh
from .flattening.energy import ENERGIES
from .flattening.seams import Ease, SeamLengths
from .measure import Distortion, StrainStats, distortion
from .mesh import Connectivity, validate_mesh
from .model import Bookkeeping, Model, Panel, Seam, Surface, SurfaceKind
from .nesting import Layout, NestOptions, layout
from .pattern import Dart, DartSearch, FlatPanel, FlatSeam, Pattern
from .pieces import Drawing, Piece, PieceOptions, pieces_of
from .predicates import Overlap, overlap_verdict
from .reading import LoadOptions, load, read_cad, read_mesh
from .sheetmetal import BendTable, UnfoldOptions, read_bend_table, unfold
from .tessellate import MeshingOptions, mesh_shape, tessellate_face
from .units import Unit

__version__ = "0.2.0"

__all__ = [
    "ENERGIES",
    "METHODS",
    "BatchOptions",
    "BatchResult",
    "Bend",
    "BendTable",
    "Blank",
    "BlankComparison",
    "Bookkeeping",
    "Bundle",
    "CadError",
    "CheckOptions",
    "Code",
    "Connectivity",
    "Cut",
    "Dart",
    "DartReport",
    "DartSearch",
    "Distortion",
    "Drawing",
    "Ease",
    "ExportError",
    "Finding",
    "FlatPanel",
    "FlatSeam",
    "FlattenError",
    "FlattenOptions",
    "Flattening",
    "InputError",
    "Layout",
    "LayoutError",
    "LoadOptions",
    "MeshTopologyError",
    "MeshingOptions",
    "Model",
    "NestOptions",
    "Overlap",
    "Panel",
    "PanelReport",
    "Pattern",
    "PatternsError",
    "Piece",
    "PieceOptions",
    "Report",
    "Row",
    "Seam",
    "SeamLengths",
    "SeamReport",
    "Severity",
    "StrainStats",
    "Surface",
    "SurfaceKind",
    "UnfoldOptions",
    "Unit",
    "WriteOptions",
    "__version__",
    "batch",
    "check",
    "compare_blank",
    "cut_to_disk",
    "distortion",
    "flatten",
    "flatten_mesh",
    "heat_map",
    "layout",
    "load",
    "mesh_shape",
    "overlap_verdict",
    "pieces_of",
    "preview_dxf",
    "read_bend_table",
    "read_cad",
    "read_flat_pattern",
    "read_mesh",
    "tessellate_face",
    "unfold",
    "validate_mesh",
    "write",
]
