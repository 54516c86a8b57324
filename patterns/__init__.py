"""patterns: 3D surfaces to accurate, cutter-ready 2D patterns at true scale.

The public API, all importable from the top level::

    import patterns
    result = patterns.flatten_mesh(vertices, faces)   # (n, 3), (m, 3) arrays in
    result.uv                                         # (n, 2) flat positions, 1:1
    result.overlap.one_to_one, result.distortion.edge_strain_rms
"""

from .check import Overlap, overlap_verdict
from .errors import (
    CadError,
    ExportError,
    FlattenError,
    InputError,
    MeshTopologyError,
    PatternsError,
)
from .flatten import METHODS, Flattening, flatten_mesh
from .measure import Distortion, distortion
from .mesh import Connectivity, validate_mesh
from .tessellate import tessellate_face

__version__ = "0.1.0"

__all__ = [
    "METHODS",
    "CadError",
    "Connectivity",
    "Distortion",
    "ExportError",
    "FlattenError",
    "Flattening",
    "InputError",
    "MeshTopologyError",
    "Overlap",
    "PatternsError",
    "__version__",
    "distortion",
    "flatten_mesh",
    "overlap_verdict",
    "tessellate_face",
    "validate_mesh",
]
