"""What FreeCAD keeps of a Python proxy in a saved document: nothing (every proxy here is made again from the
object's properties when the document is opened)."""


class Stateless:
    """A proxy FreeCAD saves as nothing and restores by :meth:`restored` (FreeCAD 0.20 calls
    ``__getstate__``/``__setstate__``, 0.21 and later ``dumps``/``loads``)."""

    def restored(self):
        """Called when the document is opened (the proxy's memory of this session is gone)."""

    def dumps(self):
        return None

    def loads(self, state):
        self.restored()

    __getstate__ = dumps

    def __setstate__(self, state):
        self.loads(state)
