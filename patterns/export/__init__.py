"""Writing results: DXF cutting patterns, flat meshes, heat maps, always atomically."""

from ._atomic import atomic_output
from .dxf import write_outline_dxf
from .heatmap import heat_map
from .mesh import write_flat_obj

__all__ = ["atomic_output", "heat_map", "write_flat_obj", "write_outline_dxf"]
