"""The hosts' sides: what goes into a CAD program so that it talks to the engine (:mod:`patterns.service`).

``freecad_addon/`` is FreeCAD's workbench (FreeCAD and the standard library only: it is never imported
here); :mod:`~patterns.hosts.freecad` installs it (``patterns freecad install``).
"""
