"""Writing results: DXF cutting patterns, flat meshes, heat maps, always atomically."""

from ..files import atomic_output
from .dxf import write_outline_dxf, write_pattern_dxf
from .heatmap import heat_map
from .mesh import write_flat_obj
from .preview import preview_dxf

__all__ = ["atomic_output", "heat_map", "preview_dxf", "write_flat_obj", "write_outline_dxf", "write_pattern_dxf"]
