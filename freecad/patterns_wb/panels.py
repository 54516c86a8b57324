"""A task panel for a command's options, made from the option records (the one declaration of each option).

Each record is a page of a tool box; each option a field: a check box (a switch), a combo box (a
choice), a spin box (a number with a default), a line of text (the rest: empty is the default), with
the option's help as its tool tip.  Nothing is checked here: the values go to ``make_pattern`` or
``make_blank``, whose records check them and say what is wrong.
"""

from dataclasses import fields

from PySide import QtGui

from patterns.freecad.properties import property_names
from patterns.options import is_number


def _field(f, spec):
    if isinstance(f.default, bool):
        widget = QtGui.QCheckBox()
        widget.setChecked(f.default)
        return widget, widget.isChecked
    if spec.choices is not None:
        widget = QtGui.QComboBox()
        widget.addItems(list(spec.choices))
        widget.setCurrentIndex(list(spec.choices).index(str(f.default)))
        return widget, widget.currentText
    if f.default is not None and spec.integer:
        widget = QtGui.QSpinBox()
        widget.setRange(int(spec.low if spec.low is not None else -10**9), int(min(spec.high or 10**9, 10**9)))
        widget.setValue(int(f.default))
        return widget, widget.value
    if f.default is not None and is_number(f.default) and not spec.repeat:
        widget = QtGui.QDoubleSpinBox()
        widget.setDecimals(6)
        widget.setRange(-1e9, 1e9)
        widget.setValue(float(f.default))
        return widget, widget.value
    widget = QtGui.QLineEdit("" if f.default is None else str(f.default))
    return widget, widget.text


class OptionsPanel:
    """A task panel with the options of ``records`` (titled ``titles``); ``accept(options)`` runs on OK
    with ``{property name: value}`` of every option changed from its default."""

    def __init__(self, title, records, titles, accept, skip=()):
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(title)
        self.form.setMinimumHeight(620)
        layout = QtGui.QVBoxLayout(self.form)
        box = QtGui.QToolBox()
        box.setMinimumHeight(600)
        layout.addWidget(box)
        self.readers, self.defaults = {}, {}
        names = property_names(records, skip)
        for record, page_title in zip(records, titles):
            page = QtGui.QWidget()
            form = QtGui.QFormLayout(page)
            for f in fields(record):
                spec = f.metadata.get("spec")
                if spec is None or (record, f.name) not in names:
                    continue
                name = names[(record, f.name)]
                widget, read = _field(f, spec)
                widget.setToolTip(spec.help)
                form.addRow(name.replace("_", " "), widget)
                self.readers[name], self.defaults[name] = read, read()
            box.addItem(page, page_title)
        self._accept = accept

    def values(self) -> dict:
        """The options changed from their defaults, by property name."""
        return {name: read() for name, read in self.readers.items() if read() != self.defaults[name]}

    def accept(self):
        import FreeCADGui as Gui

        try:
            self._accept(self.values())
        except Exception as exc:  # noqa: BLE001 - shown to the user, who fixes the option and tries again
            QtGui.QMessageBox.critical(self.form, "patterns", str(exc))
            return False
        Gui.Control.closeDialog()
        return True

    def reject(self):
        import FreeCADGui as Gui

        Gui.Control.closeDialog()
        return True
