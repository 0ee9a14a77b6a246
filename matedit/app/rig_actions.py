"""Saving and loading light rigs (matedit.io.rig) from the Lights panel.

`install_rig_actions(panel, bar)` adds an open and a save button to the panel's title bar;
`load_rig_into` and `save_rig_from` do the work without dialogs (tests, scripts). A bad
file is reported in a message box and through the panel's `rigMessage` signal (one line
naming the file, the light and the field) and leaves the panel's lights as they were.
"""

from __future__ import annotations

from PySide6.QtWidgets import QMessageBox, QToolButton

from matedit.app import file_dialogs
from matedit.app.theme import icon
from matedit.io import rig as rigio

FILTER = "Light rigs (*.json)"


def load_rig_into(panel, path: str) -> str | None:
    """Replaces the panel's lights with the rig file's; returns an error message or None."""
    try:
        lights = rigio.load(path)
    except rigio.RigError as exc:
        return str(exc)
    panel.set_lights(lights, emit=True)
    return None


def save_rig_from(panel, path: str) -> str | None:
    """Writes the panel's lights to `path` atomically; returns an error message or None."""
    try:
        rigio.save(panel.lights, path)
    except (OSError, rigio.RigError) as exc:
        return f"{path}: cannot save the light rig: {getattr(exc, 'strerror', None) or exc}"
    return None


def install_rig_actions(panel, bar) -> None:
    """Adds "Load a light rig" and "Save the light rig" buttons to `bar` (a QHBoxLayout)."""

    def report(message: str | None) -> None:
        if message:
            panel.rigMessage.emit(message)
            QMessageBox.warning(panel, "Light rig", message)

    def load() -> None:
        path, _ = file_dialogs.open_file(panel, "Load a light rig", "", FILTER)
        if path:
            report(load_rig_into(panel, path))

    def save() -> None:
        path, _ = file_dialogs.save_file(panel, "Save the light rig", "rig.json", FILTER)
        if path:
            report(save_rig_from(panel, path))

    for name, tip, slot in (("open", "Load a light rig (matedit.lightrig JSON)", load),
                            ("save", "Save the light rig", save)):
        b = QToolButton()
        b.setIcon(icon(name))
        b.setToolTip(tip)
        b.clicked.connect(slot)
        b.setObjectName(f"rig_{name}")
        bar.addWidget(b)
