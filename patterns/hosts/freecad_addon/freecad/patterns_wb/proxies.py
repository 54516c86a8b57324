"""What the proxies share: FreeCAD keeps nothing of them in a saved document (each is made again from its
object's properties when the document is opened), and a pattern's marks are found by their link to it."""


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


def marks_of(obj):
    """The Marks objects of a pattern or blank: those whose ``Base`` it is (a pasted copy's are its own)."""
    found = {o.Name: o for o in obj.InList if "Role" in o.PropertiesList and getattr(o, "Base", None) == obj}
    return list(found.values())  # once each: a Marks object links its base twice (Base, and its Placement)
