"""Writers: every file ``patterns`` writes, always atomically.

:func:`write` (:mod:`~patterns.export.profiles`) writes pieces through a
registry of profiles, one module each: :mod:`~patterns.export.machine` (DXF
for cutters), :mod:`~patterns.export.astm` (DXF ASTM D6673),
:mod:`~patterns.export.svg`, :mod:`~patterns.export.report` (JSON).  Besides
them: the strain heat map of a pattern (:mod:`~patterns.export.heatmap`), the
1:1 preview of a written DXF (:mod:`~patterns.export.preview`), a one-panel
flat mesh (:mod:`~patterns.export.mesh`) and bare flat loops
(:func:`~patterns.export.dxfdoc.write_outline_dxf`).
"""

from ..files import atomic_output
from .dxfdoc import write_outline_dxf
from .heatmap import heat_map
from .layers import LayerMap, layer_map
from .mesh import write_flat_obj
from .options import WriteOptions
from .preview import preview_dxf
from .profiles import write
from .registry import Profile, profiles, register

__all__ = ["LayerMap", "Profile", "WriteOptions", "atomic_output", "heat_map", "layer_map", "preview_dxf", "profiles",
           "register", "write", "write_flat_obj", "write_outline_dxf"]
