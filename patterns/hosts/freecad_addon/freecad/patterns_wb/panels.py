"""Task panels for the options, made from the engine's option schema (the one declaration of each option).

Each record is a page of a tool box, each option a field -- a check box (a switch), a combo box (a
choice), a spin box (a number), a line of text (the rest: empty is the default) -- with the option's help
as its tool tip, in a scroll area that fits any screen.  Nothing is checked here: the engine's records
check the values and the panel shows what they say.  OK makes one engine call.
"""

from PySide import QtGui

from . import properties


def _field(p, current):
    if p["kind"] == "bool":
        widget = QtGui.QCheckBox()
        widget.setChecked(bool(current))
        return widget, widget.isChecked
    if p["kind"] == "choice":
        widget = QtGui.QComboBox()
        widget.addItems(list(p["choices"]))
        widget.setCurrentIndex(list(p["choices"]).index(str(current)))
        return widget, widget.currentText
    if p["kind"] == "int":
        widget = QtGui.QSpinBox()
        low = p["low"] if p["low"] is not None else -10**9
        high = p["high"] if p["high"] is not None else 10**9
        widget.setRange(int(max(low, -10**9)), int(min(high, 10**9)))
        widget.setValue(int(current))
        return widget, widget.value
    if p["kind"] == "float":  # text, not a spin box: 1e-07 keeps its digits
        widget = QtGui.QLineEdit(repr(float(current)))
        return widget, lambda: _number(widget.text())
    widget = QtGui.QLineEdit(str(current))
    return widget, widget.text


def _number(text):
    """A float field's value: the number, or the text as it is (the engine's records then say what is wrong)."""
    try:
        return float(text)
    except ValueError:
        return text


class OptionsPanel:
    """A task panel with the options of ``schema`` at ``values`` (``{name: value}``, the rest at their
    defaults); :meth:`apply` runs on OK with ``{name: value}`` of the options away from their defaults."""

    def __init__(self, title, schema, values):
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(title)
        layout = QtGui.QVBoxLayout(self.form)
        self.message = QtGui.QLabel("")
        self.message.setWordWrap(True)
        self.message.setStyleSheet("color: #b00000")
        box = QtGui.QToolBox()
        layout.addWidget(box, 1)
        layout.addWidget(self.message)
        screen = QtGui.QApplication.primaryScreen().availableGeometry().height()
        self.form.setMinimumHeight(max(240, min(520, screen - 320)))  # fits a 768-pixel screen, and grows
        self.schema, self.readers = schema, {}
        pages = {}
        for p in schema:
            if p["group"] not in pages:
                page = QtGui.QWidget()
                pages[p["group"]] = QtGui.QFormLayout(page)
                pages[p["group"]].setRowWrapPolicy(QtGui.QFormLayout.WrapLongRows)
                scroll = QtGui.QScrollArea()  # each page scrolls on its own: the panel fits any screen
                scroll.setWidgetResizable(True)
                scroll.setWidget(page)
                box.addItem(scroll, p["group"])
            widget, read = _field(p, values.get(p["name"], p["default"]))
            widget.setToolTip(p["help"])
            pages[p["group"]].addRow(p["name"].replace("_", " "), widget)
            self.readers[p["name"]] = read

    def values(self):
        """The options away from their defaults, by property name."""
        out = {}
        for p in self.schema:
            got = self.readers[p["name"]]()
            if got != p["default"]:
                out[p["name"]] = got
        return out

    def accept(self):
        from .engine import EngineError
        from .properties import PatternsError

        try:
            self.apply(self.values())
        except (PatternsError, EngineError, ValueError) as exc:
            self.message.setText(str(exc))  # the panel stays open, saying why; nothing was added
            return False
        self.close()
        return True

    def reject(self):
        self.close()
        return True

    def close(self):
        import FreeCADGui as Gui

        Gui.Control.closeDialog()

    def apply(self, values):
        raise NotImplementedError


class CreatePanel(OptionsPanel):
    """Flatten's or Unfold's panel: OK makes the object (``make(options)``)."""

    def __init__(self, title, schema, make, preset):
        super().__init__(title, schema, preset)
        self._make = make

    def apply(self, values):
        self._make(values)


class EditPanel(OptionsPanel):
    """An object's options (double-click): OK sets them and recomputes it once, one undo step; a value the
    engine refuses, or a recompute that fails, leaves the object as it was."""

    def __init__(self, obj):
        from .engine import engine

        schema = engine().options[obj.Proxy.KIND]
        super().__init__(f"patterns: {obj.Label}", schema,
                         {p["name"]: properties.value(obj, p) for p in schema if p["name"] in obj.PropertiesList})
        self.obj = obj

    def apply(self, values):
        from .properties import PatternsError, check_options

        obj, doc = self.obj, self.obj.Document
        check_options(obj.Proxy.KIND, values, obj.Label)
        before = {p["name"]: properties.value(obj, p) for p in self.schema if p["name"] in obj.PropertiesList}
        defaults = {p["name"]: p["default"] for p in self.schema}
        doc.openTransaction(f"patterns: options of {obj.Label}")
        try:
            properties.set_values(obj, self.schema, dict(defaults, **values), obj.Label)
            doc.recompute()
            if not obj.isValid():
                raise PatternsError(f"{obj.Label}: {obj.getStatusString()}")
        except Exception:
            properties.set_values(obj, self.schema, before, obj.Label)
            doc.abortTransaction()
            doc.recompute()
            raise
        doc.commitTransaction()

    def close(self):
        import FreeCADGui as Gui

        Gui.ActiveDocument.resetEdit()
