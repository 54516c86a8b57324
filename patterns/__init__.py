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

import importlib
import importlib.util

_EXPORTS = {
    "CheckOptions": "audit", "DartReport": "audit", "PanelReport": "audit", "Report": "audit", "SeamReport": "audit",
    "check": "audit",
    "BatchOptions": "batching", "BatchResult": "batching", "Row": "batching", "batch": "batching",
    "Bend": "blank", "Blank": "blank",
    "Bundle": "bundle",
    "BlankComparison": "comparison", "Difference": "comparison", "compare_blank": "comparison",
    "read_flat_pattern": "comparison",
    "Cut": "cut", "cut_to_disk": "cut",
    "CadError": "errors", "ExportError": "errors", "FlattenError": "errors", "InputError": "errors",
    "LayoutError": "errors", "MeshTopologyError": "errors", "MissingFileError": "errors",
    "PatternsError": "errors",
    "WriteOptions": "export", "heat_map": "export", "preview_dxf": "export", "write": "export",
    "Code": "findings", "Finding": "findings", "Severity": "findings",
    "FlattenOptions": "flattening", "Flattening": "flattening", "METHODS": "flattening", "flatten": "flattening",
    "flatten_mesh": "flattening",
    "ENERGIES": "flattening.energy",
    "Ease": "flattening.seams", "SeamLengths": "flattening.seams",
    "Distortion": "measure", "StrainStats": "measure", "distortion": "measure",
    "Connectivity": "mesh", "validate_mesh": "mesh",
    "Bookkeeping": "model", "Model": "model", "Panel": "model", "Seam": "model", "Surface": "model",
    "SurfaceKind": "model",
    "Layout": "nesting", "NestOptions": "nesting", "layout": "nesting",
    "Dart": "pattern", "DartSearch": "pattern", "FlatPanel": "pattern", "FlatSeam": "pattern", "Pattern": "pattern",
    "Drawing": "pieces", "Piece": "pieces", "PieceOptions": "pieces", "pieces_of": "pieces",
    "Overlap": "predicates", "overlap_verdict": "predicates",
    "LoadOptions": "reading", "load": "reading", "read_cad": "reading", "read_mesh": "reading",
    "BendTable": "sheetmetal", "UnfoldOptions": "sheetmetal", "read_bend_table": "sheetmetal", "unfold": "sheetmetal",
    "MeshingOptions": "tessellate", "mesh_shape": "tessellate", "tessellate_face": "tessellate",
    "Unit": "units",
}
"""Each public name and the module it lives in: imported when first used (PEP 562), so that ``patterns --help``
and a signal handler are up before numpy, scipy and OpenCascade load."""


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        if importlib.util.find_spec(f"{__name__}.{name}") is None:  # a submodule, as ``patterns.audit``
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
        return importlib.import_module(f".{name}", __name__)
    importlib.import_module(".deprecated", __name__)  # 0.1.0's Pattern.to_dxf, ...: warn, work, go in 0.3.0
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list:
    return sorted(set(globals()) | set(__all__))


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
    "Difference",
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
    "MissingFileError",
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
