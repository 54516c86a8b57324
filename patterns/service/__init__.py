"""The engine beside a host: a worker process that CAD programs talk to, and what they need of it.

``patterns serve`` (:func:`serve`) runs the engine in its own process and its own environment, answering
requests as JSON lines on standard input and output (docs/worker.md): a host (FreeCAD's workbench now,
Blender next) starts it once, keeps it warm between recomputes, restarts it if it dies, and ends it when
the host exits.  Nothing of the engine's environment enters the host's process: shapes cross as BREP
text, results as BREP text and plain numbers.

:mod:`~patterns.service.schema` gives the hosts the options (one property per option of a
:class:`~patterns.bundle.Bundle`, checked by its records), :mod:`~patterns.service.work` computes, :mod:`~patterns.service.brep` turns
shapes into text and back; :mod:`patterns.hosts` puts a host's side into the host.
"""

from .schema import properties, records_of, schema
from .server import PROTOCOL, Server, serve

__all__ = ["PROTOCOL", "Server", "properties", "records_of", "schema", "serve"]
