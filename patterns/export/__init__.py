"""Writing results: DXF cutting patterns and flat meshes, always atomically."""

from ._atomic import atomic_output
from .dxf import write_outline_dxf
from .mesh import write_flat_obj

__all__ = ["atomic_output", "write_flat_obj", "write_outline_dxf"]
